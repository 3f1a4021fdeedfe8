#pragma once
/// \file session_file.h
/// Session files (DESIGN.md §2, §4 "Session files are JSON and replay to the same mesh"): a versioned JSON
/// record of a remeshing session — the input mesh (path and SHA-256), the renderer kind, the curvature
/// options, and the event log (every accepted scan with everything of its ScanStep, every undo and redo).
/// Replaying the log on the same input with the same renderer reproduces the recording session's current
/// mesh exactly (byte-identical when written).
///
/// Format (version 5; every field is required unless marked optional, unknown fields are errors):
/// \code
/// { "format": "fss-session", "version": 5,
///   "description": "...",                                   (optional)
///   "mesh": { "path": "../meshes/part.off", "sha256": "<64 hex digits>" },
///   "renderer": "cpu" | "gpu",
///   "curvature": { "jet_degree": 2, "min_points": 24, "max_rings": 5, "anisotropy_epsilon": 0.001 },
///   "events": [
///     { "kind": "accept", "step": {
///         "camera": { "eye": [x,y,z], "focal": [x,y,z], "up": [x,y,z],
///                     "projection": "perspective" | "parallel",
///                     "view_angle_deg": 30, "parallel_scale": 1, "near": 0.01, "far": 1000,
///                     "width": 256, "height": 256 },
///         "lasso": null | [[x,y], ...],                    (pixels of the scan image)
///         "erode_radius": 1, "dilate_radius": 1,
///         "relax_iterations": 6,                           (optional: written only when not 0, absent = 0)
///         "scan": { "scan_id": 0, "quality_angle_limit_deg": 85, "max_snap_footprints": 2,
///                   "lattice": "adaptive" | "triangular" | "square", "spacing_px": 1, "spacing_world": 0,
///                   "min_lattice_angle_deg": 35, "warp_to_surface": true, "warp_follows_fit": true },
///                                    (lattice to warp_to_surface always written; each optional, absent =
///                                     "square", 1, 0, 0, false: files before issue #20; warp_to_surface
///                                     since version 3; warp_follows_fit since version 5, written only when
///                                     on, absent = false)
///         "quality_mask": { "margin": 0.1, "force_replace": false, "search_rings": 2 },
///         "triangulate": { "max_edge_footprints": 3, "max_sampling_angle_deg": 80,
///                          "min_quad_angle_deg": 20 },  (optional: written only when not 0, absent = 0)
///         "grid": "regular" | "fishbone",
///         "fishbone": {                                    (only with "grid": "fishbone")
///             "seed": null | [x,y], "direction": "min" | "max", "h": 4,
///             "key_ribs": [[x,y], ...], "drawn_key_ribs": [[[x,y], ...], ...],
///             "drawn_backbone": [[x,y], ...],
///             "tracing": { "spacing": 4, "extend_beyond_key_ribs": true,
///                          "backbone": STREAMLINE, "ribs": STREAMLINE,
///                          the issue-20 rules, each optional, written only when not off, absent = off:
///                          "min_rib_gap": 0.5, "max_rib_turn_deg": 60, "max_rib_aspect": 1.7,
///                          "stop_ribs_at_creases": true, "spare_followed_crease": true,
///                          "close_loops": true, "stop_backbone_at_creases": true,
///                          "isotropic_ribs": true, "min_face_angle_deg": 20,
///                          "min_component_faces": 24 },
///             "min_seed_anisotropy": 0.1,
///             "crease": { "angle_deg": 30, "snap_radius": 1.5 },  (optional; missing: these defaults)
///             "raycast": { "rings": 2, "verify_unoccluded": false },
///             "sampling_factor": 0 },    (0 = automatic, or a divisor of width and height of at most h;
///                                         optional: missing = 1, the scan resolution)
///         "stitch": { "seam_rings": 2, "optimise_seam": true, "collapse_edge_ratio": 0.4, "seam_grading": 1,
///                     "min_angle_floor_deg": 1, "max_view_angle_deg": 85, "max_normal_change_deg": 20,
///                     "max_gap_ratio": 0.25, "max_trim_rounds": 16, "min_component_faces": 8,
///                     "collect_garbage": false, "peel_trim": true (optional: written only when true,
///                     absent = false), "outside_min_angle_floor_deg": 10 (optional: written only when
///                     not 0, absent = 0), "refill_seam": true (optional: written only when true,
///                     absent = false; stitch v2's seam refill, DESIGN.md §6.2), "remesh_seam": false
///                     (optional: written only when false, absent = true, in version 1 files too; stitch
///                     v2's band remesh) } } },
///     { "kind": "undo" }, { "kind": "redo" } ] }
/// STREAMLINE = { "step": 0.25, "min_step": 0.015625, "max_length": null (unbounded) | L,
///                "min_anisotropy": 0.05,
///                "low_anisotropy": "stop" | "continue_straight", "max_turn_deg": 10, "max_steps": 1000000 }
/// \endcode
/// Doubles are written in the shortest form that reads back to the same bits, so a loaded step is
/// bit-identical to the saved one. Not stored: StreamlineOptions::insideRegion and ::attractor (functions;
/// saving a step that has one is an error) and the test hook StitchOptions::failValidationForTesting
/// (loaded as false). The ranges of the options are those of their validate() (ScanParams,
/// FishboneParams with the step's camera, StitchOptions, CurvatureOptions), which the scans and the stitch
/// call too: a file that loads does not fail at replay for an option out of range.

