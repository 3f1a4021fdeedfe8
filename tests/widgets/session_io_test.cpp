// Session files in the RemeshWidget (issues #6, #7): saveSession writes what the user did (scans, undo), and
// loadSession replays it on a new session — the mesh bit-identical, the history with its undone steps
// redo-able, the event log unchanged — and `fss-remesh run` replays the widget's file to the same OFF bytes.
// Bad files, failed and cancelled replays leave the current mesh and history alone.
#include "test_data.h"

#include <algorithm>
#include <fss/camera.h>
#include <fss/mesh_io.h>
#include <fss/session_file.h>
#include <fss/shapes.h>
#include <fss/widgets/remesh_widget.h>
#include <fss/widgets/scan_panel.h>
#include <fss/widgets/vtk_view.h>

#include <QApplication>
#include <QCheckBox>
#include <QElapsedTimer>
#include <QFile>
#include <QProcess>
#include <QSignalSpy>
#include <QTest>
#include <QUndoStack>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

using fss::widgets::RemeshWidget;

namespace {

bool waitIdle(RemeshWidget& w, int timeoutMs = 300000) {
    QElapsedTimer t;
    t.start();
    while (w.isBusy() && t.elapsed() < timeoutMs)
        QTest::qWait(5);
    return !w.isBusy();
}

std::unique_ptr<RemeshWidget> shownWidget() {
    auto w = std::make_unique<RemeshWidget>();
    w->resize(900, 650);
    w->show();
    if (!QTest::qWaitForWindowExposed(w.get())) return nullptr;
    return w;
}

// Same element records index for index and bit-identical points (what Session's undo promises).
bool identical(const fss::Mesh& a, const fss::Mesh& b) {
    if (a.number_of_vertices() != b.number_of_vertices() || a.number_of_faces() != b.number_of_faces() ||
        a.number_of_halfedges() != b.number_of_halfedges())
        return false;
    for (fss::VertexIndex v : a.vertices())
        if (!b.is_valid(v) || a.point(v) != b.point(v)) return false;
    for (fss::FaceIndex f : a.faces()) {
        if (!b.is_valid(f)) return false;
        auto ia = CGAL::vertices_around_face(a.halfedge(f), a).begin();
        auto ib = CGAL::vertices_around_face(b.halfedge(f), b).begin();
        for (int k = 0; k < 3; ++k, ++ia, ++ib)
            if (*ia != *ib) return false;
    }
    return true;
}

std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream os;
    os << in.rdbuf();
    return os.str();
}

// Scans the whole view from \p view at \p resolution and accepts it; false with a message on failure.
bool scanAndAccept(RemeshWidget& w, fss::StandardView view, int resolution) {
    w.view()->setStandardView(view);
    w.scanPanel()->setResolution(resolution);
    QTest::qWait(10);
    if (!w.scan()) return false;
    w.accept();
    return waitIdle(w);
}

} // namespace

class SessionIoTest : public QObject {
    Q_OBJECT

    std::filesystem::path fandisk_ = fss::test::meshPath("fandisk.off");
    std::filesystem::path dir_ = fss::test::tmpPath("widget_sessions");

    // Meshes of the recording below: after 0, 1, 2 and 3 accepted scans.
    std::vector<fss::Mesh> stages_;
    std::filesystem::path recorded_;

private slots:
    void initTestCase() {
        std::filesystem::create_directories(dir_);
        recorded_ = dir_ / "recorded.session.json";
        // Record: three scans from different views, then one undo.
        auto w = shownWidget();
        QVERIFY(w);
        QVERIFY(w->openMesh(QString::fromStdString(fandisk_.string())));
        QCOMPARE(w->meshPath(), QString::fromStdString(fandisk_.string()));
        stages_.push_back(w->mesh());
        for (const fss::StandardView v :
             {fss::StandardView::Iso, fss::StandardView::PosX, fss::StandardView::NegZ}) {
            QVERIFY2(scanAndAccept(*w, v, 160), qPrintable(w->statusText()));
            stages_.push_back(w->mesh());
        }
        QCOMPARE(w->undoStack()->count(), 3);
        w->undoStack()->undo();
        QVERIFY(identical(w->mesh(), stages_[2]));
        QVERIFY(w->saveSession(QString::fromStdString(recorded_.string())));
        QVERIFY(std::filesystem::exists(recorded_));
        QVERIFY(w->saveMesh(QString::fromStdString((dir_ / "recorded_result.off").string())));
    }

