#pragma once
// Private to RemeshWidget: what its source files share. remesh_widget.cpp: the layout, tools, undo and
// status; remesh_widget_files.cpp: meshes, session files and their replay; remesh_widget_work.cpp: scans,
// accepts and the trial stitch on worker threads.

#include "fss/widgets/remesh_widget.h"

#include "fss/error.h"
#include "fss/face_groups.h"
#include "fss/fishbone_scan.h"
#include "fss/mesh_io.h"
#include "fss/metrics.h"
#include "fss/render/fem_io.h"
#include "fss/replay.h"
#include "fss/session_file.h"
#include "fss/widgets/figures_measurer.h"
#include "fss/widgets/fishbone_tool.h"
#include "fss/widgets/lasso_tool.h"
#include "fss/widgets/quality_panel.h"
#include "fss/widgets/scan_panel.h"
#include "fss/widgets/scan_tool.h"
#include "fss/widgets/tool.h"
#include "fss/widgets/vtk_view.h"

#include <QAction>
#include <QActionGroup>
#include <QCoreApplication>
#include <QEventLoop>
#include <QFileInfo>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QScrollArea>
#include <QSplitter>
#include <QThread>
#include <QTimer>
#include <QToolBar>
#include <QUndoCommand>
#include <QUndoStack>
#include <QUndoView>
#include <QVBoxLayout>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>

namespace fss::widgets::detail {

// State shared between the GUI thread and one worker job.
struct Job {
    std::stop_source stop; // Cancel
    std::atomic<double> fraction{0.0};
    std::mutex mutex;
    std::string stage;
    std::string error; // set by the worker on failure
    bool cancelled = false;
    // The bar shows base + span · (the work's own fraction): a session replay runs one work per event.
    double base = 0, span = 1;
};

inline QString sentence(const std::exception& e) {
    return QString::fromStdString(e.what());
}

// Whole-mesh figures shown before → after an accept (computeMetrics' figures, without its other measures:
// twice per accept, so they cost a fraction of its time): \p result's, or CancelledError when it was stopped.
inline MeshFigures figuresOf(const FiguresResult& result) {
    if (!result.figures) throw CancelledError();
    return *result.figures;
}

// One trial stitch (see the file comment of remesh_widget.h), shared by the GUI and the trial's thread. The
// inputs are copies made on the GUI thread; the thread writes the results, which the GUI reads once the
// thread has finished.
struct Trial {
    const Session* session = nullptr; // the preview it is for: session and scan id
    std::int32_t scanId = 0;
    std::stop_source stop;                     // Cancel, a newer preview, an accept
    std::shared_ptr<FiguresMeasurer> measurer; // the widget's: its whole-mesh measures stop when asked
    std::atomic<double> fraction{0.0};
    std::shared_ptr<const Mesh> current; // the widget's current mesh (immutable, shared with the GUI)
    Mesh mesh;                           // its copy, made on the thread after the figures before, stitched
    Mesh patch;
    Camera camera;
    StitchOptions options;
    std::vector<std::uint32_t> faceIds;
    StitchReport report;
    std::vector<std::uint8_t> stitched; // per patch face index: 1 glued in, 0 trimmed
    MeshFigures before, after;
    std::string error;
    bool cancelled = false;
    bool finished = false; // the thread has ended and the GUI has taken its result
    double seconds = 0;

