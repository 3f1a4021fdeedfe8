// RemeshWidget: the layout, the tools, undo / redo and the status line (remesh_widget_impl.h holds what
// its files share).
#include "remesh_widget_impl.h"
#include "view_bridge.h"

namespace fss::widgets {

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

const Mesh& RemeshWidget::mesh() const {
    return *d_->mesh;
}
const Mesh& RemeshWidget::referenceMesh() const {
    return d_->session ? d_->session->reference() : d_->empty;
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
        reportError(detail::sentence(e));
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
        reportError(detail::sentence(e));
        return;
    }
    afterMeshChange();
}

void RemeshWidget::afterMeshChange() {
    d_->mesh = std::make_shared<const Mesh>(d_->session->current());
    d_->updatingView = true;
    bridge::showMeshKeepCamera(d_->view, *d_->mesh);
    d_->updatingView = false;
    d_->qualityPanel->setMesh(*d_->mesh);
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
        d_->job = std::make_shared<detail::Job>();
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

} // namespace fss::widgets

#include "fss/widgets/moc_remesh_widget.cpp" // meta-object code compiled here: widgets/CMakeLists.txt says why
