#include "fss/widgets/remesh_widget.h"

#include "fss/error.h"
#include "fss/mesh_io.h"
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
#include <QElapsedTimer>
#include <QEventLoop>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QSplitter>
#include <QThread>
#include <QTimer>
#include <QToolBar>
#include <QUndoCommand>
#include <QUndoStack>
#include <QUndoView>
#include <QVBoxLayout>

#include <atomic>
#include <functional>
#include <mutex>
#include <string>

namespace fss::widgets {

namespace {

// State shared between the GUI thread and one worker job.
struct Job {
    std::atomic<bool> cancel{false};
    std::atomic<double> fraction{0.0};
    std::mutex mutex;
    std::string stage;
    std::string error; // set by the worker on failure
    bool cancelled = false;
};

QString sentence(const std::exception& e) {
    return QString::fromStdString(e.what());
}

} // namespace

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

struct RemeshWidget::Impl {
    std::unique_ptr<Session> session;
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
    QElapsedTimer busyClock;
    bool updatingView = false;
    bool fishbonePending = false;
    std::int32_t nextScanId = 0;
};

RemeshWidget::RemeshWidget(QWidget* parent) : QWidget(parent), d_(std::make_unique<Impl>()) {
    qRegisterMetaType<fss::StitchReport>("fss::StitchReport");
    Impl& d = *d_;
    d.view = new VtkView(this);
    d.view->setMinimumSize(200, 200);
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

    // Tool bar: tools (exclusive), scan actions, fishbone options, ghost.
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
    d.lassoAction = addTool(d.lasso);
    d.scanModeAction = addTool(d.scanTool);
    d.fishboneAction = addTool(d.fishbone);
    d.toolBar->addSeparator();
    d.scanAction = d.toolBar->addAction(tr("Take scan"), this, [this] { scan(); });
    d.scanAction->setToolTip(tr("Scan the view at the panel's resolution (inside the lasso, if any)"));
    d.acceptAction = d.toolBar->addAction(tr("Accept"), this, [this] { accept(); });
    d.rejectAction = d.toolBar->addAction(tr("Reject"), this, [this] { reject(); });
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
    d.drawRibAction = d.toolBar->addAction(tr("Draw rib"));
    d.drawRibAction->setCheckable(true);
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
    d.ghostAction->setEnabled(bridge::features().contains(QLatin1String("ghost")));
    connect(d.ghostAction, &QAction::toggled, this, &RemeshWidget::setGhostVisible);

    d.undoAction = d.undoStack->createUndoAction(this, tr("&Undo"));
    d.undoAction->setShortcut(QKeySequence::Undo);
    d.redoAction = d.undoStack->createRedoAction(this, tr("&Redo"));
    d.redoAction->setShortcut(QKeySequence::Redo);

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
    auto* splitter = new QSplitter(Qt::Horizontal, this);
    splitter->addWidget(d.view);
    splitter->addWidget(side);
    splitter->setStretchFactor(0, 1);
    splitter->setStretchFactor(1, 0);
    splitter->setChildrenCollapsible(false);

    d.status = new QLabel(this);
    d.status->setWordWrap(true);
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
        if (!d_->job) return;
        if (d_->progress->maximum() == 0x7fffffff) {
            d_->progress->setValue(int(d_->busyClock.elapsed() / 1000)); // elapsed seconds
            return;
        }
        d_->progress->setValue(int(1000 * d_->job->fraction.load()));
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
        if (d_->fishbone->hasInput() && !isBusy()) runFishbone();
        updateStatus();
    });
    connect(d.view, &VtkView::cameraChanged, this, [this] {
        if (d_->updatingView) return;
        // Lasso and fishbone positions are screen positions of the old camera: they no longer apply.
        d_->lasso->clear();
        if (d_->fishbone->hasInput()) d_->fishbone->clear();
        bridge::refreshPreview(d_->view);
        if (d_->session)
            d_->scanPanel->updateEdgeLength(d_->view->camera(),
                                            boundingBox(d_->session->reference()).center());
    });

    d.navigateAction->setChecked(true);
    setActiveTool(d.navigate);
    setBusy(false);
}

