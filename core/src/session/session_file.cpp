// Session files: JSON writer, validating reader and replay (session_file.h; the replay itself is
// SessionReplay, replay.h).
#include "fss/session_file.h"

#include "fss/error.h"
#include "fss/mesh_io.h"
#include "fss/replay.h"
#include "fss/sha256.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <sstream>
#include <system_error>
#include <unistd.h>

namespace fss {
namespace {

using Json = nlohmann::ordered_json;

constexpr const char* kFormatName = "fss-session";

double seconds(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

bool isSha256Hex(const std::string& s) {
    if (s.size() != 64) return false;
    for (char c : s)
        if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
    return true;
}

// ---------------------------------------------------------------------------------------------- writing

// Every double goes through here: JSON has no NaN or infinity, and a silent null would not round-trip.
struct Writer {
    Json number(double v, const std::string& field) const {
        if (!std::isfinite(v))
            throw InvalidInputError("The session cannot be saved: " + field + " is not a finite number.");
        return Json(v);
    }
    Json vec3(const Eigen::Vector3d& v, const std::string& field) const {
        return Json::array({number(v.x(), field), number(v.y(), field), number(v.z(), field)});
    }
    Json vec2(const Eigen::Vector2d& v, const std::string& field) const {
        return Json::array({number(v.x(), field), number(v.y(), field)});
    }
    Json points(const std::vector<Eigen::Vector2d>& pts, const std::string& field) const {
        Json a = Json::array();
        for (std::size_t i = 0; i < pts.size(); ++i)
            a.push_back(vec2(pts[i], field + "[" + std::to_string(i) + "]"));
        return a;
    }

    Json camera(const Camera& c, const std::string& f) const {
        Json j;
        j["eye"] = vec3(c.eye, f + ".eye");
        j["focal"] = vec3(c.focal, f + ".focal");
        j["up"] = vec3(c.up, f + ".up");
        j["projection"] = c.parallel ? "parallel" : "perspective";
        j["view_angle_deg"] = number(c.viewAngleDeg, f + ".view_angle_deg");
        j["parallel_scale"] = number(c.parallelScale, f + ".parallel_scale");
        j["near"] = number(c.nearPlane, f + ".near");
        j["far"] = number(c.farPlane, f + ".far");
        j["width"] = c.width;
        j["height"] = c.height;
        return j;
    }

    Json streamline(const StreamlineOptions& s, const std::string& f) const {
        if (s.insideRegion)
            throw InvalidInputError("The session cannot be saved: " + f +
                                    " has a region mask (a function), which a session file cannot hold.");
        if (s.attractor)
            throw InvalidInputError("The session cannot be saved: " + f +
                                    " has an attractor (a function), which a session file cannot hold.");
        Json j;
        j["step"] = number(s.step, f + ".step");
        j["min_step"] = number(s.minStep, f + ".min_step");
        if (s.maxLength == std::numeric_limits<double>::infinity())
            j["max_length"] = nullptr;
        else
            j["max_length"] = number(s.maxLength, f + ".max_length");
        j["min_anisotropy"] = number(s.minAnisotropy, f + ".min_anisotropy");
        j["low_anisotropy"] = s.lowAnisotropy == LowAnisotropyPolicy::Stop ? "stop" : "continue_straight";
        j["max_turn_deg"] = number(s.maxTurnDeg, f + ".max_turn_deg");
        j["max_steps"] = s.maxSteps;
        return j;
    }

    Json fishbone(const FishboneParams& p, const std::string& f) const {
        Json j;
        j["seed"] = p.seed ? vec2(*p.seed, f + ".seed") : Json(nullptr);
        j["direction"] = p.direction == PrincipalDirection::Min ? "min" : "max";
        j["h"] = number(p.spacing, f + ".h");
        j["key_ribs"] = points(p.keyRibs, f + ".key_ribs");
        Json drawn = Json::array();
        for (std::size_t i = 0; i < p.drawnKeyRibs.size(); ++i)
            drawn.push_back(points(p.drawnKeyRibs[i], f + ".drawn_key_ribs[" + std::to_string(i) + "]"));
        j["drawn_key_ribs"] = std::move(drawn);
        j["drawn_backbone"] = points(p.drawnBackbone, f + ".drawn_backbone");
        Json t;
        t["spacing"] = number(p.tracing.spacing, f + ".tracing.spacing");
        t["extend_beyond_key_ribs"] = p.tracing.extendBeyondKeyRibs;
        // The rib bounds only when set (absent: off, as in files written before them, issue #20).
        if (p.tracing.minRibGap != 0)
            t["min_rib_gap"] = number(p.tracing.minRibGap, f + ".tracing.min_rib_gap");
        if (p.tracing.stopRibsAtCreases) t["stop_ribs_at_creases"] = true;
        if (p.tracing.closeLoops) t["close_loops"] = true;
        if (p.tracing.stopBackboneAtCreases) t["stop_backbone_at_creases"] = true;
        if (p.tracing.creaseBackbone) t["crease_backbone"] = true;
        if (p.tracing.continuousKeyRibs) t["continuous_key_ribs"] = true;
        if (p.tracing.clipRibsAtLasso) t["clip_ribs_at_lasso"] = true;
        if (p.tracing.peelRibEndsDeg != 0)
            t["peel_rib_ends_deg"] = number(p.tracing.peelRibEndsDeg, f + ".tracing.peel_rib_ends_deg");
        if (p.tracing.isotropicRibs) t["isotropic_ribs"] = true;
        if (p.tracing.maxRibTurnDeg != 180)
            t["max_rib_turn_deg"] = number(p.tracing.maxRibTurnDeg, f + ".tracing.max_rib_turn_deg");
        if (p.tracing.maxRibAspect != 0)
            t["max_rib_aspect"] = number(p.tracing.maxRibAspect, f + ".tracing.max_rib_aspect");
        if (p.tracing.spareFollowedCrease) t["spare_followed_crease"] = true;
        if (p.tracing.minFaceAngleDeg != 0)
            t["min_face_angle_deg"] = number(p.tracing.minFaceAngleDeg, f + ".tracing.min_face_angle_deg");
        if (p.tracing.minComponentFaces != 0) t["min_component_faces"] = p.tracing.minComponentFaces;
        t["backbone"] = streamline(p.tracing.backboneTracing, f + ".tracing.backbone");
        t["ribs"] = streamline(p.tracing.ribTracing, f + ".tracing.ribs");
        j["tracing"] = std::move(t);
        j["min_seed_anisotropy"] = number(p.minSeedAnisotropy, f + ".min_seed_anisotropy");
        j["crease"] = {{"angle_deg", number(p.creaseAngleDeg, f + ".crease.angle_deg")},
                       {"snap_radius", number(p.creaseSnapRadius, f + ".crease.snap_radius")}};
        j["raycast"] = {{"rings", p.raycast.rings}, {"verify_unoccluded", p.raycast.verifyUnoccluded}};
        j["sampling_factor"] = p.samplingFactor;
        return j;
    }

    Json stitch(const StitchOptions& s, const std::string& f) const {
        Json j;
        j["seam_rings"] = s.seamRings;
        j["optimise_seam"] = s.optimiseSeam;
        j["collapse_edge_ratio"] = number(s.collapseEdgeRatio, f + ".collapse_edge_ratio");
        j["seam_grading"] = number(s.seamGrading, f + ".seam_grading");
        j["min_angle_floor_deg"] = number(s.minAngleFloorDeg, f + ".min_angle_floor_deg");
        j["max_view_angle_deg"] = number(s.maxViewAngleDeg, f + ".max_view_angle_deg");
        j["max_normal_change_deg"] = number(s.maxNormalChangeDeg, f + ".max_normal_change_deg");
        j["max_gap_ratio"] = number(s.maxGapRatio, f + ".max_gap_ratio");
        j["max_trim_rounds"] = s.maxTrimRounds;
        j["min_component_faces"] = s.minComponentFaces;
        j["collect_garbage"] = s.collectGarbage;
        if (s.peelTrim) j["peel_trim"] = true;     // written only when on: older files stay byte-identical
        if (s.refillSeam) j["refill_seam"] = true; // written only when on: older files stay byte-identical
        // The band remesh is on by default since version 2 (issue 19): written only when off.
        if (!s.remeshSeam) j["remesh_seam"] = false;
        // Written only when not 0 (+0.0; -0.0 is written to keep the bits): older files, recorded with 0,
        // stay byte-identical.
        if (std::bit_cast<std::uint64_t>(s.outsideMinAngleFloorDeg) != 0)
            j["outside_min_angle_floor_deg"] =
                number(s.outsideMinAngleFloorDeg, f + ".outside_min_angle_floor_deg");
        return j;
    }

    Json step(const ScanStep& s, const std::string& f) const {
        const ScanParams& p = s.params;
        Json j;
        j["camera"] = camera(p.camera, f + ".camera");
        j["lasso"] = p.lasso ? points(p.lasso->points, f + ".lasso") : Json(nullptr);
        j["erode_radius"] = p.erodeRadius;
        j["dilate_radius"] = p.dilateRadius;
        if (p.relaxIterations != 0) j["relax_iterations"] = p.relaxIterations; // absent: 0 (issue #20)
        j["scan"] = {
            {"scan_id", p.scan.scanId},
            {"quality_angle_limit_deg",
             number(p.scan.qualityAngleLimitDeg, f + ".scan.quality_angle_limit_deg")},
            {"max_snap_footprints", number(p.scan.maxSnapFootprints, f + ".scan.max_snap_footprints")}};
        // The lattice and its mask always (issue #20): files without them mean the pixel lattice without
        // the mask, which is no longer the default.
        j["scan"]["lattice"] = p.scan.lattice == Lattice::Triangular ? "triangular"
                               : p.scan.lattice == Lattice::Adaptive ? "adaptive"
                                                                     : "square";
        j["scan"]["spacing_px"] = number(p.scan.spacingPixels, f + ".scan.spacing_px");
        j["scan"]["spacing_world"] = number(p.scan.spacingWorld, f + ".scan.spacing_world");
        j["scan"]["min_lattice_angle_deg"] =
            number(p.scan.minLatticeAngleDeg, f + ".scan.min_lattice_angle_deg");
        // Always written (version 3, issue #20): files without it were recorded without the warp.
        j["scan"]["warp_to_surface"] = p.scan.warpToSurface;
        // Written only when on (version 5, issue #20 session 19): files without it were recorded with the
        // session 17 fit.
        if (p.scan.warpFollowsFit) j["scan"]["warp_follows_fit"] = true;
        j["quality_mask"] = {{"margin", number(p.quality.margin, f + ".quality_mask.margin")},
                             {"force_replace", p.quality.forceReplace},
                             {"search_rings", p.quality.searchRings}};
        j["triangulate"] = {{"max_edge_footprints",
                             number(p.triangulate.maxEdgeFootprints, f + ".triangulate.max_edge_footprints")},
                            {"max_sampling_angle_deg", number(p.triangulate.maxSamplingAngleDeg,
                                                              f + ".triangulate.max_sampling_angle_deg")}};
        if (p.triangulate.minQuadAngleDeg != 0) // absent: 0, as files written before it (issue #20)
            j["triangulate"]["min_quad_angle_deg"] =
                number(p.triangulate.minQuadAngleDeg, f + ".triangulate.min_quad_angle_deg");
        j["grid"] = s.fishbone ? "fishbone" : "regular";
        if (s.fishbone) j["fishbone"] = fishbone(*s.fishbone, f + ".fishbone");
        j["stitch"] = stitch(s.stitch, f + ".stitch");
        return j;
    }
};

Json toJson(const SessionFile& file, const std::string& meshPathText) {
    const Writer w;
    if (file.renderer != "cpu" && file.renderer != "gpu")
        throw InvalidInputError("The session cannot be saved: its renderer '" + file.renderer +
                                "' is not one of cpu, gpu.");
    if (!isSha256Hex(file.meshSha256))
        throw InvalidInputError(
            "The session cannot be saved: mesh.sha256 is not 64 lowercase hexadecimal digits.");
    Json j;
    j["format"] = kFormatName;
    j["version"] = kSessionFileVersion;
    if (!file.description.empty()) j["description"] = file.description;
    j["mesh"] = {{"path", meshPathText}, {"sha256", file.meshSha256}};
    j["renderer"] = file.renderer;
    j["curvature"] = {
        {"jet_degree", file.curvature.jetDegree},
        {"min_points", file.curvature.minPoints},
        {"max_rings", file.curvature.maxRings},
        {"anisotropy_epsilon", w.number(file.curvature.anisotropyEpsilon, "curvature.anisotropy_epsilon")}};
    Json events = Json::array();
    for (std::size_t i = 0; i < file.events.size(); ++i) {
        const SessionEvent& e = file.events[i];
        Json je;
        je["kind"] = sessionEventKindName(e.kind);
        if (e.kind == SessionEvent::Kind::Accept)
            je["step"] = w.step(e.step, "events[" + std::to_string(i) + "].step");
        events.push_back(std::move(je));
    }
    j["events"] = std::move(events);
    return j;
}

// ---------------------------------------------------------------------------------------------- reading

// A JSON value with its path in the file ("events[3].step.camera"), for messages naming the field.
class Node {
public:
    Node(const Json& value, std::string path, const std::string& file)
        : v_(value), path_(std::move(path)), file_(file) {}

    const std::string& path() const { return path_; }
    [[noreturn]] void fail(const std::string& what) const {
        throw IoError(file_ + ": " + path_ + " " + what + ".");
    }

    /// Fails naming the field \p relative ("crease.angle_deg") below this node, whether present or not.
    [[noreturn]] void failAt(const std::string& relative, const std::string& what) const {
        throw IoError(file_ + ": " + child(relative) + " " + what + ".");
    }

    bool isNull() const { return v_.is_null(); }

    /// The member \p key of this object (which must be one).
    Node at(const std::string& key) const {
        requireObject();
        const auto it = v_.find(key);
        if (it == v_.end()) Node(v_, child(key), file_).fail("is missing");
        return Node(*it, child(key), file_);
    }
    bool has(const std::string& key) const { return v_.is_object() && v_.contains(key); }
    /// Refuses members other than \p allowed (typos would otherwise be ignored silently).
    void onlyKeys(std::initializer_list<const char*> allowed) const {
        requireObject();
        for (const auto& item : v_.items()) {
            bool known = false;
            for (const char* a : allowed)
                known = known || item.key() == a;
            if (!known) fail("has an unknown field '" + item.key() + "'");
        }
    }
    Node element(std::size_t i) const { return Node(v_[i], path_ + "[" + std::to_string(i) + "]", file_); }
    std::size_t arraySize(const std::string& what = "an array") const {
        if (!v_.is_array()) fail("must be " + what);
        return v_.size();
    }

    double number() const {
        if (!v_.is_number()) fail("must be a number");
        const double d = v_.get<double>();
        if (!std::isfinite(d)) fail("must be a finite number");
        return d;
    }
    double positive() const {
        const double d = number();
        if (!(d > 0)) fail("must be a positive number");
        return d;
    }
    double inRange(double lo, double hi, bool loOpen, bool hiOpen) const {
        const double d = number();
        const bool ok = (loOpen ? d > lo : d >= lo) && (hiOpen ? d < hi : d <= hi);
        if (!ok) {
            std::ostringstream os;
            os << "must be a number in " << (loOpen ? "(" : "[") << lo << ", " << hi << (hiOpen ? ")" : "]");
            fail(os.str());
        }
        return d;
    }
    std::int64_t integer(std::int64_t lo, std::int64_t hi, const std::string& what) const {
        if (!v_.is_number_integer()) fail("must be " + what);
        if (v_.is_number_unsigned() &&
            v_.get<std::uint64_t>() > std::uint64_t(std::numeric_limits<std::int64_t>::max()))
            fail("must be " + what);
        const std::int64_t i = v_.get<std::int64_t>();
        if (i < lo || i > hi) fail("must be " + what);
        return i;
    }
    bool boolean() const {
        if (!v_.is_boolean()) fail("must be true or false");
        return v_.get<bool>();
    }
    std::string string() const {
        if (!v_.is_string()) fail("must be a string");
        return v_.get<std::string>();
    }
    /// One of \p choices (as a string).
    std::string choice(std::initializer_list<const char*> choices) const {
        std::string list;
        for (const char* c : choices)
            list += std::string(list.empty() ? "" : ", ") + "\"" + c + "\"";
        if (!v_.is_string()) fail("must be one of " + list);
        const std::string s = v_.get<std::string>();
        for (const char* c : choices)
            if (s == c) return s;
        fail("must be one of " + list + ", not \"" + s + "\"");
    }
    Eigen::Vector3d vec3() const {
        if (!v_.is_array() || v_.size() != 3) fail("must be an array of 3 numbers");
        return {element(0).number(), element(1).number(), element(2).number()};
    }
    Eigen::Vector2d vec2() const {
        if (!v_.is_array() || v_.size() != 2) fail("must be an array of 2 numbers [x, y]");
        return {element(0).number(), element(1).number()};
    }
    std::vector<Eigen::Vector2d> points() const {
        const std::size_t n = arraySize("an array of points [x, y]");
        std::vector<Eigen::Vector2d> pts;
        pts.reserve(n);
        for (std::size_t i = 0; i < n; ++i)
            pts.push_back(element(i).vec2());
        return pts;
    }

private:
    void requireObject() const {
        if (!v_.is_object()) fail("must be a JSON object");
    }
    std::string child(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

    const Json& v_;
    std::string path_;
    const std::string& file_;
};

constexpr std::int64_t kIntMax = std::numeric_limits<int>::max();
constexpr std::int64_t kIntMin = std::numeric_limits<int>::min();
constexpr std::int64_t kInt64Max = std::numeric_limits<std::int64_t>::max();

// An int field: its type only (the range is the options' validate()).
int intField(const Node& n) {
    return int(n.integer(kIntMin, kIntMax, "an integer"));
}
// A count (std::size_t) field.
std::size_t countField(const Node& n) {
    return std::size_t(n.integer(0, kInt64Max, "an integer of at least 0"));
}

// Where the file spells an option other than as validate() names it (camelCase becomes snake_case by
// itself): the C++ name's prefix and the file's.
using Renames = std::initializer_list<std::pair<const char*, const char*>>;

// The path below an options struct's node of the field \p field as validate() names it
// ("tracing.backboneTracing.minStep" -> "tracing.backbone.min_step").
std::string jsonField(const std::string& field, Renames renames) {
    std::string out, rest = field;
    for (const auto& [from, to] : renames) {
        if (field.rfind(from, 0) == 0) {
            out = to;
            rest = field.substr(std::string(from).size());
            break;
        }
    }
    for (char c : rest) {
        if (c >= 'A' && c <= 'Z') {
            out += '_';
            out += char(c - 'A' + 'a');
        } else {
            out += c;
        }
    }
    return out;
}

// Runs \p validate (an options struct's validate(), the one statement of its ranges that the API uses too)
// and reports a field out of range at its path below \p n, with the range.
template <class Validate> void validated(const Node& n, Validate&& validate, Renames renames = {}) {
    try {
        validate();
    } catch (const InvalidOptionError& e) {
        n.failAt(jsonField(e.field(), renames), e.requirement());
    } catch (const InvalidInputError& e) {
        n.fail(std::string("is invalid (") + e.what() + ")");
    }
}

Camera readCamera(const Node& n) {
    n.onlyKeys({"eye", "focal", "up", "projection", "view_angle_deg", "parallel_scale", "near", "far",
                "width", "height"});
    Camera c;
    c.eye = n.at("eye").vec3();
    c.focal = n.at("focal").vec3();
    c.up = n.at("up").vec3();
    c.parallel = n.at("projection").choice({"perspective", "parallel"}) == "parallel";
    c.viewAngleDeg = n.at("view_angle_deg").inRange(0, 180, true, true);
    c.parallelScale = n.at("parallel_scale").positive();
    c.nearPlane = n.at("near").positive();
    c.farPlane = n.at("far").positive();
    if (!(c.farPlane > c.nearPlane)) n.at("far").fail("must be larger than near");
    const std::string side = "a positive integer of at most " + std::to_string(Camera::kMaxResolution);
    c.width = int(n.at("width").integer(1, Camera::kMaxResolution, side));
    c.height = int(n.at("height").integer(1, Camera::kMaxResolution, side));
    if ((c.eye - c.focal).norm() == 0)
        n.at("focal").fail("must differ from eye (the camera has no viewing direction)");
    if (c.up.cross(c.focal - c.eye).norm() <= 1e-12 * c.up.norm() * (c.focal - c.eye).norm())
        n.at("up").fail("must not be zero or parallel to the viewing direction");
    try {
        c.validate();
    } catch (const InvalidInputError& e) {
        n.fail(std::string("is invalid (") + e.what() + ")");
    }
    return c;
}

StreamlineOptions readStreamline(const Node& n) {
    n.onlyKeys(
        {"step", "min_step", "max_length", "min_anisotropy", "low_anisotropy", "max_turn_deg", "max_steps"});
    StreamlineOptions s;
    s.step = n.at("step").number();
    s.minStep = n.at("min_step").number();
    const Node maxLength = n.at("max_length");
    s.maxLength = maxLength.isNull() ? std::numeric_limits<double>::infinity() : maxLength.number();
    s.minAnisotropy = n.at("min_anisotropy").number();
    s.lowAnisotropy = n.at("low_anisotropy").choice({"stop", "continue_straight"}) == "stop"
                          ? LowAnisotropyPolicy::Stop
                          : LowAnisotropyPolicy::ContinueStraight;
    s.maxTurnDeg = n.at("max_turn_deg").number();
    s.maxSteps = countField(n.at("max_steps"));
    return s; // validated with its FishboneParams
}

FishboneParams readFishbone(const Node& n) {
    n.onlyKeys({"seed", "direction", "h", "key_ribs", "drawn_key_ribs", "drawn_backbone", "tracing",
                "min_seed_anisotropy", "crease", "raycast", "sampling_factor"});
    FishboneParams p;
    const Node seed = n.at("seed");
    if (!seed.isNull()) p.seed = seed.vec2();
    p.direction =
        n.at("direction").choice({"min", "max"}) == "min" ? PrincipalDirection::Min : PrincipalDirection::Max;
    p.spacing = n.at("h").number();
    p.keyRibs = n.at("key_ribs").points();
    const Node drawn = n.at("drawn_key_ribs");
    const std::size_t count = drawn.arraySize("an array of polylines");
    for (std::size_t i = 0; i < count; ++i)
        p.drawnKeyRibs.push_back(drawn.element(i).points());
    p.drawnBackbone = n.at("drawn_backbone").points();
    const Node t = n.at("tracing");
    t.onlyKeys({"spacing", "extend_beyond_key_ribs", "backbone", "ribs", "min_rib_gap", "max_rib_turn_deg",
                "stop_ribs_at_creases", "close_loops", "stop_backbone_at_creases", "isotropic_ribs",
                "max_rib_aspect", "spare_followed_crease", "min_face_angle_deg", "min_component_faces",
                "crease_backbone", "continuous_key_ribs", "clip_ribs_at_lasso", "peel_rib_ends_deg"});
    p.tracing.spacing = t.at("spacing").number();
    p.tracing.extendBeyondKeyRibs = t.at("extend_beyond_key_ribs").boolean();
    p.tracing.minRibGap = t.has("min_rib_gap") ? t.at("min_rib_gap").number() : 0.0;
    p.tracing.maxRibTurnDeg = t.has("max_rib_turn_deg") ? t.at("max_rib_turn_deg").number() : 180.0;
    p.tracing.stopRibsAtCreases = t.has("stop_ribs_at_creases") && t.at("stop_ribs_at_creases").boolean();
    p.tracing.closeLoops = t.has("close_loops") && t.at("close_loops").boolean();
    p.tracing.stopBackboneAtCreases =
        t.has("stop_backbone_at_creases") && t.at("stop_backbone_at_creases").boolean();
    p.tracing.isotropicRibs = t.has("isotropic_ribs") && t.at("isotropic_ribs").boolean();
    p.tracing.creaseBackbone = t.has("crease_backbone") && t.at("crease_backbone").boolean();
    p.tracing.continuousKeyRibs = t.has("continuous_key_ribs") && t.at("continuous_key_ribs").boolean();
    p.tracing.clipRibsAtLasso = t.has("clip_ribs_at_lasso") && t.at("clip_ribs_at_lasso").boolean();
    p.tracing.peelRibEndsDeg = t.has("peel_rib_ends_deg") ? t.at("peel_rib_ends_deg").number() : 0.0;
    p.tracing.maxRibAspect = t.has("max_rib_aspect") ? t.at("max_rib_aspect").number() : 0.0;
    p.tracing.spareFollowedCrease = t.has("spare_followed_crease") && t.at("spare_followed_crease").boolean();
    p.tracing.minFaceAngleDeg = t.has("min_face_angle_deg") ? t.at("min_face_angle_deg").number() : 0.0;
    p.tracing.minComponentFaces = t.has("min_component_faces") ? intField(t.at("min_component_faces")) : 0;
    p.tracing.backboneTracing = readStreamline(t.at("backbone"));
    p.tracing.ribTracing = readStreamline(t.at("ribs"));
    p.minSeedAnisotropy = n.at("min_seed_anisotropy").number();
    if (n.has("crease")) { // optional: files written before crease following get its defaults
        const Node c = n.at("crease");
        c.onlyKeys({"angle_deg", "snap_radius"});
        p.creaseAngleDeg = c.at("angle_deg").number();
        p.creaseSnapRadius = c.at("snap_radius").number();
    }
    const Node r = n.at("raycast");
    r.onlyKeys({"rings", "verify_unoccluded"});
    p.raycast.rings = intField(r.at("rings"));
    p.raycast.verifyUnoccluded = r.at("verify_unoccluded").boolean();
    // Optional: files written before the sampling image sampled at the scan resolution (k = 1).
    p.samplingFactor = n.has("sampling_factor") ? intField(n.at("sampling_factor")) : 1;
    return p; // validated by readStep, which knows the camera
}

StitchOptions readStitch(const Node& n) {
    n.onlyKeys({"seam_rings", "optimise_seam", "collapse_edge_ratio", "seam_grading", "min_angle_floor_deg",
                "max_view_angle_deg", "max_normal_change_deg", "max_gap_ratio", "max_trim_rounds",
                "min_component_faces", "collect_garbage", "peel_trim", "outside_min_angle_floor_deg",
                "refill_seam", "remesh_seam"});
    StitchOptions s;
    s.seamRings = intField(n.at("seam_rings"));
    s.optimiseSeam = n.at("optimise_seam").boolean();
    s.collapseEdgeRatio = n.at("collapse_edge_ratio").number();
    s.seamGrading = n.at("seam_grading").number();
    s.minAngleFloorDeg = n.at("min_angle_floor_deg").number();
    s.maxViewAngleDeg = n.at("max_view_angle_deg").number();
    s.maxNormalChangeDeg = n.at("max_normal_change_deg").number();
    s.maxGapRatio = n.at("max_gap_ratio").number();
    s.maxTrimRounds = intField(n.at("max_trim_rounds"));
    s.minComponentFaces = countField(n.at("min_component_faces"));
    s.collectGarbage = n.at("collect_garbage").boolean();
    // Optional, absent in files written before they were stored: what those files were recorded with.
    s.peelTrim = n.has("peel_trim") && n.at("peel_trim").boolean();
    s.refillSeam = n.has("refill_seam") && n.at("refill_seam").boolean();
    // Absent = on, in version 1 files too: they load and replay with the new stitch (README, DESIGN.md §7).
    s.remeshSeam = !n.has("remesh_seam") || n.at("remesh_seam").boolean();
    s.outsideMinAngleFloorDeg =
        n.has("outside_min_angle_floor_deg") ? n.at("outside_min_angle_floor_deg").number() : 0.0;
    validated(n, [&] { s.validate(); });
    return s;
}

ScanStep readStep(const Node& n) {
    n.onlyKeys({"camera", "lasso", "erode_radius", "dilate_radius", "relax_iterations", "scan",
                "quality_mask", "triangulate", "grid", "fishbone", "stitch"});
    ScanStep step;
    ScanParams& p = step.params;
    p.camera = readCamera(n.at("camera"));
    const Node lasso = n.at("lasso");
    if (!lasso.isNull()) {
        p.lasso = Lasso{lasso.points()};
        try {
            validateLasso(*p.lasso);
        } catch (const InvalidInputError&) {
            lasso.fail("must enclose an area (at least 3 points, not all collinear)");
        }
    }
    p.erodeRadius = intField(n.at("erode_radius"));
    p.dilateRadius = intField(n.at("dilate_radius"));
    // Files written before the patch relaxation (issue #20) did not relax.
    p.relaxIterations = n.has("relax_iterations") ? intField(n.at("relax_iterations")) : 0;
    const Node scan = n.at("scan");
    scan.onlyKeys({"scan_id", "quality_angle_limit_deg", "max_snap_footprints", "lattice", "spacing_px",
                   "spacing_world", "min_lattice_angle_deg", "warp_to_surface", "warp_follows_fit"});
    p.scan.scanId = std::int32_t(scan.at("scan_id").integer(std::numeric_limits<std::int32_t>::min(),
                                                            std::numeric_limits<std::int32_t>::max(),
                                                            "a 32-bit integer"));
    p.scan.qualityAngleLimitDeg = scan.at("quality_angle_limit_deg").number();
    p.scan.maxSnapFootprints = scan.at("max_snap_footprints").number();
    // Files written before the triangular lattice (issue #20) scanned on the pixel lattice.
    const std::string lattice =
        scan.has("lattice") ? scan.at("lattice").choice({"triangular", "square", "adaptive"}) : "square";
    p.scan.lattice = lattice == "triangular" ? Lattice::Triangular
                     : lattice == "adaptive" ? Lattice::Adaptive
                                             : Lattice::Square;
    p.scan.minLatticeAngleDeg =
        scan.has("min_lattice_angle_deg") ? scan.at("min_lattice_angle_deg").number() : 0.0;
    p.scan.spacingPixels = scan.has("spacing_px") ? scan.at("spacing_px").number() : 1.0;
    p.scan.spacingWorld = scan.has("spacing_world") ? scan.at("spacing_world").number() : 0.0;
    // Files written before version 3 scanned without the warp (issue #20).
    p.scan.warpToSurface = scan.has("warp_to_surface") && scan.at("warp_to_surface").boolean();
    // Files written before version 5 warped with the session 17 fit (issue #20, session 19).
    p.scan.warpFollowsFit = scan.has("warp_follows_fit") && scan.at("warp_follows_fit").boolean();
    const Node quality = n.at("quality_mask");
    quality.onlyKeys({"margin", "force_replace", "search_rings"});
    p.quality.margin = quality.at("margin").number();
    p.quality.forceReplace = quality.at("force_replace").boolean();
    p.quality.searchRings = intField(quality.at("search_rings"));
    const Node tri = n.at("triangulate");
    tri.onlyKeys({"max_edge_footprints", "max_sampling_angle_deg", "min_quad_angle_deg"});
    p.triangulate.maxEdgeFootprints = tri.at("max_edge_footprints").number();
    p.triangulate.maxSamplingAngleDeg = tri.at("max_sampling_angle_deg").number();
    p.triangulate.minQuadAngleDeg =
        tri.has("min_quad_angle_deg") ? tri.at("min_quad_angle_deg").number() : 0.0;
    validated(n, [&] { p.validate(); },
              {{"quality.", "quality_mask."}, {"scan.spacingPixels", "scan.spacing_px"}});
    const bool fishbone = n.at("grid").choice({"regular", "fishbone"}) == "fishbone";
    if (fishbone) {
        const Node fb = n.at("fishbone");
        step.fishbone = readFishbone(fb);
        validated(fb, [&] { step.fishbone->validate(p.camera); },
                  {{"spacing", "h"},
                   {"tracing.backboneTracing.", "tracing.backbone."},
                   {"tracing.ribTracing.", "tracing.ribs."},
                   {"creaseAngleDeg", "crease.angle_deg"},
                   {"creaseSnapRadius", "crease.snap_radius"}});
    } else if (n.has("fishbone"))
        n.at("fishbone").fail("must not be given when grid is \"regular\"");
    step.stitch = readStitch(n.at("stitch"));
    return step;
}

// "line L, column C" of byte offset \p byte in \p text (1-based).
std::string lineColumn(const std::string& text, std::size_t byte) {
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < byte && i < text.size(); ++i) {
        if (text[i] == '\n') {
            ++line;
            column = 1;
        } else {
            ++column;
        }
    }
    return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

std::filesystem::path absoluteNormal(const std::filesystem::path& p) {
    return std::filesystem::absolute(p).lexically_normal();
}

} // namespace

// ---------------------------------------------------------------------------------------------- public API

SessionFile sessionFileFromSession(const Session& session, const std::filesystem::path& meshPath,
                                   const std::string& renderer, const CurvatureOptions& curvature) {
    if (renderer != "cpu" && renderer != "gpu")
        throw InvalidInputError("The renderer '" + renderer + "' of a session file is not one of cpu, gpu.");
    SessionFile file;
    file.meshPath = meshPath;
    file.meshSha256 = sha256OfFile(meshPath);
    file.renderer = renderer;
    file.curvature = curvature;
    file.events = session.events();
    (void)toJson(file,
                 meshPath.generic_string()); // refuses what cannot be stored, before anything is written
    return file;
}

std::string sessionFileToJson(const SessionFile& file) {
    return toJson(file, file.meshPath.generic_string()).dump(2) + "\n";
}

void saveSessionFile(const SessionFile& file, const std::filesystem::path& path) {
    std::filesystem::path written = file.meshPath;
    if (written.is_relative()) {
        const std::filesystem::path folder = absoluteNormal(path).parent_path();
        written = absoluteNormal(file.meshPath).lexically_relative(folder);
        if (written.empty()) written = absoluteNormal(file.meshPath);
    }
    const std::string text = toJson(file, written.generic_string()).dump(2) + "\n";
    const std::filesystem::path tmp = path.string() + ".tmp" + std::to_string(::getpid());
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out)
            throw IoError("The session file " + path.string() + " cannot be written (cannot create " +
                          tmp.string() + ").");
        out << text;
        out.flush();
        if (!out) {
            std::error_code ec;
            std::filesystem::remove(tmp, ec);
            throw IoError("The session file " + path.string() + " could not be written completely.");
        }
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        std::filesystem::remove(tmp, ec);
        throw IoError("The session file " + path.string() + " cannot be written (" + ec.message() + ").");
    }
}

SessionFile sessionFileFromJson(const std::string& text, const std::string& name,
                                const std::filesystem::path& baseDir, const SessionFileLoadOptions& options) {
    Json json;
    try {
        json = Json::parse(text);
    } catch (const Json::parse_error& e) {
        if (text.find_first_not_of(" \t\r\n") == std::string::npos)
            throw IoError(name + " is empty, not a session file.");
        throw IoError(name + " is not valid JSON (" +
                      (e.byte >= text.size() ? "it ends early, at " : "error at ") +
                      lineColumn(text, e.byte > 0 ? e.byte - 1 : 0) + ").");
    }
    const Node root(json, "", name);
    if (!json.is_object()) throw IoError(name + " is not a session file: its JSON is not an object.");
    if (!root.has("format"))
        throw IoError(name + ": format is missing (a session file has \"format\": \"fss-session\").");
    if (root.at("format").string() != kFormatName)
        root.at("format").fail("must be \"fss-session\" (this is not an FSS session file)");
    const std::int64_t version = root.at("version").integer(1, kIntMax, "a positive integer");
    if (version > kSessionFileVersion)
        root.at("version").fail("is " + std::to_string(version) + ", but this FSS reads versions 1 to " +
                                std::to_string(kSessionFileVersion) + " only");
    root.onlyKeys({"format", "version", "description", "mesh", "renderer", "curvature", "events"});

    SessionFile file;
    file.version = int(version);
    file.source = name;
    if (root.has("description")) file.description = root.at("description").string();
    const Node mesh = root.at("mesh");
    mesh.onlyKeys({"path", "sha256"});
    const std::string meshText = mesh.at("path").string();
    if (meshText.empty()) mesh.at("path").fail("must not be empty");
    std::filesystem::path meshPath(meshText);
    if (meshPath.is_relative()) meshPath = (baseDir / meshPath).lexically_normal();
    file.meshPath = meshPath;
    file.meshSha256 = mesh.at("sha256").string();
    if (!isSha256Hex(file.meshSha256)) mesh.at("sha256").fail("must be 64 lowercase hexadecimal digits");
    file.renderer = root.at("renderer").choice({"cpu", "gpu"});
    const Node curvature = root.at("curvature");
    curvature.onlyKeys({"jet_degree", "min_points", "max_rings", "anisotropy_epsilon"});
    file.curvature.jetDegree = intField(curvature.at("jet_degree"));
    file.curvature.minPoints = intField(curvature.at("min_points"));
    file.curvature.maxRings = intField(curvature.at("max_rings"));
    file.curvature.anisotropyEpsilon = curvature.at("anisotropy_epsilon").number();
    validated(curvature, [&] { file.curvature.validate(); });

    const Node events = root.at("events");
    const std::size_t count = events.arraySize("an array of events");
    std::size_t applied = 0, recorded = 0; // the history as the log builds it
    for (std::size_t i = 0; i < count; ++i) {
        const Node e = events.element(i);
        SessionEvent event;
        const std::string kind = e.at("kind").choice({"accept", "undo", "redo"});
        if (kind == "accept") {
            e.onlyKeys({"kind", "step"});
            event.kind = SessionEvent::Kind::Accept;
            event.step = readStep(e.at("step"));
            recorded = ++applied;
        } else {
            e.onlyKeys({"kind"});
            if (kind == "undo") {
                event.kind = SessionEvent::Kind::Undo;
                if (applied == 0) e.fail("is an undo with no accepted step left to undo");
                --applied;
            } else {
                event.kind = SessionEvent::Kind::Redo;
                if (applied == recorded) e.fail("is a redo with no undone step to redo");
                ++applied;
            }
        }
        file.events.push_back(std::move(event));
    }

    if (options.verifyMesh) {
        std::error_code ec;
        if (!std::filesystem::is_regular_file(file.meshPath, ec))
            mesh.at("path").fail("names the mesh " + file.meshPath.string() + ", which does not exist");
        if (sha256OfFile(file.meshPath) != file.meshSha256)
            mesh.at("sha256").fail("does not match the mesh " + file.meshPath.string() +
                                   " (the file changed since the session was recorded)");
    }
    return file;
}

SessionFile loadSessionFile(const std::filesystem::path& path, const SessionFileLoadOptions& options) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
        throw IoError("The session file " + path.string() + " does not exist.");
    if (!std::filesystem::is_regular_file(path, ec))
        throw IoError("The session file " + path.string() + " is not a regular file.");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw IoError("The session file " + path.string() + " cannot be opened for reading.");
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) throw IoError("The session file " + path.string() + " could not be read.");
    return sessionFileFromJson(text.str(), path.string(), absoluteNormal(path).parent_path(), options);
}

ReplayResult replaySession(const SessionFile& file, const RendererFactory& renderer,
                           const Progress& progress) {
    const auto start = std::chrono::steady_clock::now();
    SessionReplay replay(file, renderer);
    while (!replay.done())
        replay.step(progress);
    progress.report(1.0, "done");
    ReplayResult result{std::move(*replay.takeSession()), replay.events(), replay.readSeconds(), 0};
    result.totalSeconds = seconds(start);
    return result;
}

const char* sessionEventKindName(SessionEvent::Kind kind) {
    switch (kind) {
    case SessionEvent::Kind::Accept:
        return "accept";
    case SessionEvent::Kind::Undo:
        return "undo";
    case SessionEvent::Kind::Redo:
        return "redo";
    }
    return "accept";
}

} // namespace fss
