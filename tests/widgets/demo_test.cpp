// fss-demo: the --screenshot command line (run as a program) and the main window's open / save paths
// (driven directly, with a recording MessagePresenter instead of a modal box).
#include "main_window.h"
#include "pixel_stats.h"
#include "test_data.h"

#include <fss/mesh_io.h>
#include <fss/shapes.h>
#include <fss/widgets/remesh_widget.h>
#include <fss/widgets/scan_panel.h>
#include <fss/widgets/vtk_view.h>

#include <QAbstractButton>
#include <QAction>
#include <QApplication>
#include <QElapsedTimer>
#include <QFile>
#include <QFileInfo>
#include <QImage>
#include <QLabel>
#include <QMessageBox>
#include <QProcess>
#include <QSettings>
#include <QSignalSpy>
#include <QStatusBar>
#include <QTest>
#include <QTimer>
#include <QUndoStack>

#include <filesystem>
#include <fstream>
#include <memory>

namespace {

struct RunResult {
    int exitCode = -1;
    QString err;
};

RunResult runDemo(const QStringList& args) {
    QProcess process;
    process.start(QStringLiteral(FSS_DEMO_EXE), args);
    RunResult r;
    if (!process.waitForFinished(120000) || process.exitStatus() != QProcess::NormalExit) return r;
    r.exitCode = process.exitCode();
    r.err = QString::fromUtf8(process.readAllStandardError());
    return r;
}

QString tmp(const char* name) {
    return QString::fromStdString(fss::test::tmpPath(name).string());
}

QString badMeshFile() {
    const QString path = tmp("demo_bad.off");
    std::ofstream(path.toStdString())
        << "OFF\n3 1 0\n0 0 0\n1 0 0\n"; // truncated: a vertex and the face missing
    return path;
}

// Records errors instead of showing a modal box.
class RecordingPresenter final : public fss::demo::MessagePresenter {
public:
    explicit RecordingPresenter(QStringList* messages) : messages_(messages) {}
    void showError(QWidget*, const QString&, const QString& message) override { messages_->append(message); }

private:
    QStringList* messages_;
};

// Scans the shown window's mesh at 64 px and accepts the scan (unsaved work).
bool scanAndAccept(fss::demo::MainWindow& window) {
    fss::widgets::RemeshWidget* remesh = window.remeshWidget();
    remesh->scanPanel()->setResolution(64);
    remesh->scanPanel()->setForceReplace(true); // a second scan of the same view replaces faces too
    const int steps = remesh->undoStack()->count();
    if (!remesh->scan()) return false;
    remesh->accept();
    QElapsedTimer t;
    t.start();
    while (remesh->isBusy() && t.elapsed() < 60000)
        QTest::qWait(10);
    return !remesh->isBusy() && remesh->undoStack()->count() == steps + 1;
}

// Answers the next modal QMessageBox with \p button (polling, as the box runs its own event loop); records
// its title and text in \p seen.
void answerNextBox(QMessageBox::StandardButton button, QString* seen) {
    auto* timer = new QTimer;
    QObject::connect(timer, &QTimer::timeout, [timer, button, seen] {
        auto* box = qobject_cast<QMessageBox*>(QApplication::activeModalWidget());
        if (!box) return;
        *seen = box->windowTitle() + "|" + box->text();
        box->button(button)->click();
        timer->stop();
        timer->deleteLater();
    });
    timer->start(20);
}

// Red to yellow of the minimum-angle legend (the lower part of its bar), or the valence legend's red.
bool legendWarm(QRgb p) {
    return qRed(p) > 170 && qBlue(p) < 90 && qRed(p) > qGreen(p) + 20;
}

} // namespace

class DemoTest : public QObject {
    Q_OBJECT
private slots:
    void screenshotOfAMesh() {
        const QString out = tmp("demo_fandisk.png");
        QFile::remove(out);
        const RunResult r = runDemo({"--screenshot", out, "--size", "800x600", "--view", "+z",
                                     QString::fromStdString(fss::test::meshPath("fandisk.off").string())});
        QVERIFY2(r.exitCode == 0, qPrintable(r.err));
        QImage image;
        QVERIFY(image.load(out));
        QVERIFY(image.width() >= 800 && image.height() >= 600); // the whole window (× device pixel ratio)
        const double cover = fss::test::pixelFraction(image, fss::test::notBackground);
        QVERIFY2(cover > 0.1 && cover < 0.9, qPrintable(QString::number(cover)));
        QVERIFY(fss::test::pixelFraction(image, fss::test::surfaceColored) > 0.03);
        // The view occupies most of the window: its background is there too.
        QVERIFY(1 - cover > 0.1);
    }