    void theFileHoldsEveryEventAndTheMesh() {
        const fss::SessionFile file = fss::loadSessionFile(recorded_); // validates, checks the sha256
        QCOMPARE(file.events.size(), std::size_t(4));
        QVERIFY(file.events[0].kind == fss::SessionEvent::Kind::Accept);
        QVERIFY(file.events[2].kind == fss::SessionEvent::Kind::Accept);
        QVERIFY(file.events[3].kind == fss::SessionEvent::Kind::Undo);
        // The scan image's longer side is the resolution (the other follows the view's aspect).
        const fss::Camera& camera = file.events[0].step.params.camera;
        QCOMPARE(std::max(camera.width, camera.height), 160);
        QVERIFY(std::min(camera.width, camera.height) > 100);
        QCOMPARE(std::filesystem::canonical(file.meshPath), std::filesystem::canonical(fandisk_));
    }

    void loadingReplaysTheMeshAndTheHistoryExactly() {
        auto w = shownWidget();
        QVERIFY(w);
        QVERIFY(w->setMesh(fss::shapes::icosphere(2))); // something to be replaced
        QSignalSpy loaded(w.get(), &RemeshWidget::sessionLoaded);
        QSignalSpy errors(w.get(), &RemeshWidget::errorOccurred);
        QVERIFY(w->loadSession(QString::fromStdString(recorded_.string())));
        QVERIFY(w->isBusy());
        QVERIFY(w->isLoadingSession());
        QVERIFY(!w->undoAction()->isEnabled());
        QVERIFY(waitIdle(*w));
        QCOMPARE(errors.count(), 0);
        QCOMPARE(loaded.count(), 1);
        QVERIFY(!w->isLoadingSession());
        QVERIFY(identical(w->mesh(), stages_[2]));
        QVERIFY(identical(w->referenceMesh(), stages_[0]));
        // History: three steps, the last one undone and redo-able.
        QCOMPARE(w->undoStack()->count(), 3);
        QCOMPARE(w->undoStack()->index(), 2);
        QVERIFY(w->redoAction()->isEnabled());
        w->undoStack()->redo();
        QVERIFY(identical(w->mesh(), stages_[3]));
        w->undoStack()->undo();
        w->undoStack()->undo();
        QVERIFY(identical(w->mesh(), stages_[1]));
        w->undoStack()->redo();
        QVERIFY(identical(w->mesh(), stages_[2]));
        // Saving the loaded session again gives the same events (the undo/redo just done are added).
        const std::filesystem::path again = dir_ / "again.session.json";
        QVERIFY(w->saveSession(QString::fromStdString(again.string())));
        const fss::SessionFile a = fss::loadSessionFile(recorded_), b = fss::loadSessionFile(again);
        QCOMPARE(b.events.size(), a.events.size() + 4);
        QCOMPARE(b.renderer, a.renderer);
        QCOMPARE(b.meshSha256, a.meshSha256);
        // A scan after loading gets a new scan id.
        QVERIFY(scanAndAccept(*w, fss::StandardView::PosY, 96));
        const auto steps = w->session()->steps();
        QVERIFY(steps.back().params.scan.scanId > 2);
    }

    void fssRemeshRunReplaysTheWidgetsFileToTheSameBytes() {
        const std::filesystem::path out = dir_ / "replayed.off";
        QProcess p;
        p.start(QString::fromStdString(fss::test::remeshExe().string()),
                {"run", QString::fromStdString(recorded_.string()), "-o",
                 QString::fromStdString(out.string()), "--quiet"});
        QVERIFY(p.waitForFinished(600000));
        QVERIFY2(p.exitCode() == 0, p.readAllStandardError().constData());
        const std::string a = slurp(out), b = slurp(dir_ / "recorded_result.off");
        QVERIFY(!a.empty());
        QVERIFY2(a == b, "fss-remesh run does not reproduce the widget's mesh byte for byte");
    }