    // The stitch Session::accept runs (same options, camera and ID buffer), on the copy.
    void run() {
        const auto start = std::chrono::steady_clock::now();
        const Progress progress([this](double f, std::string_view) {
            fraction = f;
            return !stop.stop_requested();
        });
        try {
            before = figuresOf(measurer->measure(*current, stop.get_token()));
            progress.report(0.0, "stitch"); // an abandoned trial ends here, before the copy
            mesh = *current;
            report = stitchPatch(mesh, patch, camera, options, faceIds, progress, &stitched);
            if (mesh.has_garbage()) mesh.collect_garbage();
            progress.report(0.95, "figures");
            after = figuresOf(measurer->measure(mesh, stop.get_token()));
        } catch (const CancelledError&) {
            cancelled = true;
        } catch (const std::exception& e) {
            error = e.what();
        }
        seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    bool succeeded() const { return finished && !cancelled && error.empty(); }
};

} // namespace fss::widgets::detail

namespace fss::widgets {

/// One accepted scan on the undo stack. The scan was already applied by Session::accept when the command
/// is pushed, so its first redo() (QUndoStack::push calls it) does nothing.
class AcceptCommand final : public QUndoCommand {
public:
    AcceptCommand(RemeshWidget* widget, const QString& text) : QUndoCommand(text), widget_(widget) {}
    void undo() override { widget_->undoStep(); }
    void redo() override {
        if (first_) {
            first_ = false;
            return;
        }
        widget_->redoStep();
    }

private:
    RemeshWidget* widget_;
    bool first_ = true;
};

/// A session file being replayed by loadSession (by SessionReplay): the new session is built there and
/// replaces the widget's only when every event has been applied.
struct RemeshWidget::Replay {
    QString path;     // the session file, as given
    QString meshPath; // its mesh
    bool cpuRenderer = false;
    std::unique_ptr<SessionReplay> engine;
};

struct RemeshWidget::Impl {
    std::unique_ptr<Session> session;
    QString meshPath; // the reference's file, if any
    // A mesh given to setMesh without a file, as given: its file (saveSession) reads back as the
    // reference, canonicalMesh(memoryInput) (canonicalMesh is not idempotent, so the reference itself
    // would not).
    std::optional<Mesh> memoryInput;
    bool cpuRenderer = false; // the session was made with the CPU renderer
    // Set by the session's renderer factory when the view could not give a GPU renderer.
    std::shared_ptr<std::atomic<bool>> cpuFallback = std::make_shared<std::atomic<bool>>(false);
    CurvatureOptions curvature; // the session's curvature options (saved in session files)
    std::unique_ptr<Replay> replay;
    std::shared_ptr<std::atomic<bool>> cpuFallbackPending; // the replayed session's cpuFallback
    bool syncingStack = false; // pushing / undoing commands that only mirror the session's history
    // A message for the user (an error, what an accept did, what a camera change dropped) shown in the
    // status line until the next action (scan, accept, reject, tool, settings, undo / redo).
    QString note;
    QScrollArea* sideScroll = nullptr;
    Mesh empty;
    // The GUI thread's copy of the session's current mesh: the worker may be replacing the session's
    // own while the GUI reads this one. Never changed once made (a mesh change makes a new one), so a
    // trial's thread reads it while the GUI goes on (no copy on the GUI thread when a scan starts a trial).
    std::shared_ptr<const Mesh> mesh = std::make_shared<const Mesh>();
    VtkView* view = nullptr;
    ScanPanel* scanPanel = nullptr;
    QualityPanel* qualityPanel = nullptr;
    QUndoStack* undoStack = nullptr;
    QUndoView* historyView = nullptr;
    NavigateTool* navigate = nullptr;
    LassoTool* lasso = nullptr;
    ScanTool* scanTool = nullptr;
    FishboneTool* fishbone = nullptr;
    Tool* active = nullptr;
    QAction *navigateAction = nullptr, *lassoAction = nullptr, *scanModeAction = nullptr,
            *fishboneAction = nullptr;
    QAction *scanAction = nullptr, *acceptAction = nullptr, *rejectAction = nullptr;
    QAction *directionAction = nullptr, *keyRibAction = nullptr, *drawBackboneAction = nullptr,
            *drawRibAction = nullptr, *ghostAction = nullptr;
    QAction *undoAction = nullptr, *redoAction = nullptr;
    QToolBar* toolBar = nullptr;
    QLabel* status = nullptr;
    QProgressBar* progress = nullptr;
    QPushButton* cancelButton = nullptr;
    QTimer* progressTimer = nullptr;

    std::shared_ptr<detail::Job> job;
    QThread* thread = nullptr;
    QString busyWhat;
    bool updatingView = false;
    bool fishbonePending = false;
    std::int32_t nextScanId = 0;
    // The trial stitch of the pending preview (null when none) and the thread running one (possibly an
    // abandoned one: the next trial starts when it has ended).
    std::shared_ptr<detail::Trial> trial;
    QThread* trialThread = nullptr;
    // Measures the trials' whole-mesh figures (a newer trial's measure stops an older one's).
    std::shared_ptr<FiguresMeasurer> figures = std::make_shared<FiguresMeasurer>();
};

} // namespace fss::widgets
