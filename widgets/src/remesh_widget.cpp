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
#include "view_bridge.h"

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

namespace fss::widgets {

namespace {

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

// Session options for a session of the widget: the view's GPU renderer (sharing its GL context; the CPU
// renderer when the view has none, which sets *cpuFallback) or, with cpuRenderer, the CPU renderer.
SessionOptions widgetSessionOptions(VtkView* view, bool cpuRenderer,
                                    const std::shared_ptr<std::atomic<bool>>& cpuFallback,
                                    const CurvatureOptions& curvature) {
    SessionOptions options;
    options.curvature = curvature;
    options.renderer = [view, cpuRenderer, cpuFallback]() -> std::unique_ptr<MeshRenderer> {
        if (!cpuRenderer) {
            try {
                if (auto renderer = view->createMeshRenderer()) return renderer;
            } catch (const std::exception&) {
                // No GL context yet (never shown) or no usable GL: the CPU renderer serves.
            }
        }
        if (!cpuRenderer) *cpuFallback = true;
        return std::make_unique<CpuMeshRenderer>();
    };
    return options;
}

QString sentence(const std::exception& e) {
    return QString::fromStdString(e.what());
}

// The standard view whose direction the camera looks along (within ~2.5°), else "custom view".
QString viewName(const Camera& camera) {
    const Eigen::Vector3d from = (camera.eye - camera.focal).normalized();
    const std::pair<Eigen::Vector3d, const char*> views[] = {{Eigen::Vector3d(1, 1, 1).normalized(), "iso"},
                                                             {{1, 0, 0}, "+X"},
                                                             {{-1, 0, 0}, "-X"},
                                                             {{0, 1, 0}, "+Y"},
                                                             {{0, -1, 0}, "-Y"},
                                                             {{0, 0, 1}, "+Z"},
                                                             {{0, 0, -1}, "-Z"}};
    for (const auto& [direction, name] : views)
        if (from.dot(direction) > 0.999) return RemeshWidget::tr("from %1").arg(QLatin1String(name));
    return RemeshWidget::tr("custom view");
}

// Mean length of the edges of \p mesh (0 without edges).
double meanEdgeLength(const Mesh& mesh) {
    double sum = 0;
    for (EdgeIndex e : mesh.edges())
        sum +=
            std::sqrt((mesh.point(mesh.source(mesh.halfedge(e))) - mesh.point(mesh.target(mesh.halfedge(e))))
                          .squared_length());
    return mesh.number_of_edges() > 0 ? sum / double(mesh.number_of_edges()) : 0;
}

// Whole-mesh figures shown before → after an accept (computeMetrics' figures, without its other measures:
// twice per accept, so they cost a fraction of its time): \p result's, or CancelledError when it was stopped.
MeshFigures figuresOf(const FiguresResult& result) {
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
    Mesh mesh; // the current mesh, stitched in place
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
            before = figuresOf(measurer->measure(mesh, stop.get_token()));
            progress.report(0.0, "stitch");
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

} // namespace

QString RemeshWidget::stepName(int number, const ScanStep& step) {
    const Camera& c = step.params.camera;
    const QString grid = step.fishbone       ? tr("fishbone grid")
                         : step.params.lasso ? tr("regular grid in a lasso")
                                             : tr("regular grid");
    return tr("%1. Scan %2, %3×%4 px, %5").arg(number).arg(viewName(c)).arg(c.width).arg(c.height).arg(grid);
}

QString RemeshWidget::acceptSummary(const StitchReport& report, double valence6Before, double valence6After,
                                    double minAngleBefore, double minAngleAfter) {
    // One entry per figure: a new StitchReport field is one more line here.
    QStringList parts;
    parts << tr("%1 faces replaced by %2").arg(report.facesRemoved).arg(report.facesAdded);
    parts << tr("valence 6 %1 % → %2 %")
                 .arg(100 * valence6Before, 0, 'f', 1)
                 .arg(100 * valence6After, 0, 'f', 1);
    parts << tr("min angle %1° → %2°").arg(minAngleBefore, 0, 'f', 1).arg(minAngleAfter, 0, 'f', 1);
    if (report.seamFaces > 0) {
        parts << tr("seam min angle %1°").arg(report.seamMinAngleDeg, 0, 'f', 1);
        parts << tr("seam faces ≥ 30° %1 %").arg(100 * report.seamFracMinAngleAbove30, 0, 'f', 1);
    }
    if (report.seamVertices > 0)
        parts << tr("seam valence 5–7 %1 %").arg(100 * report.seamFracValence5To7, 0, 'f', 1);
    return parts.join(QStringLiteral("; "));
}

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
    // own while the GUI reads this one.
    Mesh mesh;
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

    std::shared_ptr<Job> job;
    QThread* thread = nullptr;
    QString busyWhat;
    bool updatingView = false;
    bool fishbonePending = false;
    std::int32_t nextScanId = 0;
    // The trial stitch of the pending preview (null when none) and the thread running one (possibly an
    // abandoned one: the next trial starts when it has ended).
    std::shared_ptr<Trial> trial;
    QThread* trialThread = nullptr;
    // Measures the trials' whole-mesh figures (a newer trial's measure stops an older one's).
    std::shared_ptr<FiguresMeasurer> figures = std::make_shared<FiguresMeasurer>();
};

RemeshWidget::RemeshWidget(QWidget* parent) : QWidget(parent), d_(std::make_unique<Impl>()) {
    qRegisterMetaType<fss::StitchReport>("fss::StitchReport");
    Impl& d = *d_;
    d.view = new VtkView(this);
    d.view->setMinimumSize(200, 200);
    d.view->setAxesVisible(true);
    d.view->setFocusPolicy(Qt::StrongFocus);
    d.scanPanel = new ScanPanel(this);
    d.qualityPanel = new QualityPanel(this);
    d.undoStack = new QUndoStack(this);
    d.undoStack->setUndoLimit(100); // Session's default depth
    d.historyView = new QUndoView(d.undoStack, this);
    d.historyView->setEmptyLabel(tr("Input mesh"));
    d.navigate = new NavigateTool(d.view, this);
    d.lasso = new LassoTool(d.view, this);
    d.scanTool = new ScanTool(d.view, d.scanPanel, d.lasso, this);
    d.fishbone = new FishboneTool(d.view, this);

    createToolBar();

    d.undoAction = d.undoStack->createUndoAction(this, tr("&Undo"));
    d.undoAction->setShortcut(QKeySequence::Undo);
    d.redoAction = d.undoStack->createRedoAction(this, tr("&Redo"));
    // The platform's redo keys, and both of the common ones (Ctrl+Shift+Z, Ctrl+Y) wherever missing.
    QList<QKeySequence> redoKeys = QKeySequence::keyBindings(QKeySequence::Redo);
    for (const QKeySequence& k :
         {QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_Z), QKeySequence(Qt::CTRL | Qt::Key_Y)})
        if (!redoKeys.contains(k)) redoKeys << k;
    d.redoAction->setShortcuts(redoKeys);

