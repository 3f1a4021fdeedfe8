#pragma once
/// \file session.h
/// A remeshing session (DESIGN.md §2, §3): the *reference* mesh (the input, read-only, with the structures
/// every scan needs built once), the *current* mesh (the reference with the accepted scans stitched in),
/// a pending preview, and the undo/redo history.
///
/// Typical use:
/// \code
///   fss::Session session(fss::readMesh("part.off"));
///   fss::ScanStep step;
///   step.params.camera = fss::Camera::standardView(fss::StandardView::Iso,
///   fss::boundingBox(session.reference()), 256, 256); session.scan(step);          // preview:
///   session.preview()->patch session.accept();            // stitches the preview into session.current()
///   session.undo();              // back to the reference, exactly
/// \endcode
///
/// **Exact undo / redo.** undo() and redo() restore the current mesh *index for index*: the same number of
/// vertices, halfedges and faces; every vertex with a bit-identical point (the same 64-bit patterns, so even
/// -0.0 vs 0.0 is told apart) and the same halfedge; every halfedge with the same next, prev, target vertex
/// and face; every face with the same halfedge, hence the same vertex indices in the same order; the same
/// face properties props::faceQuality and props::faceScanId (bit-identical values, and present or absent
/// as before). Other properties an input file may have brought are resized with the mesh but their values
/// are not recorded. To make this possible the current mesh never holds garbage: the session collects it
/// after every stitch, exactly as collect_garbage() does (deterministic; done locally, see below), and it
/// runs collect_garbage() on the reference at construction (a reference with garbage is renumbered).
///
/// **History memory.** A step stores the index-wise difference of the element arrays between the mesh
/// before and after it: for every vertex, halfedge and face whose record changed (or that exists in one
/// state only) its record(s) — 32 bytes per vertex record, 16 per halfedge record, 12 per face record,
/// both the old and the new record plus a 4-byte index for an element present in both states, one record
/// for an element present in one state only — plus a few hundred bytes for the ScanStep and StitchReport.
/// A stitch adding F faces and removing R therefore costs roughly 90 × (F + R) bytes whatever the mesh size
/// (measured: an 18k-face patch costs 1.6 MB in a 10k- and 1.7 MB in a 300k-face sphere, whose element
/// arrays take 2.1 and 22 MB). accept() stitches into the current mesh in place while a journal keeps the
/// records of every element the stitch may change, then collects the garbage where it lies and compares only
/// those records: no copy of the mesh, no pass over it, so accept() costs the stitch plus time proportional
/// to the change; undo() and redo() write the records back in time proportional to the change too.
///
/// A Session is not thread-safe: call it from one thread at a time (the widgets run scan() and accept()
/// on a worker thread while the GUI only reads what it copied).
#include "fss/fishbone_scan.h"
#include "fss/mesh.h"
#include "fss/progress.h"
#include "fss/scan_pipeline.h"
#include "fss/stitch.h"
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace fss {

/// Makes the renderers a Session uses for its reference and current meshes. Core offers
/// CpuMeshRenderer (the default); FSS::render's GpuMeshRenderer is injected by the layers above.
using RendererFactory = std::function<std::unique_ptr<MeshRenderer>()>;

/// Everything one scan needs to be repeated exactly: the scan parameters (camera with the resolution,
/// lasso, erosion / dilation, quality-mask and triangulation options), the grid kind and the stitch
/// options used when it is accepted. Session files (session_file.h) record one ScanStep per scan.
struct ScanStep {
    ScanParams params;                      ///< camera (width × height = resolution), lasso, masks
    std::optional<FishboneParams> fishbone; ///< empty: regular pixel grid; set: a fishbone grid
    StitchOptions stitch;                   ///< options of the stitch on accept()
};

/// The patch a scan proposes before it is accepted (Session::scan).
struct ScanPreview {
    ScanStep step;                        ///< the step that made it
    SampleGrid grid;                      ///< samples with their masks
    Patch patch;                          ///< the triangulated patch
    std::optional<FishboneGrid> fishbone; ///< the screen grid of a fishbone scan
    FrameBuffers currentBuffers;          ///< the current mesh from the scan camera (for the stitch)
    double seconds = 0;                   ///< wall time of the scan
};

/// One thing that happened in a session, in order. Session files store this log, and replaying it
/// reproduces the session's current mesh exactly.
struct SessionEvent {
    enum class Kind { Accept, Undo, Redo };
    Kind kind = Kind::Accept;
    ScanStep step; ///< the accepted scan (Kind::Accept only)
};

/// Options of a Session.
struct SessionOptions {
    /// Undo depth: the oldest steps are forgotten beyond it. At least 50.
    std::size_t maxUndoSteps = 100;
    /// Renderers of the reference and current mesh; empty = CpuMeshRenderer.
    RendererFactory renderer;
    /// Curvature estimation of the reference (fishbone scans), done on the first fishbone scan.
    CurvatureOptions curvature;
};

/// A remeshing session; see the file comment.
class Session {
public:
    /// Takes \p reference as the input mesh; the current mesh starts as a copy of it.
    /// \throw InvalidInputError when the mesh is empty, not a triangle mesh, or invalid; InvalidOptionError
    ///        when options.curvature is out of range (CurvatureOptions::validate).
    explicit Session(Mesh reference, SessionOptions options = {});
    ~Session();
    Session(Session&&) noexcept;
    Session& operator=(Session&&) noexcept;
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;

    /// The input mesh (never changes).
    const Mesh& reference() const;
    /// The mesh being remeshed: the reference with every accepted (and not undone) scan stitched in.
    const Mesh& current() const;

    /// Scans the reference from `step.params.camera` against the current mesh (quality mask) and keeps the
    /// result as the pending preview, replacing any earlier one. The current mesh does not change.
    /// \throw InvalidInputError (one sentence, as scanPatch / scanFishbonePatch, or StitchOptions::validate
    ///        for `step.stitch`, checked here rather than at accept()); CancelledError. The
    ///        previous preview is kept on failure.
    const ScanPreview& scan(const ScanStep& step, const Progress& progress = {});
    /// The pending preview, or nullptr.
    const ScanPreview* preview() const;
    /// Drops the pending preview.
    void reject();
    /// Stitches the pending preview into the current mesh (StitchOptions::collectGarbage is forced on, see
    /// the file comment), records the step in the history (clearing the redo steps, forgetting the oldest
    /// step beyond maxUndoSteps) and drops the preview. Reports progress through \p progress (stages
    /// "stitch", "record").
    /// \throw InvalidInputError when there is no preview or nothing could be stitched (the preview stays);
    ///        CancelledError. Strong guarantee: on failure the current mesh, the preview, the history and
    ///        the event log are unchanged (what the stitch changed in place is written back from its
    ///        journal, bit for bit).
    const StitchReport& accept(const Progress& progress = {});

    bool canUndo() const;
    bool canRedo() const;
    /// Steps that can be undone / redone now.
    std::size_t undoCount() const;
    std::size_t redoCount() const;
    /// Restores the current mesh to exactly (see the file comment) what it was before the last accepted
    /// step, in time proportional to that step's change; drops any preview.
    /// \throw InvalidInputError when there is nothing to undo (nothing changes). Out of memory (the only
    ///        other failure) is thrown before the mesh is touched.
    void undo();
    /// Re-applies the last undone step, restoring exactly the mesh it produced, in time proportional to
    /// that step's change; drops any preview.
    /// \throw InvalidInputError when there is nothing to redo (nothing changes). Out of memory (the only
    ///        other failure) is thrown before the mesh is touched.
    void redo();
    /// The steps currently in the history (oldest first): the first undoCount() are applied, the rest
    /// can be redone. Steps forgotten beyond maxUndoSteps are not listed (events() still has them).
    std::vector<ScanStep> steps() const;
    /// The stitch report of history step \p i (as steps()).
    /// \throw InvalidInputError when \p i >= steps().size().
    const StitchReport& report(std::size_t i) const;
    /// Bytes the history holds for undo and redo: the change records of every step (see the file comment)
    /// plus the steps' parameters and reports. Grows with the size of the changes, not of the mesh.
    std::size_t historyBytes() const;
    /// Everything that happened since construction, in order (for session files).
    const std::vector<SessionEvent>& events() const;

    /// Curvature and ray-casting structures of the reference, built on first use.
    FishboneCache& fishboneCache();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace fss
