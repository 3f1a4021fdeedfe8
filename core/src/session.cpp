// Session: reference, current mesh, preview, history (session.h).
//
// FIRST VERSION: the history keeps whole copies of the mesh before and after each step. It is exact and
// correct but its memory grows with the mesh; it is to be replaced by per-step change records.
#include "fss/session.h"

#include "fss/error.h"

#include <chrono>
#include <deque>
#include <utility>

namespace fss {

namespace {
struct HistoryItem {
    ScanStep step;
    StitchReport report;
    Mesh before;
    Mesh after;
};

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
    std::size_t applied = 0; // history[0, applied) is applied
    std::vector<SessionEvent> events;
    FishboneCache fishboneCache;

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
    if (!reference.is_valid(false)) throw InvalidInputError("The session's input mesh is not a valid halfedge mesh.");
    if (options.maxUndoSteps < 50) options.maxUndoSteps = 50;
    impl_->options = std::move(options);
    impl_->reference = std::move(reference);
    impl_->current = impl_->reference;
    impl_->referenceRenderer = makeRenderer(impl_->options.renderer);
    impl_->currentRenderer = makeRenderer(impl_->options.renderer);
    impl_->referenceRenderer->setMesh(impl_->reference);
}

Session::~Session() = default;
Session::Session(Session&&) noexcept = default;
Session& Session::operator=(Session&&) noexcept = default;

const Mesh& Session::reference() const { return impl_->reference; }
const Mesh& Session::current() const { return impl_->current; }

const ScanPreview& Session::scan(const ScanStep& step, const Progress& progress) {
    Impl& d = *impl_;
    const auto start = std::chrono::steady_clock::now();
    const bool first = d.applied == 0;
    const Mesh& current = first ? d.reference : d.current;
    MeshRenderer& currentRenderer = first ? *d.referenceRenderer : d.rendererOfCurrent();
    ScanPreview preview;
    preview.step = step;
    if (step.fishbone) {
        FishboneScanResult result = scanFishbonePatch(d.reference, *d.referenceRenderer, current, currentRenderer,
                                                      step.params, *step.fishbone, d.fishboneCache, progress);
        preview.grid = std::move(result.grid);
        preview.patch = std::move(result.patch);
        preview.fishbone = std::move(result.fishbone);
        preview.currentBuffers = std::move(result.currentBuffers);
    } else {
        ScanResult result =
            scanPatch(d.reference, *d.referenceRenderer, current, currentRenderer, step.params, progress);
        preview.grid = std::move(result.grid);
        preview.patch = std::move(result.patch);
        preview.currentBuffers = std::move(result.currentBuffers);
    }
    preview.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    d.preview = std::move(preview);
    return *d.preview;
}

const ScanPreview* Session::preview() const { return impl_->preview ? &*impl_->preview : nullptr; }

void Session::reject() { impl_->preview.reset(); }

const StitchReport& Session::accept(const Progress& progress) {
    Impl& d = *impl_;
    if (!d.preview) throw InvalidInputError("There is no scan to accept: take a scan first.");
    progress.report(0.0, "stitch");
    Mesh next = d.current;
    const ScanPreview& p = *d.preview;
    StitchReport report = stitchPatch(next, p.patch.mesh, p.step.params.camera, p.step.stitch,
                                      p.currentBuffers.faceId);
    HistoryItem item{p.step, std::move(report), d.current, std::move(next)};
    d.history.erase(d.history.begin() + std::ptrdiff_t(d.applied), d.history.end());
    d.history.push_back(std::move(item));
    d.current = d.history.back().after;
    d.currentRendererValid = false;
    d.events.push_back({SessionEvent::Kind::Accept, p.step});
    while (d.history.size() > d.options.maxUndoSteps) d.history.pop_front();
    d.applied = d.history.size();
    d.preview.reset();
    progress.report(1.0, "stitch");
    return d.history.back().report;
}

bool Session::canUndo() const { return impl_->applied > 0; }
bool Session::canRedo() const { return impl_->applied < impl_->history.size(); }
std::size_t Session::undoCount() const { return impl_->applied; }
std::size_t Session::redoCount() const { return impl_->history.size() - impl_->applied; }

void Session::undo() {
    Impl& d = *impl_;
    if (!canUndo()) throw InvalidInputError("There is nothing to undo.");
    d.preview.reset();
    d.current = d.history[d.applied - 1].before;
    --d.applied;
    d.currentRendererValid = false;
    d.events.push_back({SessionEvent::Kind::Undo, {}});
}

void Session::redo() {
    Impl& d = *impl_;
    if (!canRedo()) throw InvalidInputError("There is nothing to redo.");
    d.preview.reset();
    d.current = d.history[d.applied].after;
    ++d.applied;
    d.currentRendererValid = false;
    d.events.push_back({SessionEvent::Kind::Redo, {}});
}

std::vector<ScanStep> Session::steps() const {
    std::vector<ScanStep> out;
    for (const HistoryItem& item : impl_->history) out.push_back(item.step);
    return out;
}

const StitchReport& Session::report(std::size_t i) const {
    if (i >= impl_->history.size()) throw InvalidInputError("There is no history step " + std::to_string(i) + ".");
    return impl_->history[i].report;
}

std::size_t Session::historyBytes() const {
    std::size_t bytes = 0;
    for (const HistoryItem& item : impl_->history)
        bytes += (item.before.number_of_vertices() + item.after.number_of_vertices()) * 40 +
                 (item.before.number_of_faces() + item.after.number_of_faces()) * 80;
    return bytes;
}

const std::vector<SessionEvent>& Session::events() const { return impl_->events; }

FishboneCache& Session::fishboneCache() { return impl_->fishboneCache; }

} // namespace fss
