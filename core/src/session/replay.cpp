// The step-by-step replay of session files (replay.h).
#include "fss/replay.h"

#include "fss/error.h"
#include "fss/mesh_io.h"
#include "fss/sha256.h"

#include <algorithm>
#include <chrono>
#include <string_view>
#include <utility>

namespace fss {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point since) {
    return std::chrono::duration<double>(Clock::now() - since).count();
}

} // namespace

struct SessionReplay::Impl {
    SessionFile file;
    std::string name; // the file in messages
    double readSeconds = 0;
    std::unique_ptr<Session> session;
    std::size_t next = 0;
    std::vector<ReplayedEvent> events;
    // The event being replayed by the parts of step(): what its scan took.
    ReplayedEvent pending;
    bool scanned = false;
    double lastFraction = 0; // step()'s progress never goes back

    const SessionEvent& nextEvent() const {
        if (next >= file.events.size())
            throw InvalidInputError(name + ": every event has been replayed already.");
        return file.events[next];
    }
};

SessionReplay::SessionReplay(SessionFile file, const RendererFactory& renderer)
    : impl_(std::make_unique<Impl>()) {
    Impl& d = *impl_;
    const auto start = Clock::now();
    d.file = std::move(file);
    d.name = d.file.source.empty() ? std::string("the session") : d.file.source.string();
    if (!d.file.meshSha256.empty() && sha256OfFile(d.file.meshPath) != d.file.meshSha256)
        throw IoError(d.name + ": the mesh " + d.file.meshPath.string() +
                      " does not match mesh.sha256 (the file changed since the session was recorded).");
    Mesh reference = readMesh(d.file.meshPath);
    d.readSeconds = secondsSince(start);

    SessionOptions options;
    options.renderer = renderer;
    options.curvature = d.file.curvature;
    std::size_t accepts = 0;
    for (const SessionEvent& e : d.file.events)
        accepts += e.kind == SessionEvent::Kind::Accept;
    options.maxUndoSteps = std::max<std::size_t>(options.maxUndoSteps, accepts);
    d.session = std::make_unique<Session>(std::move(reference), std::move(options));
}

SessionReplay::~SessionReplay() = default;
SessionReplay::SessionReplay(SessionReplay&&) noexcept = default;
SessionReplay& SessionReplay::operator=(SessionReplay&&) noexcept = default;

const SessionFile& SessionReplay::file() const {
    return impl_->file;
}
std::size_t SessionReplay::eventCount() const {
    return impl_->file.events.size();
}
std::size_t SessionReplay::nextEvent() const {
    return impl_->next;
}
bool SessionReplay::done() const {
    return impl_->next >= impl_->file.events.size();
}
double SessionReplay::fraction() const {
    return eventCount() == 0 ? 1.0 : double(nextEvent()) / double(eventCount());
}

Session& SessionReplay::session() {
    return *impl_->session;
}
const Session& SessionReplay::session() const {
    return *impl_->session;
}
const Mesh& SessionReplay::current() const {
    return impl_->session->current();
}
const std::vector<ReplayedEvent>& SessionReplay::events() const {
    return impl_->events;
}
double SessionReplay::readSeconds() const {
    return impl_->readSeconds;
}
std::unique_ptr<Session> SessionReplay::takeSession() {
    return std::move(impl_->session);
}

bool SessionReplay::needsFishboneCache() const {
    const Impl& d = *impl_;
    if (d.next >= d.file.events.size()) return false;
    const SessionEvent& e = d.file.events[d.next];
    if (e.kind != SessionEvent::Kind::Accept || !e.step.fishbone) return false;
    Session& s = *d.session;
    return !s.fishboneCache().hasCurvature(s.reference()) || !s.fishboneCache().hasRayCaster(s.reference());
}

void SessionReplay::buildFishboneCache(const Progress& progress) {
    Session& s = *impl_->session;
    s.fishboneCache().curvature(s.reference(), {}, progress);
    s.fishboneCache().rayCaster(s.reference());
}

void SessionReplay::scanNext(const Progress& progress) {
    Impl& d = *impl_;
    const SessionEvent& e = d.nextEvent();
    d.pending = ReplayedEvent{};
    d.pending.kind = e.kind;
    d.scanned = false;
    if (e.kind != SessionEvent::Kind::Accept) return;
    d.pending.fishbone = e.step.fishbone.has_value();
    const auto start = Clock::now();
    const ScanPreview& preview = d.session->scan(e.step, progress);
    d.pending.scanSeconds = secondsSince(start);
    d.pending.patchFaces = preview.patch.mesh.number_of_faces();
    d.scanned = true;
}

const ReplayedEvent& SessionReplay::finishNext(const Progress& progress) {
    Impl& d = *impl_;
    const SessionEvent& e = d.nextEvent();
    ReplayedEvent done = d.pending.kind == e.kind ? d.pending : ReplayedEvent{};
    done.kind = e.kind;
    const auto start = Clock::now();
    switch (e.kind) {
    case SessionEvent::Kind::Accept:
        if (!d.scanned)
            throw InvalidInputError(d.name + ": events[" + std::to_string(d.next) +
                                    "] must be scanned before it is accepted.");
        done.stitch = d.session->accept(progress);
        done.stitchSeconds = secondsSince(start);
        break;
    case SessionEvent::Kind::Undo:
        d.session->undo();
        break;
    case SessionEvent::Kind::Redo:
        d.session->redo();
        break;
    }
    done.seconds = done.scanSeconds + secondsSince(start);
    d.scanned = false;
    d.pending = ReplayedEvent{};
    d.events.push_back(std::move(done));
    ++d.next;
    return d.events.back();
}

const ReplayedEvent& SessionReplay::step(const Progress& progress) {
    Impl& d = *impl_;
    const SessionEvent& e = d.nextEvent();
    const std::size_t i = d.next, n = d.file.events.size();
    const std::string label = "events[" + std::to_string(i) + "]";
    // Inner stages report their own fractions (some restart at 0 per sub-stage): keep the total monotone.
    auto report = [&progress, &d](double fraction, const std::string& stage) {
        d.lastFraction = std::max(d.lastFraction, std::min(fraction, 1.0));
        progress.report(d.lastFraction, stage);
    };
    auto inner = [&](double from, double to, const std::string& what) {
        return Progress([&report, i, n, from, to, what](double f, std::string_view stage) {
            report((double(i) + from + (to - from) * std::clamp(f, 0.0, 1.0)) / double(n),
                   what + (stage.empty() ? std::string() : ": " + std::string(stage)));
            return true;
        });
    };
    const auto start = Clock::now();
    try {
        switch (e.kind) {
        case SessionEvent::Kind::Accept:
            scanNext(inner(0.0, 0.8, label + " scan"));
            finishNext(inner(0.8, 1.0, label + " stitch"));
            break;
        case SessionEvent::Kind::Undo:
            report(double(i) / double(n), label + " undo");
            finishNext();
            break;
        case SessionEvent::Kind::Redo:
            report(double(i) / double(n), label + " redo");
            finishNext();
            break;
        }
    } catch (const CancelledError&) {
        throw;
    } catch (const InvalidInputError& err) {
        throw InvalidInputError(d.name + ", " + label + " (" + sessionEventKindName(e.kind) +
                                "): " + err.what());
    }
    ReplayedEvent& done = d.events.back();
    done.seconds = secondsSince(start);
    return done;
}

} // namespace fss