    // Layout: tool bar; view | panels; status line with progress and Cancel.
    auto* side = new QWidget(this);
    auto* sideLayout = new QVBoxLayout(side);
    sideLayout->setContentsMargins(0, 0, 0, 0);
    auto group = [&](const QString& title, QWidget* content, int stretch) {
        auto* box = new QGroupBox(title, side);
        auto* l = new QVBoxLayout(box);
        l->setContentsMargins(4, 4, 4, 4);
        l->addWidget(content);
        sideLayout->addWidget(box, stretch);
    };
    group(tr("Scan"), d.scanPanel, 0);
    group(tr("Quality"), d.qualityPanel, 2);
    group(tr("History"), d.historyView, 1);
    // Sensible minimum sizes: below them the side panel scrolls instead of squeezing its parts.
    d.qualityPanel->setMinimumHeight(std::max(160, d.qualityPanel->minimumSizeHint().height()));
    d.historyView->setMinimumHeight(110);
    d.sideScroll = new QScrollArea(this);
    d.sideScroll->setWidget(side);
    d.sideScroll->setWidgetResizable(true);
    d.sideScroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
    d.sideScroll->setFrameShape(QFrame::NoFrame);
    d.sideScroll->setMinimumWidth(side->minimumSizeHint().width() + 20); // room for the vertical bar
    auto* splitter = new QSplitter(Qt::Horizontal, this);
    splitter->addWidget(d.view);
    splitter->addWidget(d.sideScroll);
    splitter->setStretchFactor(0, 1);
    splitter->setStretchFactor(1, 0);
    splitter->setChildrenCollapsible(false);

    d.status = new QLabel(this);
    d.status->setWordWrap(true);
    d.status->setObjectName(QStringLiteral("status"));
    // Always two lines high and never wider than the window: a message that wraps must not resize the view
    // (that re-renders the whole mesh and changes the scan size under the user's clicks).
    d.status->setFixedHeight(2 * d.status->fontMetrics().lineSpacing() + 2 * d.status->margin());
    d.status->setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Fixed);
    d.status->setAlignment(Qt::AlignLeft | Qt::AlignVCenter);
    d.view->installEventFilter(this); // a resize changes the scan size the status line tells
    d.progress = new QProgressBar(this);
    d.progress->setMaximumWidth(220);
    d.progress->setRange(0, 1000);
    d.progress->hide();
    d.cancelButton = new QPushButton(tr("Cancel"), this);
    d.cancelButton->hide();
    // Showing them must not change the layout: a resize of the view re-renders the whole mesh.
    for (QWidget* w : {static_cast<QWidget*>(d.progress), static_cast<QWidget*>(d.cancelButton)}) {
        QSizePolicy policy = w->sizePolicy();
        policy.setRetainSizeWhenHidden(true);
        w->setSizePolicy(policy);
    }
    connect(d.cancelButton, &QPushButton::clicked, this, &RemeshWidget::cancel);
    auto* statusRow = new QHBoxLayout;
    statusRow->addWidget(d.status, 1);
    statusRow->addWidget(d.progress);
    statusRow->addWidget(d.cancelButton);

    auto* layout = new QVBoxLayout(this);
    layout->setContentsMargins(0, 0, 0, 0);
    layout->addWidget(d.toolBar);
    layout->addWidget(splitter, 1);
    layout->addLayout(statusRow);

    d.progressTimer = new QTimer(this);
    d.progressTimer->setInterval(250);
    connect(d.progressTimer, &QTimer::timeout, this, [this] {
        if (isBusy() && d_->job) {
            d_->progress->setValue(int(1000 * d_->job->fraction.load()));
        } else if (d_->trial && d_->trialThread) {
            d_->progress->setValue(int(1000 * d_->trial->fraction.load()));
            updateStatus();
        }
    });

    // Wiring.
    for (Tool* tool : {static_cast<Tool*>(d.navigate), static_cast<Tool*>(d.lasso),
                       static_cast<Tool*>(d.scanTool), static_cast<Tool*>(d.fishbone)})
        connect(tool, &Tool::statusChanged, this, [this, tool] {
            if (tool == d_->active) updateStatus();
        });
    connect(d.scanTool, &ScanTool::scanRequested, this, [this] { scan(); });
    connect(d.scanTool, &ScanTool::acceptRequested, this, &RemeshWidget::accept);
    connect(d.scanTool, &ScanTool::rejectRequested, this, &RemeshWidget::reject);
    connect(d.fishbone, &FishboneTool::acceptRequested, this, &RemeshWidget::accept);
    connect(d.fishbone, &FishboneTool::paramsChanged, this, &RemeshWidget::runFishbone);
    connect(d.fishbone, &FishboneTool::paramsChanged, this, [this] {
        const QSignalBlocker a(d_->directionAction), b(d_->keyRibAction);
        d_->directionAction->setChecked(d_->fishbone->direction() == PrincipalDirection::Max);
        d_->keyRibAction->setChecked(d_->fishbone->ribMode() == FishboneTool::RibMode::KeyRibs);
    });
    connect(d.lasso, &LassoTool::lassoChanged, this,
            [this] { d_->scanTool->setPreviewPending(hasPreview()); });
    connect(d.scanPanel, &ScanPanel::settingsChanged, this, [this] {
        d_->note.clear();
        if (d_->fishbone->hasInput() && !isBusy()) runFishbone();
        updateStatus();
    });
    connect(d.scanPanel, &ScanPanel::scanRequested, this, [this] {
        if (d_->active == d_->fishbone) return; // the fishbone scans by itself
        scan();
    });
    connect(d.view, &VtkView::cameraChanged, this, [this] {
        if (d_->updatingView) return;
        // Lasso and fishbone strokes are screen positions of the old camera: they no longer apply and are
        // dropped. A preview (regular or fishbone) lies on the surface in world space: it stays, and the
        // status line says what was dropped.
        QStringList dropped;
        if (d_->lasso->hasLasso()) dropped << tr("the lasso");
        if (d_->fishbone->hasInput()) dropped << tr("the fishbone strokes");
        {
            const QSignalBlocker blocker(d_->fishbone); // no new fishbone scan: the preview is kept
            if (d_->fishbone->hasInput()) d_->fishbone->clear();
        }
        d_->lasso->clear();
        if (d_->session) // first: with a target edge length the resolution changes (settingsChanged)
            d_->scanPanel->updateEdgeLength(d_->view->camera(),
                                            boundingBox(d_->session->reference()).center());
        if (!dropped.isEmpty())
            setNote(hasPreview() ? tr("The view moved: %1 (drawn on the screen) dropped; the preview is kept "
                                      "— Accept or Reject it.")
                                       .arg(dropped.join(tr(" and ")))
                                 : tr("The view moved: %1 (drawn on the screen) dropped — draw again.")
                                       .arg(dropped.join(tr(" and "))));
    });

    d.navigateAction->setChecked(true);
    setActiveTool(d.navigate);
    setBusy(false);
}

