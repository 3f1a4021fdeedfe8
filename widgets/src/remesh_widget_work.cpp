// RemeshWidget: scans, fishbone grids, accepts and the trial stitch, on worker threads (remesh_widget_impl.h
// holds what its files share).
#include "remesh_widget_impl.h"

namespace fss::widgets {

namespace {

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
        reportError(detail::sentence(e));
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
            const std::shared_ptr<detail::Job> job = d_->job;
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
        tool->setProblem(detail::sentence(e));
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
            if (!reuse) figures->first = detail::figuresOf(FiguresMeasurer::measureAlone(s->current(), stop));
            *report = s->accept(progress);
            if (!reuse) figures->second = detail::figuresOf(FiguresMeasurer::measureAlone(s->current()));
        },
        [this, report, name, figures] {
            const std::shared_ptr<detail::Job> job = d_->job;
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
    auto t = std::make_shared<detail::Trial>();
    t->session = d_->session.get();
    t->scanId = p.step.params.scan.scanId;
    t->measurer = d_->figures;
    // The inputs of Session::accept, copied (the current mesh shared: the thread copies it): the thread never
    // touches the session.
    t->current = d_->mesh;
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
    const detail::Trial& t = *d_->trial;
    const ScanPreview* preview = d_->session->preview();
    if (preview && !t.cancelled) d_->view->setPreviewMesh(preview->patch.mesh, t.stitched);
    updateStatus();
    emit trialFinished();
}

// What the status line adds about the trial of the pending preview.
QString RemeshWidget::trialText() const {
    if (!d_->trial) return {};
    const detail::Trial& t = *d_->trial;
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

void RemeshWidget::waitForWork() {
    if (!d_->thread) return;
    d_->thread->wait();
    // Deliver the finished() handler now, so the job's result is applied before the caller continues.
    QCoreApplication::sendPostedEvents(this);
    QCoreApplication::processEvents(QEventLoop::ExcludeUserInputEvents);
}

} // namespace fss::widgets
