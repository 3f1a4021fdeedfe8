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

#include <QAction>
#include <QApplication>
#include <QElapsedTimer>
#include <QFile>
#include <QFileInfo>
#include <QImage>
#include <QProcess>
#include <QSettings>
#include <QSignalSpy>
#include <QTest>

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