// Tool bar: tools (exclusive), scan actions, fishbone options, ghost; every action with a tooltip.
void RemeshWidget::createToolBar() {
    Impl& d = *d_;
    d.toolBar = new QToolBar(this);
    d.toolBar->setToolButtonStyle(Qt::ToolButtonTextOnly);
    auto* tools = new QActionGroup(this);
    auto addTool = [&](Tool* tool) {
        QAction* a = d.toolBar->addAction(tool->name());
        a->setCheckable(true);
        tools->addAction(a);
        connect(a, &QAction::triggered, this, [this, tool] { setActiveTool(tool); });
        return a;
    };
    d.navigateAction = addTool(d.navigate);
    d.navigateAction->setToolTip(tr("Navigate: left drag rotates, middle or Shift+left drag pans, right "
                                    "drag or the wheel zooms, R frames the mesh"));
    d.lassoAction = addTool(d.lasso);
    d.lassoAction->setToolTip(tr("Lasso: drag around the region the next scan samples (Esc clears it); "
                                 "other buttons still navigate"));
    d.scanModeAction = addTool(d.scanTool);
    d.scanModeAction->setToolTip(tr("Scan mode: Enter takes a regular scan of the view, Enter again "
                                    "accepts it, Esc rejects it"));
    d.fishboneAction = addTool(d.fishbone);
    d.fishboneAction->setToolTip(tr("Fishbone: click a seed on a feature; the backbone follows a "
                                    "principal curvature direction and the ribs cross it, giving a grid "
                                    "aligned with the feature"));
    d.toolBar->addSeparator();
    d.scanAction = d.toolBar->addAction(tr("Take scan"), this, [this] { scan(); });
    d.scanAction->setToolTip(tr("Scan the view at the panel's resolution (inside the lasso, if any)"));
    d.acceptAction = d.toolBar->addAction(tr("Accept"), this, [this] { accept(); });
    d.acceptAction->setToolTip(tr("Stitch the blue preview into the mesh, replacing the faces under it "
                                  "where the scan is better (one undo step)"));
    d.rejectAction = d.toolBar->addAction(tr("Reject"), this, [this] { reject(); });
    d.rejectAction->setToolTip(tr("Drop the preview; the mesh stays as it is"));
    d.toolBar->addSeparator();
    d.directionAction = d.toolBar->addAction(tr("Max direction"));
    d.directionAction->setCheckable(true);
    d.directionAction->setToolTip(
        tr("Fishbone backbone along the maximal (checked) or minimal curvature (D)"));
    connect(d.directionAction, &QAction::toggled, this, [this](bool max) {
        d_->fishbone->setDirection(max ? PrincipalDirection::Max : PrincipalDirection::Min);
    });
    d.keyRibAction = d.toolBar->addAction(tr("Key-ribs"));
    d.keyRibAction->setCheckable(true);
    d.keyRibAction->setToolTip(tr("Place key-ribs on the backbone instead of automatic ribs (K)"));
    connect(d.keyRibAction, &QAction::toggled, this, [this](bool on) {
        d_->fishbone->setRibMode(on ? FishboneTool::RibMode::KeyRibs : FishboneTool::RibMode::Automatic);
    });
    d.drawBackboneAction = d.toolBar->addAction(tr("Draw backbone"));
    d.drawBackboneAction->setCheckable(true);
    d.drawBackboneAction->setToolTip(tr("Drag the fishbone's backbone by hand instead of tracing it "
                                        "from a seed along the curvature"));
    d.drawRibAction = d.toolBar->addAction(tr("Draw rib"));
    d.drawRibAction->setCheckable(true);
    d.drawRibAction->setToolTip(tr("Drag a rib across the backbone by hand; drawn ribs replace the "
                                   "automatic ones"));
    auto inputChanged = [this] {
        FishboneTool::InputMode mode = FishboneTool::InputMode::Pick;
        if (d_->drawBackboneAction->isChecked())
            mode = FishboneTool::InputMode::DrawBackbone;
        else if (d_->drawRibAction->isChecked())
            mode = FishboneTool::InputMode::DrawRib;
        d_->fishbone->setInputMode(mode);
    };
    connect(d.drawBackboneAction, &QAction::toggled, this, [this, inputChanged](bool on) {
        if (on) d_->drawRibAction->setChecked(false);
        inputChanged();
    });
    connect(d.drawRibAction, &QAction::toggled, this, [this, inputChanged](bool on) {
        if (on) d_->drawBackboneAction->setChecked(false);
        inputChanged();
    });
    d.toolBar->addSeparator();
    d.ghostAction = d.toolBar->addAction(tr("Ghost"));
    d.ghostAction->setCheckable(true);
    d.ghostAction->setToolTip(tr("Show the input mesh as a translucent ghost"));
    connect(d.ghostAction, &QAction::toggled, this, &RemeshWidget::setGhostVisible);
}