    void screenshotWithColorMapAndDefaultMesh() {
        const QString out = tmp("demo_default_angle.png");
        QFile::remove(out);
        const RunResult r = runDemo({"--screenshot", out, "--colormap", "angle"});
        QVERIFY2(r.exitCode == 0, qPrintable(r.err));
        QImage image;
        QVERIFY(image.load(out));
        QVERIFY(fss::test::pixelFraction(image, fss::test::qualityGreen) > 0.02);
    }

    void screenshotOfABadFileFails() {
        const QString out = tmp("demo_bad.png");
        QFile::remove(out);
        const RunResult r = runDemo({"--screenshot", out, badMeshFile()});
        QVERIFY(r.exitCode != 0 && r.exitCode != -1);
        const QString sentence = r.err.trimmed();
        QVERIFY2(!sentence.isEmpty() && !sentence.contains('\n') && sentence.endsWith('.'),
                 qPrintable(r.err));
        QVERIFY(sentence.contains("demo_bad.off"));
        QVERIFY(!QFile::exists(out));
    }

    void screenshotAfterAScan() {
        const QString out = tmp("demo_scanned.png");
        QFile::remove(out);
        const RunResult r = runDemo({"--screenshot", out, "--size", "800x600", "--scan", "+z", "--resolution",
                                     "96", "--colormap", "angle",
                                     QString::fromStdString(fss::test::meshPath("fandisk.off").string())});
        QVERIFY2(r.exitCode == 0, qPrintable(r.err));
        QImage image;
        QVERIFY(image.load(out));
        QVERIFY(fss::test::pixelFraction(image, fss::test::qualityGreen) > 0.02);
        QCOMPARE(runDemo({"--screenshot", out, "--scan", "sideways"}).exitCode, 2);
        QCOMPARE(runDemo({"--screenshot", out, "--resolution", "3"}).exitCode, 2);
    }

    void wrongCommandLineIsRefused() {
        const RunResult r = runDemo({"--screenshot", tmp("x.png"), "--view", "sideways"});
        QCOMPARE(r.exitCode, 2);
        QVERIFY(r.err.contains("sideways"));
    }

    void openingABadFileKeepsTheMesh() {
        QStringList messages;
        fss::demo::MainWindow window(std::make_unique<RecordingPresenter>(&messages));
        const QString good = QString::fromStdString(fss::test::meshPath("fandisk.off").string());
        QVERIFY(window.openMesh(good));
        const std::size_t faces = window.mesh().number_of_faces();
        QCOMPARE(faces, std::size_t(12946));
        QVERIFY(window.statisticsText().contains("12946 faces"));
        QVERIFY(window.view()->hasMesh());

        QSignalSpy errors(&window, &fss::demo::MainWindow::errorOccurred);
        QSignalSpy changed(&window, &fss::demo::MainWindow::meshChanged);
        QVERIFY(!window.openMesh(badMeshFile()));
        QCOMPARE(errors.count(), 1);
        QCOMPARE(messages.size(), 1);
        QCOMPARE(errors.at(0).at(0).toString(), messages.at(0));
        QVERIFY(messages.at(0).contains("demo_bad.off") && messages.at(0).trimmed().endsWith('.'));
        QCOMPARE(changed.count(), 0);
        QCOMPARE(window.mesh().number_of_faces(), faces); // the previous mesh stays
        QCOMPARE(window.meshPath(), good);
        QVERIFY(window.statisticsText().contains("12946 faces"));

        QVERIFY(!window.openMesh(tmp("does_not_exist.off")));
        QCOMPARE(messages.size(), 2);
        QCOMPARE(window.mesh().number_of_faces(), faces);
    }

    void saveWritesTheMeshAndReportsFailures() {
        QStringList messages;
        fss::demo::MainWindow window(std::make_unique<RecordingPresenter>(&messages));
        QVERIFY(window.openMesh(QString::fromStdString(fss::test::meshPath("fandisk.off").string())));
        const QString out = tmp("demo_saved.ply");
        QVERIFY(window.saveMesh(out));
        QCOMPARE(fss::readMesh(out.toStdString()).number_of_faces(), window.mesh().number_of_faces());
        QVERIFY(messages.isEmpty());
        QVERIFY(!window.saveMesh(tmp("demo_saved.unknown")));
        QCOMPARE(messages.size(), 1);
    }