RemeshWidget::~RemeshWidget() {
    if (d_->job) d_->job->cancel = true;
    if (d_->thread) {
        d_->thread->wait();
        delete d_->thread; // its finished() handler will not run any more
        d_->thread = nullptr;
    }
    for (Tool* tool : {static_cast<Tool*>(d_->navigate), static_cast<Tool*>(d_->lasso),
                       static_cast<Tool*>(d_->scanTool), static_cast<Tool*>(d_->fishbone)})
        tool->deactivate();
    d_->undoStack->clear();
    d_->session.reset(); // its renderers may use the view's GL context: before the view goes
}

bool RemeshWidget::setMesh(const Mesh& mesh) {
    waitForWork();
    std::unique_ptr<Session> session;
    try {
        SessionOptions options;
        VtkView* view = d_->view;
        options.renderer = [view]() -> std::unique_ptr<MeshRenderer> {
            if (auto renderer = bridge::createRenderer(view)) return renderer;
            return std::make_unique<CpuMeshRenderer>();
        };
        session = std::make_unique<Session>(mesh, std::move(options));
    } catch (const std::exception& e) {
        reportError(sentence(e));
        return false;
    }
    d_->undoStack->clear();
    d_->session = std::move(session);
    d_->mesh = d_->session->current();
    d_->nextScanId = 0;
    d_->lasso->clear();
    d_->fishbone->clear();
    bridge::setPreview(d_->view, nullptr);
    d_->updatingView = true;
    d_->view->setMesh(d_->mesh);
    d_->updatingView = false;
    setGhostVisible(ghost_);
    d_->qualityPanel->setMesh(d_->mesh);
    d_->scanPanel->updateEdgeLength(d_->view->camera(), boundingBox(d_->session->reference()).center());
    d_->scanTool->setPreviewPending(false);
    updateStatus();
    emit previewChanged();
    emit meshChanged();
    return true;
}