RemeshWidget::~RemeshWidget() {
    d_->view->removeEventFilter(this); // the view outlives d_
    if (d_->job) d_->job->stop.request_stop();
    if (d_->trial) d_->trial->stop.request_stop();
    if (d_->thread) {
        d_->thread->wait();
        delete d_->thread; // its finished() handler will not run any more
        d_->thread = nullptr;
    }
    if (d_->trialThread) {
        d_->trialThread->wait(); // it only uses its own copies, and stops at its next progress report
        delete d_->trialThread;
        d_->trialThread = nullptr;
    }
    for (Tool* tool : {static_cast<Tool*>(d_->navigate), static_cast<Tool*>(d_->lasso),
                       static_cast<Tool*>(d_->scanTool), static_cast<Tool*>(d_->fishbone)})
        tool->deactivate();
    d_->undoStack->clear();
    d_->replay.reset();
    d_->session.reset(); // its renderers may use the view's GL context: before the view goes
}

bool RemeshWidget::setMesh(const Mesh& mesh, const QString& meshPath) {
    waitForWork();
    if (d_->replay) {
        reportError(tr("A session is being loaded: cancel it before setting a mesh."));
        return false;
    }
    auto fallback = std::make_shared<std::atomic<bool>>(false);
    std::unique_ptr<Session> session;
    try {
        // From memory: the layout a file of it would read back as, so saved sessions replay exactly.
        session = std::make_unique<Session>(meshPath.isEmpty() ? canonicalMesh(mesh) : mesh,
                                            widgetSessionOptions(d_->view, false, fallback, {}));
    } catch (const std::exception& e) {
        reportError(sentence(e));
        return false;
    }
    d_->cpuFallback = fallback;
    installSession(std::move(session), meshPath, false, {});
    if (meshPath.isEmpty()) d_->memoryInput = mesh;
    return true;
}

void RemeshWidget::installSession(std::unique_ptr<Session> session, const QString& meshPath, bool cpuRenderer,
                                  const CurvatureOptions& curvature) {
    stopTrial(); // it belongs to the old session
    d_->undoStack->clear();
    d_->session = std::move(session);
    d_->meshPath = meshPath;
    d_->memoryInput.reset();
    d_->cpuRenderer = cpuRenderer;
    d_->curvature = curvature;
    d_->mesh = d_->session->current();
    // Mirror the session's history on the undo stack: applied steps, then the redo-able ones undone.
    const std::vector<ScanStep> steps = d_->session->steps();
    d_->syncingStack = true;
    for (std::size_t i = 0; i < steps.size(); ++i)
        d_->undoStack->push(new AcceptCommand(this, stepName(int(i) + 1, steps[i])));
    for (std::size_t i = 0; i < d_->session->redoCount(); ++i)
        d_->undoStack->undo();
    d_->syncingStack = false;
    std::int32_t nextId = 0;
    for (const SessionEvent& e : d_->session->events())
        if (e.kind == SessionEvent::Kind::Accept) nextId = std::max(nextId, e.step.params.scan.scanId + 1);
    d_->nextScanId = nextId;
    d_->lasso->clear();
    d_->fishbone->clear();
    d_->view->clearPreviewMesh();
    d_->updatingView = true;
    d_->view->setMesh(d_->mesh);
    d_->updatingView = false;
    setGhostVisible(ghost_);
    d_->qualityPanel->setMesh(d_->mesh);
    d_->scanPanel->updateEdgeLength(d_->view->camera(), boundingBox(d_->session->reference()).center());
    d_->scanPanel->setInputEdgeLength(meanEdgeLength(d_->session->reference()));
    d_->scanTool->setPreviewPending(false);
    d_->undoAction->setEnabled(!isBusy() && d_->undoStack->canUndo());
    d_->redoAction->setEnabled(!isBusy() && d_->undoStack->canRedo());
    updateStatus();
    emit previewChanged();
    emit meshChanged();
}

bool RemeshWidget::openMesh(const QString& path) {
    Mesh mesh;
    try {
        mesh = readMesh(path.toStdString());
    } catch (const std::exception& e) {
        reportError(sentence(e));
        return false;
    }
    return setMesh(mesh, path);
}

QString RemeshWidget::meshPath() const {
    return d_->meshPath;
}

bool RemeshWidget::saveSession(const QString& path) {
    waitForWork();
    try {
        if (!d_->session) throw InvalidInputError("There is no session to save: open a mesh first.");
        if (path.isEmpty()) throw InvalidInputError("The session file name is empty.");
        const std::filesystem::path file = path.toStdString();
        std::filesystem::path meshFile = d_->meshPath.toStdString();
        if (meshFile.empty()) {
            // The reference came from memory: write it next to the session file, exactly.
            // Binary PLY: doubles, face quality and scan ids as they are. The mesh as given reads back as
            // canonicalMesh of it, the reference setMesh made.
            meshFile = file.parent_path() / (file.stem().string() + ".input.ply");
            WriteOptions exact;
            exact.binary = true;
            writeMesh(d_->memoryInput ? *d_->memoryInput : d_->session->reference(), meshFile, exact);
        }
        const bool cpu = d_->cpuRenderer || d_->cpuFallback->load();
        saveSessionFile(sessionFileFromSession(*d_->session, meshFile, cpu ? "cpu" : "gpu", d_->curvature),
                        file);
        if (d_->meshPath.isEmpty()) {
            d_->meshPath = QString::fromStdString(meshFile.string());
            d_->memoryInput.reset();
        }
    } catch (const std::exception& e) {
        reportError(sentence(e));
        return false;
    }
    return true;
}

