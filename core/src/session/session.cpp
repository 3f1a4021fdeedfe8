// Session: reference, current mesh, preview, history (session.h).
//
// The current mesh is kept garbage-free (its garbage collected after every stitch, as collect_garbage()
// does, which is deterministic), so it is fully described by its element arrays. Each history step stores
// the index-wise difference of those arrays between the states before and after the stitch
// (detail::MeshDelta); undo / redo write one side back. accept() stitches in place and journals the records
// the stitch may change (detail::MeshJournal), so accept, undo and redo are all O(change), not O(mesh).
#include "fss/session.h"

#include "fss/error.h"
#include "session/mesh_delta.h"
#include "stitch/stitch_edits.h"

#include <chrono>
#include <deque>
#include <optional>
#include <span>
#include <utility>

namespace fss {

namespace {
struct HistoryItem {
    ScanStep step;
    StitchReport report;
    detail::MeshDelta delta; // before → after of the current mesh
};

// Heap bytes of the parts of a step that are not the mesh delta.
std::size_t stepBytes(const ScanStep& step, const StitchReport& report) {
    std::size_t bytes = 0;
    if (step.params.lasso)
        bytes += step.params.lasso->points.capacity() * sizeof(step.params.lasso->points[0]);
    if (step.fishbone)
        bytes += (step.fishbone->keyRibs.capacity() + step.fishbone->drawnBackbone.capacity()) *
                 sizeof(Eigen::Vector2d);
    for (const std::string& s : report.skipped)
        bytes += sizeof(std::string) + s.capacity();
    return bytes;
}

std::unique_ptr<MeshRenderer> makeRenderer(const RendererFactory& factory) {
    if (factory) {
        auto renderer = factory();
        if (!renderer) throw InvalidInputError("The session's renderer factory returned no renderer.");
        return renderer;
    }
    return std::make_unique<CpuMeshRenderer>();
}
} // namespace

struct Session::Impl {
    SessionOptions options;
    Mesh reference;
    Mesh current;
    std::unique_ptr<MeshRenderer> referenceRenderer;
    std::unique_ptr<MeshRenderer> currentRenderer;
    bool currentRendererValid = false;
    std::optional<ScanPreview> preview;
    std::deque<HistoryItem> history;
    std::size_t applied = 0;   // history[0, applied) is applied
    std::size_t forgotten = 0; // oldest steps dropped beyond maxUndoSteps
    std::vector<SessionEvent> events;
    FishboneCache fishboneCache;
    // Scan after scan at one size reuses the same memory: a dropped preview's grid and patch go back here.
    ScanWorkspace workspace;

    // Drops the preview, keeping its grid's and patch's storage for the next scan (moves only).
    void dropPreview() {
        if (!preview) return;
        workspace.recycle(std::move(preview->grid));
        workspace.recycle(std::move(preview->patch));
        preview.reset();
    }