    void recentFilesKeepTheLastEight() {
        QSettings().remove(QStringLiteral("recentFiles"));
        QStringList messages;
        fss::demo::MainWindow window(std::make_unique<RecordingPresenter>(&messages));
        QVERIFY(window.recentFiles().isEmpty());
        const fss::Mesh tetra = fss::readMesh(fss::test::meshPath("tetrahedron.off"));
        QStringList written;
        for (int i = 0; i < 10; ++i) {
            const QString path = tmp(qPrintable(QString("demo_recent_%1.off").arg(i)));
            fss::writeMesh(tetra, path.toStdString());
            QVERIFY(window.openMesh(path));
            written.prepend(QFileInfo(path).absoluteFilePath());
        }
        QVERIFY(!window.openMesh(badMeshFile())); // failures are not recorded
        QCOMPARE(window.recentFiles().size(), fss::demo::MainWindow::kMaxRecentFiles);
        QCOMPARE(window.recentFiles(), written.mid(0, fss::demo::MainWindow::kMaxRecentFiles));
        QVERIFY(window.openMesh(written.at(5))); // reopening moves a file to the front, without duplicates
        QCOMPARE(window.recentFiles().front(), written.at(5));
        QCOMPARE(window.recentFiles().count(written.at(5)), 1);
        QCOMPARE(window.recentFiles().size(), fss::demo::MainWindow::kMaxRecentFiles);
        QSettings().remove(QStringLiteral("recentFiles"));
    }

    void editUndoRedoAfterAScan() {
        QStringList messages;
        fss::demo::MainWindow window(std::make_unique<RecordingPresenter>(&messages));
        window.resize(1000, 700);
        window.show();
        QVERIFY(QTest::qWaitForWindowExposed(&window));
        window.setMesh(fss::shapes::icosphere(3), QStringLiteral("sphere"));
        fss::widgets::RemeshWidget* remesh = window.remeshWidget();
        QAction* undo = remesh->undoAction();
        QAction* redo = remesh->redoAction();
        QCOMPARE(undo->shortcut(), QKeySequence(QKeySequence::Undo));
        QCOMPARE(redo->shortcut(), QKeySequence(QKeySequence::Redo));
        QVERIFY(!undo->isEnabled());
        const fss::Mesh before = window.mesh();
        QVERIFY(window.statisticsText().contains(QString("%1 faces").arg(before.number_of_faces())));
        remesh->scanPanel()->setResolution(128);
        QVERIFY(remesh->scan());
        QSignalSpy changed(&window, &fss::demo::MainWindow::meshChanged);
        remesh->accept();
        QElapsedTimer t;
        t.start();
        while (remesh->isBusy() && t.elapsed() < 60000)
            QTest::qWait(10);
        QCOMPARE(changed.count(), 1);
        const std::size_t faces = window.mesh().number_of_faces();
        QVERIFY(faces != before.number_of_faces());
        QVERIFY(window.statisticsText().contains(QString("%1 faces").arg(faces)));
        QVERIFY(undo->isEnabled());
        undo->trigger();
        QCOMPARE(window.mesh().number_of_faces(), before.number_of_faces());
        QVERIFY(window.statisticsText().contains(QString("%1 faces").arg(before.number_of_faces())));
        QVERIFY(redo->isEnabled());
        redo->trigger();
        QCOMPARE(window.mesh().number_of_faces(), faces);
        QCOMPARE(changed.count(), 3);
        QVERIFY(messages.isEmpty());
    }

    // Issue #21 item 3: closing (Ctrl+Q) with unsaved accepted scans asks; Cancel keeps the window.
    void unsavedWorkAsksBeforeClosing() {
        QStringList messages;
        fss::demo::MainWindow window(std::make_unique<RecordingPresenter>(&messages));
        window.resize(1000, 700);
        window.show();
        QVERIFY(QTest::qWaitForWindowExposed(&window));
        window.setMesh(fss::shapes::icosphere(3), QStringLiteral("sphere"));
        QVERIFY(!window.hasUnsavedChanges());
        QVERIFY(scanAndAccept(window));
        QVERIFY(window.hasUnsavedChanges());
        QString seen;
        answerNextBox(QMessageBox::Cancel, &seen);
        QVERIFY(!window.close()); // Cancel: the window stays
        QVERIFY2(seen.startsWith("Save changes?|") && seen.contains("1 accepted scan"), qPrintable(seen));
        QVERIFY(window.isVisible());
        QCOMPARE(window.remeshWidget()->undoStack()->count(), 1);
        // Saving makes the work clean; a new accept makes it unsaved again.
        QVERIFY(window.saveMesh(tmp("demo_unsaved.ply")));
        QVERIFY(!window.hasUnsavedChanges());
        QVERIFY(scanAndAccept(window));
        QVERIFY(window.hasUnsavedChanges());
        seen.clear();
        answerNextBox(QMessageBox::Discard, &seen);
        QVERIFY(window.close()); // Discard: it closes
        QVERIFY(seen.startsWith("Save changes?|"));
        QVERIFY(messages.isEmpty());
    }

