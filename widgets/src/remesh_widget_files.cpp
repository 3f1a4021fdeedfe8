// RemeshWidget: meshes, session files and their replay (remesh_widget_impl.h holds what its files share).
#include "remesh_widget_impl.h"

namespace fss::widgets {

namespace {

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

// Mean length of the edges of \p mesh (0 without edges).
double meanEdgeLength(const Mesh& mesh) {
    double sum = 0;
    for (EdgeIndex e : mesh.edges())
        sum +=
            std::sqrt((mesh.point(mesh.source(mesh.halfedge(e))) - mesh.point(mesh.target(mesh.halfedge(e))))
                          .squared_length());
    return mesh.number_of_edges() > 0 ? sum / double(mesh.number_of_edges()) : 0;
}

} // namespace

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
        reportError(detail::sentence(e));
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
    d_->mesh = std::make_shared<const Mesh>(d_->session->current());
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
    d_->view->setMesh(*d_->mesh);
    d_->updatingView = false;
    setGhostVisible(ghost_);
    d_->qualityPanel->setMesh(*d_->mesh);
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
        reportError(detail::sentence(e));
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
        reportError(detail::sentence(e));
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
        reportError(detail::sentence(e));
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
            return failReplay(where(i, detail::sentence(ex)));
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

bool RemeshWidget::saveMesh(const QString& path) {
    try {
        if (!d_->session) throw InvalidInputError("There is no mesh to save: open a mesh first.");
        // Any format of fss/render/fem_io.h, with the reference's face groups carried to the new faces.
        Mesh out = mesh();
        if (hasFaceGroups(d_->session->reference())) transferFaceGroups(d_->session->reference(), out);
        render::writeMeshFile(out, path.toStdString());
    } catch (const std::exception& e) {
        reportError(detail::sentence(e));
        return false;
    }
    return true;
}

} // namespace fss::widgets