    MeshRenderer& rendererOfCurrent() {
        if (!currentRendererValid) {
            currentRenderer->setMesh(current);
            currentRendererValid = true;
        }
        return *currentRenderer;
    }
};

Session::Session(Mesh reference, SessionOptions options) : impl_(std::make_unique<Impl>()) {
    if (reference.number_of_faces() == 0) throw InvalidInputError("The session's input mesh has no faces.");
    if (!CGAL::is_triangle_mesh(reference))
        throw InvalidInputError("The session's input mesh is not a triangle mesh.");
    if (!reference.is_valid(false))
        throw InvalidInputError("The session's input mesh is not a valid halfedge mesh.");
    options.curvature.validate();
    if (options.maxUndoSteps < 50) options.maxUndoSteps = 50;
    impl_->options = std::move(options);
    // The history needs a garbage-free current mesh (collect_garbage renumbers: do it on the reference
    // too so that the two agree index for index).
    if (reference.has_garbage()) reference.collect_garbage();
    impl_->reference = std::move(reference);
    impl_->current = impl_->reference;
    impl_->referenceRenderer = makeRenderer(impl_->options.renderer);
    impl_->currentRenderer = makeRenderer(impl_->options.renderer);
    impl_->referenceRenderer->setMesh(impl_->reference);
}

Session::~Session() = default;
Session::Session(Session&&) noexcept = default;
Session& Session::operator=(Session&&) noexcept = default;

const Mesh& Session::reference() const {
    return impl_->reference;
}
const Mesh& Session::current() const {
    return impl_->current;
}

const ScanPreview& Session::scan(const ScanStep& step, const Progress& progress) {
    Impl& d = *impl_;
    const auto start = std::chrono::steady_clock::now();
    // The stitch options too are checked now, not at accept(): a step that scans can be accepted (and
    // replayed from a session file) without an option out of range.
    step.stitch.validate();
    // Until the first step the current mesh is the reference itself: scan with the one renderer.
    const bool first = d.applied == 0 && d.forgotten == 0;
    const Mesh& current = first ? d.reference : d.current;
    MeshRenderer& currentRenderer = first ? *d.referenceRenderer : d.rendererOfCurrent();
    ScanPreview preview;
    preview.step = step;
    if (step.fishbone) {
        FishboneScanResult result =
            scanFishbonePatch(d.reference, *d.referenceRenderer, current, currentRenderer, step.params,
                              *step.fishbone, d.fishboneCache, progress);
        preview.grid = std::move(result.grid);
        preview.patch = std::move(result.patch);
        preview.fishbone = std::move(result.fishbone);
        preview.currentBuffers = std::move(result.currentBuffers);
    } else {
        ScanResult result = scanPatch(d.reference, *d.referenceRenderer, current, currentRenderer,
                                      step.params, d.workspace, progress);
        preview.grid = std::move(result.grid);
        preview.patch = std::move(result.patch);
        preview.currentBuffers = std::move(result.currentBuffers);
    }
    preview.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    d.dropPreview(); // the new scan succeeded: the old preview's storage serves the next one
    d.preview = std::move(preview);
    return *d.preview;
}

const ScanPreview* Session::preview() const {
    return impl_->preview ? &*impl_->preview : nullptr;
}

void Session::reject() {
    impl_->dropPreview();
}

const StitchReport& Session::accept(const Progress& progress) {
    Impl& d = *impl_;
    if (!d.preview) throw InvalidInputError("There is no scan to accept: take a scan first.");
    progress.report(0.0, "stitch");
    // The stitch edits the current mesh in place while a journal keeps the records of every element it
    // may change; the journal then collects the garbage where it is (as collect_garbage() would) and gives
    // the history's delta, all in time proportional to the change. Until the step is recorded, any failure
    // writes the journal's records back (strong guarantee): the mesh is then as it was, bit for bit.
    Mesh& mesh = d.current;
    detail::MeshJournal journal(mesh);
    const ScanPreview& p = *d.preview;
    StitchOptions options = p.step.stitch;
    options.collectGarbage = false; // the journal does it (same result)
    // The stitch reports its own progress (and is cancellable) between components: mapped into [0, 0.9).
    const Progress stitchProgress([&progress](double fraction, std::string_view stage) {
        progress.report(0.85 * fraction, stage);
        return true;
    });
    // A fishbone scan samples (and rendered the current mesh) with its sampling camera.
    const Camera camera = p.step.fishbone ? fishboneSamplingCamera(p.step.params.camera, *p.step.fishbone)
                                          : p.step.params.camera;
    std::optional<HistoryItem> item;
    std::optional<SessionEvent> event;
    try {
        StitchReport report = detail::stitchPatch(
            mesh, p.patch.mesh, camera, options, p.currentBuffers.faceId, stitchProgress,
            [&journal](const Mesh& m, std::span<const FaceIndex> removed, std::span<const VertexIndex> used) {
                journal.record(m, used, removed);
            });
        progress.report(0.9, "record");
        item.emplace(HistoryItem{p.step, std::move(report), journal.finish(mesh)});
        d.events.reserve(d.events.size() + 1);
        event.emplace(SessionEvent{SessionEvent::Kind::Accept, p.step});
        progress.report(1.0, "stitch");
        d.history.push_back(std::move(*item)); // strong guarantee of deque::push_back
    } catch (...) {
        if (item)
            item->delta.applyBackward(mesh); // the garbage is collected: back to the mesh before
        else if (!journal.empty())
            journal.finish(mesh).applyBackward(mesh);
        throw;
    }
    // No allocation from here on.
    d.history.erase(d.history.begin() + std::ptrdiff_t(d.applied), d.history.end() - 1); // drop redo steps
    d.currentRendererValid = false;
    d.events.push_back(std::move(*event)); // capacity reserved above: no allocation
    while (d.history.size() > d.options.maxUndoSteps) {
        d.history.pop_front();
        ++d.forgotten;
    }
    d.applied = d.history.size();
    d.dropPreview();
    return d.history.back().report;
}

bool Session::canUndo() const {
    return impl_->applied > 0;
}
bool Session::canRedo() const {
    return impl_->applied < impl_->history.size();
}
std::size_t Session::undoCount() const {
    return impl_->applied;
}
std::size_t Session::redoCount() const {
    return impl_->history.size() - impl_->applied;
}

void Session::undo() {
    Impl& d = *impl_;
    if (!canUndo()) throw InvalidInputError("There is nothing to undo.");
    d.events.reserve(d.events.size() + 1);
    d.history[d.applied - 1].delta.applyBackward(d.current);
    d.dropPreview();
    --d.applied;
    d.currentRendererValid = false;
    d.events.push_back({SessionEvent::Kind::Undo, {}});
}

void Session::redo() {
    Impl& d = *impl_;
    if (!canRedo()) throw InvalidInputError("There is nothing to redo.");
    d.events.reserve(d.events.size() + 1);
    d.history[d.applied].delta.applyForward(d.current);
    d.dropPreview();
    ++d.applied;
    d.currentRendererValid = false;
    d.events.push_back({SessionEvent::Kind::Redo, {}});
}

std::vector<ScanStep> Session::steps() const {
    std::vector<ScanStep> out;
    for (const HistoryItem& item : impl_->history)
        out.push_back(item.step);
    return out;
}

const StitchReport& Session::report(std::size_t i) const {
    if (i >= impl_->history.size())
        throw InvalidInputError("There is no history step " + std::to_string(i) + ".");
    return impl_->history[i].report;
}

std::size_t Session::historyBytes() const {
    std::size_t bytes = 0;
    for (const HistoryItem& item : impl_->history)
        bytes += sizeof(HistoryItem) - sizeof(detail::MeshDelta) + item.delta.bytes() +
                 stepBytes(item.step, item.report);
    return bytes;
}

const std::vector<SessionEvent>& Session::events() const {
    return impl_->events;
}

FishboneCache& Session::fishboneCache() {
    return impl_->fishboneCache;
}

} // namespace fss