#include "fss/curvature.h"
#include "fss/progress.h"
#include "fss/session.h"

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace fss {

/// The session file format version this FSS writes; it reads versions 1 to this. Version 2 (issue 19): the
/// stitch's seam band remesh is on by default ("remesh_seam" absent = on, written only when off); version 1
/// files load and replay with it, so their results differ from the ones they were recorded with. Version 3
/// (issue #20): "scan.warp_to_surface" (ScanOptions::warpToSurface, on by default) is always written;
/// absent = off, so version 1 and 2 files replay as before. An FSS reading versions up to 2 refuses a
/// version 3 file ("version is 3, but this FSS reads versions 1 to 2 only"). Version 4 (issue #20, session
/// 16): fishbone steps carry "tracing.crease_backbone" and "tracing.continuous_key_ribs" (on by default,
/// written only when on, absent = off, so older files replay their fishbone scans as recorded); the warp's
/// solver and the seam band's outlier-cap rule changed, so version 1 to 3 files replay to different bytes
/// than before. Version 5 (issue #20, session 19): "scan.warp_follows_fit" (ScanOptions::warpFollowsFit, on
/// by default) is written when on; absent = off, so version 1 to 4 files warp with the fit they were
/// recorded with and replay to the same bytes.
inline constexpr int kSessionFileVersion = 5;

/// A session file in memory.
struct SessionFile {
    int version = kSessionFileVersion; ///< format version (kSessionFileVersion)
    std::string description;           ///< free text (optional in the file)
    /// The input mesh, usable from the current working directory. loadSessionFile resolves a relative path
    /// of the file against the session file's folder; saveSessionFile writes a relative path relative to the
    /// session file's folder (an absolute path stays absolute).
    std::filesystem::path meshPath;
    std::string meshSha256;           ///< SHA-256 of the mesh file's bytes, 64 lowercase hex digits
    std::string renderer = "cpu";     ///< the renderer the session was recorded with: "cpu" or "gpu"
    CurvatureOptions curvature;       ///< the session's curvature options (fishbone scans)
    std::vector<SessionEvent> events; ///< the event log (Session::events())
    /// The file this was loaded from (for messages); empty when made in memory.
    std::filesystem::path source;
};

/// Makes the SessionFile of \p session, whose reference was read from \p meshPath (readMesh with default
/// options): computes the mesh file's SHA-256 and copies the event log. \p renderer is the kind of renderer
/// the session used ("cpu" or "gpu") and \p curvature its SessionOptions::curvature.
/// \throw IoError when the mesh file cannot be read; InvalidInputError when \p renderer is not "cpu" or
///        "gpu" or a step cannot be stored (a streamline region mask).
SessionFile sessionFileFromSession(const Session& session, const std::filesystem::path& meshPath,
                                   const std::string& renderer = "cpu",
                                   const CurvatureOptions& curvature = {});

/// The JSON text of \p file (see the file comment), ending with a newline. The mesh path is written as
/// given (use saveSessionFile to make it relative to the session file).
/// \throw InvalidInputError naming the field when something cannot be stored: a non-finite number, a
///        renderer other than "cpu"/"gpu", a sha256 that is not 64 hex digits, a streamline region mask.
std::string sessionFileToJson(const SessionFile& file);

/// Writes \p file to \p path (JSON, see the file comment), with a relative mesh path made relative to
/// \p path's folder. Written to a temporary file and renamed, so an existing file is never half-written.
/// \throw InvalidInputError as sessionFileToJson; IoError naming the file when it cannot be written.
void saveSessionFile(const SessionFile& file, const std::filesystem::path& path);

/// Options of loadSessionFile / sessionFileFromJson.
struct SessionFileLoadOptions {
    /// Check that the mesh file exists and that its SHA-256 matches "mesh.sha256".
    bool verifyMesh = true;
};

/// Parses and validates session-file JSON \p text. \p name names the file in messages; relative mesh
/// paths are resolved against \p baseDir. Every field is checked for presence, type and range, unknown
/// fields are refused, and the event log must be consistent (an undo needs an applied step, a redo an
/// undone one). \throw IoError with one sentence naming the file and the offending field, e.g.
/// "session.json: events[3].step.camera.width must be a positive integer.", for invalid JSON (with line
/// and column), a wrong format or version, missing, unknown or mistyped fields, values out of range, an
/// inconsistent event log, a missing mesh file, or a mesh whose SHA-256 differs from the recorded one. An
/// option out of range is named by its JSON path with the range its validate() states:
/// "session.json: events[3].step.stitch.min_angle_floor_deg must be in [0, 30), not 45.".
SessionFile sessionFileFromJson(const std::string& text, const std::string& name,
                                const std::filesystem::path& baseDir,
                                const SessionFileLoadOptions& options = {});

/// Reads and validates the session file \p path (as sessionFileFromJson, named by \p path as given and
/// resolving the mesh path against its folder). \throw IoError as sessionFileFromJson, or when the file
/// cannot be read.
SessionFile loadSessionFile(const std::filesystem::path& path, const SessionFileLoadOptions& options = {});

/// The name of an event kind in session files and reports: "accept", "undo" or "redo".
const char* sessionEventKindName(SessionEvent::Kind kind);

/// What replaying one event took.
struct ReplayedEvent {
    SessionEvent::Kind kind = SessionEvent::Kind::Accept;
    bool fishbone = false;              ///< an accepted fishbone scan
    double scanSeconds = 0;             ///< Session::scan (accepted scans)
    double stitchSeconds = 0;           ///< Session::accept (accepted scans)
    double seconds = 0;                 ///< the whole event
    std::size_t patchFaces = 0;         ///< faces of the scan's patch (accepted scans)
    std::optional<StitchReport> stitch; ///< the stitch report (accepted scans)
};

/// A replayed session with the cost of each event.
struct ReplayResult {
    Session session;                   ///< the session after the last event (current() is the result)
    std::vector<ReplayedEvent> events; ///< one per event of the file
    double readSeconds = 0;            ///< reading the input mesh
    double totalSeconds = 0;           ///< reading and replaying
};

/// Replays \p file: reads the input mesh (readMesh, default options), checks its SHA-256 when the file
/// records one, creates a Session (SessionOptions: \p renderer, the file's curvature options, an undo
/// depth that holds every step) and applies the events in order — scan + accept, undo, redo. With the same
/// kind of renderer as the recording (file.renderer) the current mesh equals the recording session's bit
/// for bit. The caller chooses the renderer: an empty factory means CpuMeshRenderer.
/// Progress: fraction of the events done; stages "events[i] scan: ...", "events[i] stitch", ...
/// \throw IoError when the mesh cannot be read or its SHA-256 differs; InvalidInputError with the file
///        and the event named ("session.json, events[3]: <why>") when a scan or stitch fails on replay;
///        CancelledError through \p progress.
ReplayResult replaySession(const SessionFile& file, const RendererFactory& renderer = {},
                           const Progress& progress = {});

} // namespace fss