bool RemeshWidget::isLoadingSession() const {
    return d_->replay != nullptr;
}

bool RemeshWidget::loadSession(const QString& path) {
    if (isBusy()) {
        reportError(tr("Work is running: wait for it or cancel it before loading a session."));
        return false;
    }
    auto r = std::make_unique<Replay>();
    r->path = path;
    auto fallback = std::make_shared<std::atomic<bool>>(false);
    try {
        SessionFile file = loadSessionFile(path.toStdString());
        r->meshPath = QString::fromStdString(file.meshPath.string());
        r->cpuRenderer = file.renderer == "cpu";
        const RendererFactory renderer =
            widgetSessionOptions(d_->view, r->cpuRenderer, fallback, file.curvature).renderer;
        r->engine = std::make_unique<SessionReplay>(std::move(file), renderer);
    } catch (const std::exception& e) {
        reportError(sentence(e));
        return false;
    }
    d_->replay = std::move(r);
    d_->cpuFallbackPending = fallback;
    setBusy(true, tr("Replaying %1").arg(QFileInfo(path).fileName()));
    replayNext();
    return true;
}

void RemeshWidget::failReplay(const QString& message) {
    d_->replay.reset();
    d_->cpuFallbackPending.reset();
    setBusy(false);
    if (message.isEmpty())
        setNote(tr("Loading the session was cancelled; the previous mesh is kept."));
    else
        reportError(message);
}

void RemeshWidget::replayNext() {
    Replay& r = *d_->replay;
    SessionReplay* replay = r.engine.get();
    const auto where = [&r](std::size_t i, const QString& why) {
        return tr("%1, events[%2]: %3").arg(QFileInfo(r.path).fileName()).arg(i).arg(why);
    };
    // Undo and redo here; a scan on the GUI thread (it needs the view's GL context), its stitch and the
    // reference's curvature on the worker thread.
    while (!replay->done()) {
        if (d_->job->stop.stop_requested()) return failReplay({});
        const std::size_t i = replay->nextEvent();
        d_->job->base = double(i) / double(replay->eventCount());
        d_->job->span = 1.0 / double(replay->eventCount());
        d_->job->fraction = d_->job->base;
        try {
            if (replay->file().events[i].kind != SessionEvent::Kind::Accept) {
                replay->finishNext();
                continue;
            }
            if (replay->needsFishboneCache()) {
                // The curvature of the reference, once, on the worker thread; then this event again.
                startWork([replay](const Progress& progress) { replay->buildFishboneCache(progress); },
                          [this, where, i] {
                              if (!d_->job->error.empty())
                                  return failReplay(where(i, QString::fromStdString(d_->job->error)));
                              if (d_->job->cancelled) return failReplay({});
                              replayNext();
                          });
                return;
            }
            replay->scanNext();
        } catch (const std::exception& ex) {
            return failReplay(where(i, sentence(ex)));
        }
        startWork([replay](const Progress& progress) { replay->finishNext(progress); },
                  [this, where, i] {
                      if (!d_->job->error.empty())
                          return failReplay(where(i, QString::fromStdString(d_->job->error)));
                      if (d_->job->cancelled) return failReplay({});
                      replayNext();
                  });
        return;
    }
    finishReplay();
}

void RemeshWidget::finishReplay() {
    std::unique_ptr<Replay> r = std::move(d_->replay);
    const bool fellBack = !r->cpuRenderer && d_->cpuFallbackPending->load();
    d_->cpuFallback = std::move(d_->cpuFallbackPending);
    setBusy(false);
    const CurvatureOptions curvature = r->engine->file().curvature;
    installSession(r->engine->takeSession(), r->meshPath, r->cpuRenderer, curvature);
    if (fellBack)
        setNote(tr("The session was recorded with the GPU renderer, which this view cannot give; it was "
                   "replayed with the CPU renderer and may differ slightly."));
    emit sessionLoaded(r->path);
}

const Mesh& RemeshWidget::mesh() const {
    return d_->mesh;
}
const Mesh& RemeshWidget::referenceMesh() const {
    return d_->session ? d_->session->reference() : d_->empty;
}

bool RemeshWidget::saveMesh(const QString& path) {
    try {
        if (!d_->session) throw InvalidInputError("There is no mesh to save: open a mesh first.");
        // Any format of fss/render/fem_io.h, with the reference's face groups carried to the new faces.
        Mesh out = mesh();
        if (hasFaceGroups(d_->session->reference())) transferFaceGroups(d_->session->reference(), out);
        render::writeMeshFile(out, path.toStdString());
    } catch (const std::exception& e) {
        reportError(sentence(e));
        return false;
    }
    return true;
}

QUndoStack* RemeshWidget::undoStack() const {
    return d_->undoStack;
}
QAction* RemeshWidget::undoAction() const {
    return d_->undoAction;
}
QAction* RemeshWidget::redoAction() const {
    return d_->redoAction;
}
QAction* RemeshWidget::scanAction() const {
    return d_->scanAction;
}
QAction* RemeshWidget::acceptAction() const {
    return d_->acceptAction;
}
QAction* RemeshWidget::rejectAction() const {
    return d_->rejectAction;
}
VtkView* RemeshWidget::view() const {
    return d_->view;
}
ScanPanel* RemeshWidget::scanPanel() const {
    return d_->scanPanel;
}
QualityPanel* RemeshWidget::qualityPanel() const {
    return d_->qualityPanel;
}
QUndoView* RemeshWidget::historyView() const {
    return d_->historyView;
}
NavigateTool* RemeshWidget::navigateTool() const {
    return d_->navigate;
}
LassoTool* RemeshWidget::lassoTool() const {
    return d_->lasso;
}
ScanTool* RemeshWidget::scanTool() const {
    return d_->scanTool;
}
FishboneTool* RemeshWidget::fishboneTool() const {
    return d_->fishbone;
}
Tool* RemeshWidget::activeTool() const {
    return d_->active;
}
const Session* RemeshWidget::session() const {
    return d_->session.get();
}
bool RemeshWidget::hasPreview() const {
    return d_->session && !isBusy() && d_->session->preview();
}
bool RemeshWidget::eventFilter(QObject* watched, QEvent* event) {
    if (d_ && watched == d_->view && event->type() == QEvent::Resize) {
        // The scan size and the edge length follow the view's size.
        if (d_->session)
            d_->scanPanel->updateEdgeLength(d_->view->camera(),
                                            boundingBox(d_->session->reference()).center());
        updateStatus();
    }
    return QWidget::eventFilter(watched, event);
}

