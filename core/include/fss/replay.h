#pragma once
/// \file replay.h
/// The step-by-step replay of a session file (DESIGN.md §7): one engine for replaySession (session_file.h,
/// `fss-remesh run`) and for the widgets' session loading. It reads the file's input mesh, creates the
/// Session and applies one event of the log per step() — scan + accept, undo or redo — exposing the
/// progress, the session being rebuilt and the cost of every event replayed so far.
///
/// Typical use:
/// \code
///   fss::SessionReplay replay(fss::loadSessionFile("part.session.json"));
///   while (!replay.done()) replay.step();
///   const fss::Mesh& result = replay.current();
/// \endcode
/// A caller that runs parts of an event on different threads (the widgets scan on the GUI thread, which
/// owns the GPU renderer's GL context, and stitch on a worker) uses the parts of step() instead:
/// buildFishboneCache() when needsFishboneCache(), then scanNext(), then finishNext(). Either way the
/// replayed mesh is the same.

#include "fss/progress.h"
#include "fss/session.h"
#include "fss/session_file.h"

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace fss {

/// Replays a SessionFile one event at a time; see the file comment. Not thread-safe: call it from one
/// thread at a time.
class SessionReplay {
public:
    /// Checks the SHA-256 of the input mesh when \p file records one, reads the mesh (readMesh, default
    /// options) and creates the Session to replay into (SessionOptions: \p renderer, the file's curvature
    /// options, an undo depth that holds every accepted step). An empty factory means CpuMeshRenderer.
    /// \throw IoError when the mesh cannot be read or its SHA-256 differs; InvalidInputError as Session's
    ///        constructor.
    explicit SessionReplay(SessionFile file, const RendererFactory& renderer = {});
    ~SessionReplay();
    SessionReplay(SessionReplay&&) noexcept;
    SessionReplay& operator=(SessionReplay&&) noexcept;
    SessionReplay(const SessionReplay&) = delete;
    SessionReplay& operator=(const SessionReplay&) = delete;

    /// The file being replayed.
    const SessionFile& file() const;
    /// Number of events in the file.
    std::size_t eventCount() const;
    /// Index of the next event to replay (eventCount() when done).
    std::size_t nextEvent() const;
    /// Whether every event has been replayed.
    bool done() const;
    /// Share of the events replayed, in [0, 1] (1 for a file without events).
    double fraction() const;

    /// Replays the next event: scan + accept, undo or redo. Reports through \p progress the fraction of the
    /// whole replay (never decreasing), with stages "events[i] scan: <stage>", "events[i] stitch: <stage>",
    /// "events[i] undo" and "events[i] redo".
    /// \return the cost of the event (also appended to events()).
    /// \throw InvalidInputError with the file and the event named ("session.json, events[3] (accept): <why>")
    ///        when the scan or stitch fails, or when done(); CancelledError through \p progress. On failure
    ///        the event is not counted as replayed.
    const ReplayedEvent& step(const Progress& progress = {});

    /// Whether the next event is a fishbone scan whose reference curvature and ray caster are not built yet
    /// (scanNext would build them itself, in the scan).
    bool needsFishboneCache() const;
    /// Builds the reference's curvature and ray caster for the next fishbone scan.
    /// \throw as FishboneCache::curvature; CancelledError through \p progress.
    void buildFishboneCache(const Progress& progress = {});
    /// The first part of an Accept event: Session::scan of its step (nothing for undo and redo). Passes
    /// \p progress to the scan as it is.
    /// \throw the scan's error as it is (InvalidInputError, CancelledError), or InvalidInputError when
    /// done().
    void scanNext(const Progress& progress = {});
    /// The rest of the next event: Session::accept of the scan (scanNext must have run), undo or redo.
    /// Records the event's cost and moves on to the next event. Passes \p progress to the accept as it is.
    /// \throw the accept's, undo's or redo's error as it is, or InvalidInputError when done(); the event then
    ///        stays the next one.
    const ReplayedEvent& finishNext(const Progress& progress = {});

    /// The session being rebuilt: after the last event, its current() is the replayed mesh.
    Session& session();
    const Session& session() const;
    /// session().current().
    const Mesh& current() const;
    /// The cost of every event replayed so far, in order.
    const std::vector<ReplayedEvent>& events() const;
    /// Seconds spent checking and reading the input mesh.
    double readSeconds() const;
    /// Hands the session over to the caller; the replay must not be used afterwards.
    std::unique_ptr<Session> takeSession();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace fss