    // Issue #20: the scan panel's "Warp lattice to the surface" switch — on by default, enabled only with
    // the adaptive lattice — reaches the scan and is recorded in the session file (always written).
    void warpSwitchReachesTheScanAndTheSession() {
        auto w = shownWidget();
        QVERIFY(w);
        QVERIFY(w->openMesh(QString::fromStdString(fandisk_.string())));
        fss::widgets::ScanPanel* panel = w->scanPanel();
        auto* box = panel->findChild<QCheckBox*>("warpToSurface");
        QVERIFY(box);
        QVERIFY(box->isChecked());
        QVERIFY(box->isEnabled());
        QCOMPARE(panel->warpToSurface(), fss::ScanOptions{}.warpToSurface);
        QSignalSpy changed(panel, &fss::widgets::ScanPanel::settingsChanged);
        for (fss::Lattice other : {fss::Lattice::Square, fss::Lattice::Triangular}) {
            panel->setLattice(other);
            QVERIFY(!box->isEnabled());
        }
        panel->setLattice(fss::Lattice::Adaptive);
        QVERIFY(box->isEnabled());
        const int before = changed.count();
        box->click(); // as the user does
        QVERIFY(!panel->warpToSurface());
        QCOMPARE(changed.count(), before + 1);
        QVERIFY(!panel->scanParams(w->view()->camera()).scan.warpToSurface);

        // Two scans of the same view, without and with the warp: different samples, both recorded.
        QVERIFY2(scanAndAccept(*w, fss::StandardView::Iso, 128), qPrintable(w->statusText()));
        const fss::Mesh plain = w->mesh();
        w->undoStack()->undo();
        panel->setWarpToSurface(true);
        QVERIFY(scanAndAccept(*w, fss::StandardView::Iso, 128));
        QVERIFY(!identical(w->mesh(), plain));
        QVERIFY(!identical(w->mesh(), stages_[0]));
        const std::filesystem::path file = dir_ / "warp.session.json";
        QVERIFY(w->saveSession(QString::fromStdString(file.string())));
        const fss::SessionFile saved = fss::loadSessionFile(file);
        QCOMPARE(saved.events.size(), std::size_t(3)); // accept, undo, accept
        QVERIFY(!saved.events[0].step.params.scan.warpToSurface);
        QVERIFY(saved.events[2].step.params.scan.warpToSurface);
        const std::string text = slurp(file);
        QVERIFY(text.find("\"warp_to_surface\": false") != std::string::npos);
        QVERIFY(text.find("\"warp_to_surface\": true") != std::string::npos);
    }

    void aMeshFromMemoryIsSavedNextToTheSession() {
        auto w = shownWidget();
        QVERIFY(w);
        const fss::Mesh sphere = fss::shapes::icosphere(3);
        QVERIFY(w->setMesh(sphere));
        QVERIFY(w->meshPath().isEmpty());
        QVERIFY(scanAndAccept(*w, fss::StandardView::PosZ, 120));
        const fss::Mesh result = w->mesh();
        const std::filesystem::path file = dir_ / "sphere.session.json";
        QVERIFY(w->saveSession(QString::fromStdString(file.string())));
        QVERIFY(std::filesystem::exists(dir_ / "sphere.session.input.ply"));
        QCOMPARE(w->meshPath(), QString::fromStdString((dir_ / "sphere.session.input.ply").string()));
        auto w2 = shownWidget();
        QVERIFY(w2);
        QVERIFY(w2->loadSession(QString::fromStdString(file.string())));
        QVERIFY(waitIdle(*w2));
        // Written as binary PLY: the same points bit for bit, the same faces.
        QCOMPARE(w2->referenceMesh().number_of_faces(), sphere.number_of_faces());
        for (fss::VertexIndex v : sphere.vertices())
            QVERIFY(w2->referenceMesh().point(v) == sphere.point(v));
        QVERIFY(identical(w2->referenceMesh(), w->referenceMesh()));
        QVERIFY2(
            w2->mesh().number_of_faces() == result.number_of_faces(),
            qPrintable(QString("%1 vs %2").arg(w2->mesh().number_of_faces()).arg(result.number_of_faces())));
        QVERIFY(identical(w2->mesh(), result));
    }