bool RemeshWidget::isBusy() const {
    return d_->thread != nullptr || d_->replay != nullptr;
}
QString RemeshWidget::statusText() const {
    return d_->status->text();
}

void RemeshWidget::setActiveTool(Tool* tool) {
    if (!tool || tool == d_->active) return;
    d_->note.clear();
    if (d_->active) d_->active->deactivate();
    d_->active = tool;
    tool->activate();
    const std::pair<Tool*, QAction*> actions[] = {{d_->navigate, d_->navigateAction},
                                                  {d_->lasso, d_->lassoAction},
                                                  {d_->scanTool, d_->scanModeAction},
                                                  {d_->fishbone, d_->fishboneAction}};
    for (const auto& [t, a] : actions) {
        const QSignalBlocker blocker(a);
        a->setChecked(t == tool);
    }
    const bool fishbone = tool == d_->fishbone;
    for (QAction* a : {d_->directionAction, d_->keyRibAction, d_->drawBackboneAction, d_->drawRibAction})
        a->setVisible(fishbone);
    updateStatus();
}

bool RemeshWidget::scan() {
    if (isBusy()) return false;
    d_->note.clear();
    if (!d_->session) {
        reportError(tr("There is no mesh to scan: open a mesh first."));
        return false;
    }
    try {
        const ScanStep step = d_->scanTool->step(d_->nextScanId);
        d_->session->scan(step);
        ++d_->nextScanId;
    } catch (const std::exception& e) {
        reportError(sentence(e));
        return false;
    }
    showPreview();
    return true;
}

void RemeshWidget::runFishbone() {
    if (!d_->session) return;
    if (isBusy()) {
        d_->fishbonePending = true;
        return;
    }
    d_->fishbonePending = false;
    FishboneTool* tool = d_->fishbone;
    Session& session = *d_->session;
    const bool fishbonePreview = session.preview() && session.preview()->step.fishbone.has_value();
    if (!tool->hasInput()) {
        if (fishbonePreview) {
            session.reject();
            showPreview();
        }
        return;
    }
    // The curvature of the reference and its AABB tree are computed once, on the worker thread.
    FishboneCache& cache = session.fishboneCache();
    if (!cache.hasCurvature(session.reference()) || !cache.hasRayCaster(session.reference())) {
        Session* s = &session;
        auto work = [s](const Progress& progress) {
            s->fishboneCache().curvature(s->reference(), {}, progress);
            progress.report(0.95, "ray caster");
            s->fishboneCache().rayCaster(s->reference());
        };
        // Started through the job runner below; on success the fishbone scan is run.
        d_->fishbonePending = true;
        setBusy(true, tr("Estimating the curvature of the input mesh"));
        startWork(work, [this] {
            const std::shared_ptr<Job> job = d_->job;
            setBusy(false);
            if (!job->error.empty()) {
                d_->fishbonePending = false;
                d_->fishbone->setProblem(QString::fromStdString(job->error));
                reportError(QString::fromStdString(job->error));
            } else if (job->cancelled) {
                d_->fishbonePending = false;
                d_->fishbone->clear();
                setNote(tr("The curvature estimate was cancelled."));
            } else if (d_->fishbonePending) {
                runFishbone();
            }
        });
        return;
    }
    try {
        ScanStep step = d_->scanTool->step(d_->nextScanId);
        const QSize size(step.params.camera.width, step.params.camera.height);
        step.fishbone = tool->params(size, d_->scanPanel->fishboneSpacing());
        if (!step.fishbone) return;
        step.fishbone->samplingFactor = d_->scanPanel->fishboneSamplingFactor();
        const ScanPreview& preview = session.scan(step);
        ++d_->nextScanId;
        tool->setGrid(preview.fishbone ? &*preview.fishbone : nullptr, size);
        if (tool->backboneOnly()) session.reject(); // traced only to show the backbone
    } catch (const std::exception& e) {
        // A failed scan keeps the previous preview: drop it, it belongs to other input.
        session.reject();
        tool->setGrid(nullptr, {});
        tool->setProblem(sentence(e));
    }
    showPreview();
}