bool RemeshWidget::openMesh(const QString& path) {
    Mesh mesh;
    try {
        mesh = readMesh(path.toStdString());
    } catch (const std::exception& e) {
        reportError(sentence(e));
        return false;
    }
    return setMesh(mesh);
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
        writeMesh(mesh(), path.toStdString());
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
bool RemeshWidget::isBusy() const {
    return d_->thread != nullptr;
}
QString RemeshWidget::statusText() const {
    return d_->status->text();
}

void RemeshWidget::setActiveTool(Tool* tool) {
    if (!tool || tool == d_->active) return;
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
        auto job = d_->job;
        d_->thread = QThread::create([job, work] {
            const Progress progress([job](double f, std::string_view stage) {
                job->fraction = f;
                {
                    const std::lock_guard lock(job->mutex);
                    job->stage = std::string(stage);
                }
                return f >= 1.0 || !job->cancel.load();
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
        connect(thread, &QThread::finished, this, [this, job, thread] {
            thread->deleteLater();
            d_->thread = nullptr;
            setBusy(false);
            if (!job->error.empty()) {
                d_->fishbonePending = false;
                d_->fishbone->setProblem(QString::fromStdString(job->error));
                reportError(QString::fromStdString(job->error));
            } else if (job->cancelled) {
                d_->fishbonePending = false;
                d_->fishbone->clear();
                d_->status->setText(tr("The curvature estimate was cancelled."));
            } else if (d_->fishbonePending) {
                runFishbone();
            }
        });
        thread->start();
        return;
    }
    try {
        ScanStep step = d_->scanTool->step(d_->nextScanId);
        const QSize size(step.params.camera.width, step.params.camera.height);
        step.fishbone = tool->params(size, d_->scanPanel->fishboneSpacing());
        if (!step.fishbone) return;
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
    if (!d_->session || !d_->session->preview()) {
        reportError(tr("There is no scan to accept: take a scan first."));
        return;
    }
    Session* s = d_->session.get();
    const bool fishbone = s->preview()->step.fishbone.has_value();
    const QString text = fishbone ? tr("Fishbone scan %1").arg(s->preview()->step.params.scan.scanId)
                                  : tr("Scan %1").arg(s->preview()->step.params.scan.scanId);
    auto report = std::make_shared<StitchReport>();
    setBusy(true, tr("Stitching the scan into the mesh"));
    auto job = d_->job;
    // Session::accept reports only its start and end: the bar shows the elapsed time instead of a busy
    // animation (which would repaint the whole GL-composed window many times a second on a software GL).
    d_->progress->setFormat(tr("stitching… %v s"));
    d_->progress->setRange(0, 0x7fffffff);
    d_->thread = QThread::create([job, s, report] {
        const Progress progress([job](double f, std::string_view) {
            job->fraction = f;
            // Never cancel on the final report: the stitch is committed by then.
            return f >= 1.0 || !job->cancel.load();
        });
        try {
            *report = s->accept(progress);
        } catch (const CancelledError&) {
            job->cancelled = true;
        } catch (const std::exception& e) {
            job->error = e.what();
        }
    });
    QThread* thread = d_->thread;
    connect(thread, &QThread::finished, this, [this, job, thread, report, text] {
        thread->deleteLater();
        d_->thread = nullptr;
        setBusy(false);
        if (!job->error.empty()) {
            reportError(QString::fromStdString(job->error));
            return;
        }
        if (job->cancelled) {
            d_->status->setText(tr("Stitching was cancelled; the preview is kept."));
            return;
        }
        d_->undoStack->push(new AcceptCommand(this, text));
        if (d_->fishbone->hasInput()) {
            const QSignalBlocker blocker(d_->fishbone); // the accepted grid is done: no rescan
            d_->fishbone->clear();
        }
        d_->lasso->clear();
        afterMeshChange();
        emit scanAccepted(*report);
    });
    thread->start();
}

void RemeshWidget::reject() {
    if (isBusy() || !d_->session) return;
    d_->session->reject();
    if (d_->fishbone->hasInput()) {
        const QSignalBlocker blocker(d_->fishbone);
        d_->fishbone->clear();
    }
    showPreview();
}

void RemeshWidget::cancel() {
    if (d_->job) d_->job->cancel = true;
    d_->status->setText(tr("Cancelling…"));
}

void RemeshWidget::setGhostVisible(bool visible) {
    ghost_ = visible;
    if (d_->ghostAction->isChecked() != visible) {
        const QSignalBlocker blocker(d_->ghostAction);
        d_->ghostAction->setChecked(visible);
    }
    bridge::setGhost(d_->view, visible && d_->session ? &d_->session->reference() : nullptr);
}

void RemeshWidget::undoStep() {
    waitForWork();
    try {
        d_->session->undo();
    } catch (const std::exception& e) {
        reportError(sentence(e));
        return;
    }
    afterMeshChange();
}

void RemeshWidget::redoStep() {
    waitForWork();
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
    bridge::setPreview(d_->view, preview ? &preview->patch.mesh : nullptr);
    d_->scanTool->setPreviewPending(preview != nullptr);
    d_->acceptAction->setEnabled(preview != nullptr && !isBusy());
    d_->rejectAction->setEnabled(preview != nullptr && !isBusy());
    updateStatus();
    emit previewChanged();
}

void RemeshWidget::reportError(const QString& message) {
    d_->status->setText(message);
    emit errorOccurred(message);
}

void RemeshWidget::setBusy(bool busy, const QString& what) {
    if (busy) {
        d_->job = std::make_shared<Job>();
        d_->busyWhat = what;
        d_->busyClock.start();
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
    else if (!d_->session)
        text = tr("Open a mesh to start.");
    else if (d_->active)
        text = d_->active->statusText();
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