    void badFilesAreRefusedAndTheMeshStays() {
        auto w = shownWidget();
        QVERIFY(w);
        const fss::Mesh sphere = fss::shapes::icosphere(2);
        QVERIFY(w->setMesh(sphere));
        QVERIFY(scanAndAccept(*w, fss::StandardView::PosZ, 96));
        const fss::Mesh before = w->mesh();
        const std::string good = slurp(recorded_);
        struct Case {
            const char* name;
            std::string text;
            const char* mentions;
        };
        auto replaced = [&good](const std::string& from, const std::string& to) {
            std::string s = good;
            const auto at = s.find(from);
            if (at == std::string::npos) return std::string("not found: ") + from;
            s.replace(at, from.size(), to);
            return s;
        };
        const Case cases[] = {
            // (the file's own version, so that the replacement is made: "bad_version" alone names the field)
            {"version",
             replaced("\"version\": " + std::to_string(fss::kSessionFileVersion), "\"version\": 7"), "is 7"},
            {"width", replaced("\"width\": 160", "\"width\": -3"), "width"},
            {"sha", replaced("\"sha256\": \"", "\"sha256\": \"0"), "sha256"},
            {"json", good.substr(0, good.size() / 2), "json"},
        };
        for (const Case& c : cases) {
            const std::filesystem::path file = dir_ / (std::string("bad_") + c.name + ".json");
            {
                std::ofstream out(file, std::ios::binary);
                out << c.text;
            }
            QSignalSpy errors(w.get(), &RemeshWidget::errorOccurred);
            QVERIFY(!w->loadSession(QString::fromStdString(file.string())));
            QCOMPARE(errors.count(), 1);
            const QString message = errors.at(0).at(0).toString();
            QVERIFY2(message.contains(QLatin1String(c.mentions), Qt::CaseInsensitive), qPrintable(message));
            QVERIFY2(!message.contains('\n'), qPrintable(message));
            QVERIFY(!w->isBusy());
            QVERIFY(identical(w->mesh(), before));
            QCOMPARE(w->undoStack()->count(), 1);
        }
        // A replay that fails on an event: a step whose camera looks away from the mesh sees nothing.
        fss::SessionFile file = fss::loadSessionFile(recorded_);
        fss::Camera& camera = file.events[1].step.params.camera;
        camera.focal = camera.eye + (camera.eye - camera.focal);
        const std::filesystem::path failing = dir_ / "failing.session.json";
        fss::saveSessionFile(file, failing);
        QSignalSpy errors(w.get(), &RemeshWidget::errorOccurred);
        QSignalSpy loaded(w.get(), &RemeshWidget::sessionLoaded);
        QVERIFY(w->loadSession(QString::fromStdString(failing.string())));
        QVERIFY(waitIdle(*w));
        QCOMPARE(loaded.count(), 0);
        QCOMPARE(errors.count(), 1);
        QVERIFY2(errors.at(0).at(0).toString().contains(QLatin1String("events[1]")),
                 qPrintable(errors.at(0).at(0).toString()));
        QVERIFY(identical(w->mesh(), before));
        QCOMPARE(w->undoStack()->count(), 1);
    }

    void aCancelledReplayKeepsTheMesh() {
        auto w = shownWidget();
        QVERIFY(w);
        QVERIFY(w->setMesh(fss::shapes::icosphere(2)));
        const fss::Mesh before = w->mesh();
        QSignalSpy loaded(w.get(), &RemeshWidget::sessionLoaded);
        QVERIFY(w->loadSession(QString::fromStdString(recorded_.string())));
        w->cancel();
        QVERIFY(waitIdle(*w));
        QCOMPARE(loaded.count(), 0);
        QVERIFY(identical(w->mesh(), before));
        QCOMPARE(w->undoStack()->count(), 0);
        QVERIFY2(w->statusText().contains(QLatin1String("cancelled")), qPrintable(w->statusText()));
        // The widget works on: a scan after the cancelled load.
        QVERIFY(scanAndAccept(*w, fss::StandardView::PosZ, 96));
        QCOMPARE(w->undoStack()->count(), 1);
    }
};

int main(int argc, char** argv) {
    fss::widgets::VtkView::setDefaultSurfaceFormat();
    QApplication app(argc, argv);
    SessionIoTest test;
    return QTest::qExec(&test, argc, argv);
}

#include "session_io_test.moc"