void RemeshWidget::accept() {
    if (isBusy()) return;
    d_->note.clear();
    if (!d_->session || !d_->session->preview()) {
        reportError(tr("There is no scan to accept: take a scan first."));
        return;
    }
    Session* s = d_->session.get();
    const QString name = stepName(d_->undoStack->index() + 1, s->preview()->step);
    auto report = std::make_shared<StitchReport>();
    auto figures = std::make_shared<std::pair<MeshFigures, MeshFigures>>();
    // A finished trial of this preview already measured the mesh before and after the stitch (the stitch is
    // deterministic: Session::accept makes the trial's mesh). A running trial is abandoned.
    const bool reuse = d_->trial && d_->trial->succeeded();
    if (reuse) *figures = {d_->trial->before, d_->trial->after};
    stopTrial();
    setBusy(true, tr("Stitching the scan into the mesh"));
    startWork(
        [s, report, figures, reuse, stop = d_->job->stop.get_token()](const Progress& progress) {
            // Cancel stops the measure before the stitch; the one after it runs to its end (the accept is
            // committed by then).
            if (!reuse) figures->first = figuresOf(FiguresMeasurer::measureAlone(s->current(), stop));
            *report = s->accept(progress);
            if (!reuse) figures->second = figuresOf(FiguresMeasurer::measureAlone(s->current()));
        },
        [this, report, name, figures] {
            const std::shared_ptr<Job> job = d_->job;
            setBusy(false);
            if (!job->error.empty()) {
                reportError(QString::fromStdString(job->error));
                return;
            }
            if (job->cancelled) {
                setNote(tr("Stitching was cancelled; the preview is kept."));
                return;
            }
            const QString summary = acceptSummary(*report, figures->first.valence6, figures->second.valence6,
                                                  figures->first.minAngle, figures->second.minAngle);
            d_->undoStack->push(new AcceptCommand(this, name + QStringLiteral(" — ") + summary));
            if (d_->fishbone->hasInput()) {
                const QSignalBlocker blocker(d_->fishbone); // the accepted grid is done: no rescan
                d_->fishbone->clear();
            }
            d_->lasso->clear();
            afterMeshChange();
            setNote(tr("Accepted: %1.").arg(summary));
            emit scanAccepted(*report);
        });
}

void RemeshWidget::startWork(std::function<void(const Progress&)> work, std::function<void()> done) {
    auto job = d_->job;
    d_->thread = QThread::create([job, work = std::move(work)] {
        const Progress progress([job](double f, std::string_view stage) {
            job->fraction = job->base + job->span * f;
            {
                const std::lock_guard lock(job->mutex);
                job->stage = std::string(stage);
            }
            // Never cancel on the final report: the work is committed by then.
            return f >= 1.0 || !job->stop.stop_requested();
        });
        try {
            work(progress);
        } catch (const CancelledError&) {
            job->cancelled = true;
        } catch (const std::exception& e) {
            job->error = e.what();
        }
    });
    QThread* thread = d_->thread;
    connect(thread, &QThread::finished, this, [this, thread, done = std::move(done)] {
        thread->deleteLater();
        d_->thread = nullptr;
        done();
    });
    thread->start();
}

void RemeshWidget::reject() {
    if (isBusy() || !d_->session) return;
    d_->note.clear();
    d_->session->reject();
    if (d_->fishbone->hasInput()) {
        const QSignalBlocker blocker(d_->fishbone);
        d_->fishbone->clear();
    }
    showPreview();
}

void RemeshWidget::cancel() {
    if (isBusy()) {
        if (d_->job) d_->job->stop.request_stop();
    } else if (d_->trial && d_->trialThread && !d_->trial->finished) {
        d_->trial->stop.request_stop();
    } else {
        return;
    }
    d_->status->setText(tr("Cancelling…"));
}

void RemeshWidget::setGhostVisible(bool visible) {
    ghost_ = visible;
    if (d_->ghostAction->isChecked() != visible) {
        const QSignalBlocker blocker(d_->ghostAction);
        d_->ghostAction->setChecked(visible);
    }
    if (visible && d_->session)
        d_->view->setGhostMesh(d_->session->reference());
    else
        d_->view->clearGhostMesh();
}

void RemeshWidget::undoStep() {
    if (d_->syncingStack) return; // the stack only mirrors the session's history
    waitForWork();
    d_->note.clear();
    try {
        d_->session->undo();
    } catch (const std::exception& e) {
        reportError(sentence(e));
        return;
    }
    afterMeshChange();
}

void RemeshWidget::redoStep() {
    if (d_->syncingStack) return;
    waitForWork();
    d_->note.clear();
    try {
        d_->session->redo();
    } catch (const std::exception& e) {
        reportError(sentence(e));
        return;
    }
    afterMeshChange();
}

void RemeshWidget::afterMeshChange() {
    d_->mesh = d_->session->current();
    d_->updatingView = true;
    bridge::showMeshKeepCamera(d_->view, d_->mesh);
    d_->updatingView = false;
    d_->qualityPanel->setMesh(d_->mesh);
    showPreview();
    emit meshChanged();
}

void RemeshWidget::showPreview() {
    const ScanPreview* preview = d_->session ? d_->session->preview() : nullptr;
    updateTrial(); // drops a trial of another preview, starts this one's
    if (preview && d_->trial && d_->trial->finished && !d_->trial->cancelled)
        d_->view->setPreviewMesh(preview->patch.mesh, d_->trial->stitched);
    else if (preview)
        d_->view->setPreviewMesh(preview->patch.mesh);
    else
        d_->view->clearPreviewMesh();
    d_->scanTool->setPreviewPending(preview != nullptr);
    d_->acceptAction->setEnabled(preview != nullptr && !isBusy());
    d_->rejectAction->setEnabled(preview != nullptr && !isBusy());
    updateStatus();
    emit previewChanged();
}

bool RemeshWidget::isTrialRunning() const {
    return d_->trial && !d_->trial->finished;
}
const Mesh* RemeshWidget::trialMesh() const {
    return d_->trial && d_->trial->succeeded() ? &d_->trial->mesh : nullptr;
}
const StitchReport* RemeshWidget::trialReport() const {
    return d_->trial && d_->trial->succeeded() ? &d_->trial->report : nullptr;
}
const std::vector<std::uint8_t>* RemeshWidget::trialStitchedFaces() const {
    return d_->trial && d_->trial->succeeded() ? &d_->trial->stitched : nullptr;
}

// Keeps d_->trial on the pending preview: none without one (or while work runs: an accept consumes it),
// else this preview's, started when no trial thread runs (an abandoned one is asked to stop; its end
// starts the next).
void RemeshWidget::updateTrial() {
    const ScanPreview* preview = d_->session && !isBusy() ? d_->session->preview() : nullptr;
    if (d_->trial && (!preview || d_->trial->session != d_->session.get() ||
                      d_->trial->scanId != preview->step.params.scan.scanId))
        stopTrial();
    if (preview && !d_->trial && !d_->trialThread) startTrial();
}