    // Issue #21 items 4 and 7: a status message is readable after saving (the statistics keep to the
    // right); Save As adds the chosen filter's suffix; the desktop shortcuts exist; no grammar slip.
    void statusMessageIsReadableAfterSavingAndSaveAsAddsTheSuffix() {
        QStringList messages;
        fss::demo::MainWindow window(std::make_unique<RecordingPresenter>(&messages));
        window.resize(1024, 700);
        window.show();
        QVERIFY(QTest::qWaitForWindowExposed(&window));
        QVERIFY(window.openMesh(QString::fromStdString(fss::test::meshPath("fandisk.off").string())));
        const QString base = tmp("demo_suffix");
        QFile::remove(base + ".off");
        const QString path = fss::demo::MainWindow::withFilterSuffix(base, "OFF (*.off)");
        QCOMPARE(path, base + ".off");
        QCOMPARE(fss::demo::MainWindow::withFilterSuffix(base + ".ply", "OFF (*.off)"), base + ".ply");
        QCOMPARE(fss::demo::MainWindow::withFilterSuffix(base + ".v2", "STL (*.stl)"), base + ".v2.stl");
        QVERIFY(window.saveMesh(path));
        QCOMPARE(fss::readMesh(path.toStdString()).number_of_faces(), std::size_t(12946));
        QTest::qWait(20);
        const QString message = window.statusBar()->currentMessage();
        QVERIFY2(message.startsWith("Saved demo_suffix.off"), qPrintable(message));
        auto* statistics = window.statusBar()->findChild<QLabel*>("statistics");
        QVERIFY(statistics && statistics->isVisible());
        const int room = statistics->geometry().left();
        const int needed = window.statusBar()->fontMetrics().horizontalAdvance(message);
        QVERIFY2(room > needed, qPrintable(QString("%1 px for a message of %2 px").arg(room).arg(needed)));

        QVERIFY(!window.saveMesh(base)); // no extension: one sentence without the old grammar slip
        QCOMPARE(messages.size(), 1);
        QVERIFY2(messages.at(0).contains("has no extension, so the format is unknown"),
                 qPrintable(messages.at(0)));
        auto* save = window.findChild<QAction*>("save");
        auto* saveAs = window.findChild<QAction*>("saveAs");
        QVERIFY(save && saveAs);
        QCOMPARE(save->shortcut(), QKeySequence(Qt::CTRL | Qt::Key_S));
        QCOMPARE(saveAs->shortcut(), QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_S));
        QVERIFY(
            window.remeshWidget()->redoAction()->shortcuts().contains(QKeySequence(Qt::CTRL | Qt::Key_Y)));
        // Save (Ctrl+S) writes to the last Save As file.
        QFile::remove(path);
        QVERIFY(window.save());
        QVERIFY(QFile::exists(path));
    }

    // Issue #21 item 9: View keys (0–6, R), edges, triad, up axis, scan-id colours, Help.
    void viewMenuKeysColoursAndHelp() {
        QStringList messages;
        fss::demo::MainWindow window(std::make_unique<RecordingPresenter>(&messages));
        const std::pair<const char*, QKeySequence> keys[] = {
            {"view-iso", QKeySequence(Qt::Key_0)}, {"view--y", QKeySequence(Qt::Key_1)},
            {"view-+z", QKeySequence(Qt::Key_2)},  {"view-+x", QKeySequence(Qt::Key_3)},
            {"view-+y", QKeySequence(Qt::Key_4)},  {"view--z", QKeySequence(Qt::Key_5)},
            {"view--x", QKeySequence(Qt::Key_6)},  {"frame", QKeySequence(Qt::Key_R)}};
        for (const auto& [name, key] : keys) {
            auto* a = window.findChild<QAction*>(name);
            QVERIFY2(a, name);
            QCOMPARE(a->shortcut(), key);
        }
        window.setMesh(fss::shapes::icosphere(2), QStringLiteral("sphere"));
        window.findChild<QAction*>("view-+z")->trigger();
        QVERIFY(window.view()->camera().viewDirection().dot(Eigen::Vector3d(0, 0, -1)) > 1 - 1e-9);
        auto* edges = window.findChild<QAction*>("edges");
        QVERIFY(edges && edges->isChecked() && window.view()->edgesVisible());
        edges->trigger();
        QVERIFY(!window.view()->edgesVisible());
        auto* axes = window.findChild<QAction*>("axes");
        QVERIFY(axes && axes->isChecked() && window.view()->axesVisible());
        window.findChild<QAction*>("up-y")->trigger();
        QCOMPARE(window.view()->upAxis(), fss::widgets::VtkView::UpAxis::Y);
        window.findChild<QAction*>("view-+x")->trigger();
        QVERIFY(window.view()->camera().up.dot(Eigen::Vector3d::UnitY()) > 1 - 1e-9);
        auto* scanIds = window.findChild<QAction*>("colour-scan-id");
        QVERIFY(scanIds);
        scanIds->trigger();
        QCOMPARE(window.view()->colorMap(), fss::widgets::ColorMap::ScanId);
        QVERIFY(window.findChild<QAction*>("navigationHelp"));
        const QString help = fss::demo::MainWindow::navigationHelp();
        for (const char* word : {"R frames", "wheel", "Ctrl+Y", "Esc"})
            QVERIFY2(help.contains(word), word);
    }

    // Issue #21 item 9: the colour legend shows in the window's screenshot (the --screenshot path).
    void legendShowsInTheScreenshot() {
        QStringList messages;
        fss::demo::MainWindow window(std::make_unique<RecordingPresenter>(&messages));
        window.resize(1024, 700);
        window.setMesh(fss::shapes::icosphere(3), QStringLiteral("sphere")); // all faces ≥ 50°: no red
        window.setColorMap(fss::widgets::ColorMap::MinAngle);
        const QString out = tmp("demo_legend.png");
        QCOMPARE(window.saveScreenshot(out), QString());
        QVERIFY(window.view()->legendShown());
        // The legend's strip: the right 14 % of the view.
        const QRect viewRect(window.view()->mapTo(&window, QPoint(0, 0)), window.view()->size());
        const QRect strip(viewRect.left() + viewRect.width() * 86 / 100, viewRect.top(),
                          viewRect.width() * 14 / 100, viewRect.height());
        QImage with;
        QVERIFY(with.load(out));
        const qreal dpr = window.devicePixelRatioF(); // the image has device pixels
        const QRect s((QPointF(strip.topLeft()) * dpr).toPoint(), strip.size() * dpr);
        const double warmWith = fss::test::pixelFraction(with, legendWarm, s);
        window.view()->setLegendVisible(false);
        QCOMPARE(window.saveScreenshot(out), QString());
        QImage without;
        QVERIFY(without.load(out));
        const double warmWithout = fss::test::pixelFraction(without, legendWarm, s);
        QVERIFY2(
            warmWith > 0.01 && warmWithout < 0.001,
            qPrintable(QString("warm legend pixels %1 with, %2 without").arg(warmWith).arg(warmWithout)));
    }

    void windowScreenshotShowsTheMesh() {
        QStringList messages;
        fss::demo::MainWindow window(std::make_unique<RecordingPresenter>(&messages));
        QVERIFY(window.openMesh(QString::fromStdString(fss::test::meshPath("fandisk.off").string())));
        window.setColorMap(fss::widgets::ColorMap::Valence);
        const QString out = tmp("demo_window.png");
        QCOMPARE(window.saveScreenshot(out), QString());
        QImage image;
        QVERIFY(image.load(out));
        QVERIFY(fss::test::pixelFraction(image, fss::test::qualityGreen) > 0.02);
    }
};

int main(int argc, char** argv) {
    fss::widgets::VtkView::setDefaultSurfaceFormat();
    QApplication app(argc, argv);
    QApplication::setOrganizationName(QStringLiteral("FSS-tests")); // keeps the user's recent files alone
    DemoTest test;
    return QTest::qExec(&test, argc, argv);
}

#include "demo_test.moc"