void RemeshWidget::stopTrial() {
    if (d_->trial) d_->trial->stop.request_stop();
    d_->trial.reset();
}

void RemeshWidget::startTrial() {
    const ScanPreview& p = *d_->session->preview();
    auto t = std::make_shared<Trial>();
    t->session = d_->session.get();
    t->scanId = p.step.params.scan.scanId;
    t->measurer = d_->figures;
    // The inputs of Session::accept, copied: the thread never touches the session.
    t->mesh = d_->mesh;
    t->patch = p.patch.mesh;
    t->camera = p.step.fishbone ? fishboneSamplingCamera(p.step.params.camera, *p.step.fishbone)
                                : p.step.params.camera;
    t->options = p.step.stitch;
    t->options.collectGarbage = true;
    t->faceIds = p.currentBuffers.faceId;
    d_->trial = t;
    d_->trialThread = QThread::create([t] { t->run(); });
    QThread* thread = d_->trialThread;
    connect(thread, &QThread::finished, this, [this, thread, t] {
        thread->deleteLater();
        d_->trialThread = nullptr;
        t->finished = true;
        if (t == d_->trial) finishTrial();
        updateTrial(); // a newer preview may be waiting for its trial
        if (!d_->trialThread && !isBusy()) {
            d_->progressTimer->stop();
            d_->progress->hide();
            d_->cancelButton->hide();
        }
        updateStatus();
    });
    if (!isBusy()) {
        d_->progress->setRange(0, 1000);
        d_->progress->setValue(0);
        d_->progress->show();
        d_->cancelButton->show();
        d_->progressTimer->start();
    }
    thread->start();
}

// The trial of the pending preview has ended: shade what the stitch keeps.
void RemeshWidget::finishTrial() {
    const Trial& t = *d_->trial;
    const ScanPreview* preview = d_->session->preview();
    if (preview && !t.cancelled) d_->view->setPreviewMesh(preview->patch.mesh, t.stitched);
    updateStatus();
    emit trialFinished();
}

// What the status line adds about the trial of the pending preview.
QString RemeshWidget::trialText() const {
    if (!d_->trial) return {};
    const Trial& t = *d_->trial;
    if (!t.finished) return tr("Checking what the stitch keeps… %1 %").arg(int(100 * t.fraction.load()));
    if (t.cancelled) return tr("The check of what the stitch keeps was cancelled.");
    if (!t.error.empty())
        return tr("The stitch would keep none of this scan (red): %1").arg(QString::fromStdString(t.error));
    const std::size_t total = t.patch.number_of_faces();
    const std::size_t kept = total - std::min(total, t.report.patchFacesTrimmed);
    if (kept == total) return tr("All %1 patch faces will be stitched.").arg(total);
    return tr("%1 of %2 patch faces will be stitched; the red ones are trimmed (the mesh stays as it is "
              "there).")
        .arg(kept)
        .arg(total);
}

void RemeshWidget::reportError(const QString& message) {
    setNote(message);
    emit errorOccurred(message);
}

void RemeshWidget::setNote(const QString& text) {
    d_->note = text;
    updateStatus();
}

void RemeshWidget::setBusy(bool busy, const QString& what) {
    if (busy) {
        d_->job = std::make_shared<Job>();
        d_->busyWhat = what;
        d_->progress->setFormat(QStringLiteral("%p%"));
        d_->progress->setRange(0, 1000);
        d_->progress->setValue(0);
        d_->progress->show();
        d_->cancelButton->show();
        d_->progressTimer->start();
    } else {
        d_->progressTimer->stop();
        d_->progress->hide();
        d_->cancelButton->hide();
        d_->busyWhat.clear();
    }
    for (Tool* tool :
         {static_cast<Tool*>(d_->lasso), static_cast<Tool*>(d_->scanTool), static_cast<Tool*>(d_->fishbone)})
        tool->setEnabled(!busy);
    for (QAction* a : {d_->lassoAction, d_->scanModeAction, d_->fishboneAction, d_->scanAction,
                       d_->directionAction, d_->keyRibAction, d_->drawBackboneAction, d_->drawRibAction})
        a->setEnabled(!busy);
    const bool preview = !busy && d_->session && d_->session->preview();
    d_->acceptAction->setEnabled(preview);
    d_->rejectAction->setEnabled(preview);
    d_->undoAction->setEnabled(!busy && d_->undoStack->canUndo());
    d_->redoAction->setEnabled(!busy && d_->undoStack->canRedo());
    d_->historyView->setEnabled(!busy);
    d_->scanPanel->setEnabled(!busy);
    updateStatus();
    if (busy || d_->job) emit busyChanged(busy);
}

void RemeshWidget::updateStatus() {
    QString text;
    if (isBusy() || !d_->busyWhat.isEmpty())
        text = d_->busyWhat + tr("… (Cancel stops it)");
    else if (!d_->note.isEmpty())
        text = d_->note;
    else if (!d_->session)
        text = tr("Open a mesh to start.");
    else if (hasPreview() && d_->active != d_->fishbone)
        text = d_->scanTool->statusText(); // what to do with the preview, whichever tool is active
    else if (d_->active)
        text = d_->active->statusText();
    if (!isBusy() && d_->busyWhat.isEmpty() && d_->note.isEmpty() && hasPreview()) {
        const QString trial = trialText();
        if (!trial.isEmpty()) text += QLatin1Char(' ') + trial;
    }
    if (text == d_->status->text()) return;
    d_->status->setText(text);
    emit statusChanged(text);
}

void RemeshWidget::waitForWork() {
    if (!d_->thread) return;
    d_->thread->wait();
    // Deliver the finished() handler now, so the job's result is applied before the caller continues.
    QCoreApplication::sendPostedEvents(this);
    QCoreApplication::processEvents(QEventLoop::ExcludeUserInputEvents);
}

} // namespace fss::widgets

#include "fss/widgets/moc_remesh_widget.cpp" // meta-object code compiled here: widgets/CMakeLists.txt says why
