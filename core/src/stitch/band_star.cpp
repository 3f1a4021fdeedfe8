// Stitch v2, design B: the compound repair of a band face that no single flip, collapse, move or split
// improves (band_remesher.h, DESIGN.md §6.2). A small disk of band faces around it (its free corners' stars,
// its neighbours, optionally one ring more) is triangulated anew in the scan's view by the gap's quality CDT
// (gap_triangulation.h: the disk's border loop as constraints, crease chords inside kept as constraints, a
// few variants of interior points), the new vertices lifted onto the draft's smooth surface; the disk is
// replaced only where the smallest angle over it rises and every band rule holds (faces facing the camera
// and within the normal bound, valences 4..8, creases kept, held vertices fixed, new edges near the draft).
#include "stitch/band_remesher.h"
#include "stitch/gap_triangulation.h"

#include <map>
#include <string>

namespace fss::stitch::band {

namespace {
using V2 = Eigen::Vector2d;
// At most this many faces in a disk (the repair is local; a larger disk is refused).
constexpr std::size_t kMaxStarFaces = 40;

double cross2(const V2& a, const V2& b) {
    return a.x() * b.y() - a.y() * b.x();
}

// Barycentric coordinates of p in the 2D triangle (a, b, c); false when degenerate.
bool barycentric2(const V2& a, const V2& b, const V2& c, const V2& p, std::array<double, 3>& w) {
    const double area = cross2(b - a, c - a);
    if (!(std::abs(area) > 0)) return false;
    w[0] = cross2(b - p, c - p) / area;
    w[1] = cross2(c - p, a - p) / area;
    w[2] = 1.0 - w[0] - w[1];
    return true;
}
} // namespace

bool BandRemesher::starDisk(const std::vector<FaceIndex>& faces, StarDisk& disk) {
    disk = StarDisk{};
    disk.faces = faces;
    std::sort(disk.faces.begin(), disk.faces.end());
    disk.faces.erase(std::unique(disk.faces.begin(), disk.faces.end()), disk.faces.end());
    if (disk.faces.size() > kMaxStarFaces) return false;
    std::unordered_set<std::uint32_t> in;
    for (FaceIndex f : disk.faces) {
        if (!inBand(f) || S_.is_removed(f) || unseen(f)) return false;
        in.insert(std::uint32_t(f));
    }
    // The border: halfedges of the disk whose opposite face is outside it. Each border vertex once (a
    // disk, not a pinched one); no border edge on the mesh's border (its vertices could be left isolated).
    std::unordered_map<std::uint32_t, HalfedgeIndex> next; // border halfedge by its source
    std::unordered_set<std::uint32_t> verts;
    for (FaceIndex f : disk.faces)
        for (HalfedgeIndex h : CGAL::halfedges_around_face(S_.halfedge(f), S_)) {
            verts.insert(std::uint32_t(S_.target(h)));
            const HalfedgeIndex o = S_.opposite(h);
            if (S_.is_border(o)) return false;
            if (in.count(std::uint32_t(S_.face(o)))) continue;
            if (!next.emplace(std::uint32_t(S_.source(h)), h).second) return false;
        }
    if (next.size() < 3) return false;
    HalfedgeIndex h = next.begin()->second;
    // Start at the smallest source for a deterministic loop.
    for (const auto& [s, g] : next)
        if (s < std::uint32_t(S_.source(h))) h = g;
    const VertexIndex start = S_.source(h);
    do {
        disk.loop.push_back(S_.source(h));
        auto it = next.find(std::uint32_t(S_.target(h)));
        if (it == next.end() || disk.loop.size() > next.size()) return false;
        h = it->second;
    } while (S_.source(h) != start);
    if (disk.loop.size() != next.size()) return false; // more than one border loop
    std::unordered_set<std::uint32_t> onLoop;
    for (VertexIndex v : disk.loop)
        onLoop.insert(std::uint32_t(v));
    for (std::uint32_t v : verts)
        if (!onLoop.count(v)) disk.inner.push_back(VertexIndex(v));
    std::sort(disk.inner.begin(), disk.inner.end());
    // Interior vertices go: they must be free (not held, not on a crease, their whole star in the band).
    for (VertexIndex v : disk.inner)
        if (isFixed(v) || creaseDegree(v) > 0 || !wholeStarInBand(v) || S_.is_border(v)) return false;
    // Nearly flat: every well-shaped face within the normal bound of the disk's mean normal (a disk over a
    // fold that no crease marks would be cut across it in the view).
    V3 mean(0, 0, 0);
    for (FaceIndex f : disk.faces)
        mean += areaVector(f);
    if (!(mean.squaredNorm() > 0)) return false;
    mean.normalize();
    for (FaceIndex f : disk.faces)
        if (faceMinAngle(f) >= kSliverDeg * kBandDeg && !detail::angleAtMost(faceNormal(f), mean, maxTurn_))
            return false;
    // A disk: V - E + F = 1.
    const std::size_t E = (3 * disk.faces.size() + disk.loop.size()) / 2;
    return verts.size() + disk.faces.size() == E + 1;
}

bool BandRemesher::repairStar(FaceIndex f) {
    if (stageOff("star") || unseen(f)) return false;
    // Disks grown from f and its neighbours by the stars of free vertices (its corners and the corners
    // across its edges first, then one ring further), a star taken only where the faces stay a disk whose
    // interior vertices are all free: the first ring's disk and the widest.
    auto free = [&](VertexIndex v) { return !isFixed(v) && creaseDegree(v) == 0 && wholeStarInBand(v); };
    std::vector<FaceIndex> region{f};
    std::vector<VertexIndex> corners;
    for (HalfedgeIndex h : CGAL::halfedges_around_face(S_.halfedge(f), S_)) {
        if (interiorEdge(h)) {
            region.push_back(S_.face(S_.opposite(h)));
            corners.push_back(S_.target(S_.next(S_.opposite(h))));
        }
        corners.push_back(S_.target(h));
    }
    StarDisk disk, grown;
    if (!starDisk(region, disk)) {
        region = {f};
        if (!starDisk(region, disk)) {
            if (bandDiagnosticsVerbose())
                std::fprintf(stderr, "  star at face %u: no disk around it\n", std::uint32_t(f));
            return false;
        }
    }
    auto growBy = [&](const std::vector<VertexIndex>& verts) {
        for (VertexIndex v : verts) {
            if (!free(v)) continue;
            std::vector<FaceIndex> more = region;
            for (HalfedgeIndex h : CGAL::halfedges_around_target(S_.halfedge(v), S_))
                more.push_back(S_.face(h));
            if (starDisk(more, grown)) {
                region = std::move(more);
                disk = grown;
            }
        }
    };
    std::sort(corners.begin(), corners.end());
    growBy(corners);
    std::vector<StarDisk> disks{disk};
    std::vector<VertexIndex> ring = disk.loop;
    std::sort(ring.begin(), ring.end());
    growBy(ring);
    if (disk.faces != disks.front().faces) disks.push_back(disk);
    StarPlan best;
    for (const StarDisk& d : disks) {
        StarPlan plan;
        const bool planned = planStar(d, plan);
        if (bandDiagnosticsVerbose())
            std::fprintf(stderr, "  star at face %u (%.2f deg): disk of %zu faces, %zu inner: %s %.2f deg\n",
                         std::uint32_t(f), faceMinAngle(f) / kBandDeg, d.faces.size(), d.inner.size(),
                         planned ? "planned" : "no plan", planned ? plan.minAngle / kBandDeg : 0.0);
        if (planned && plan.minAngle > best.minAngle) best = std::move(plan);
    }
    if (best.triangles.empty()) return false;
    const bool applied = applyStar(best);
    if (bandDiagnosticsVerbose() && !applied) std::fprintf(stderr, "  star: not applied (non-manifold)\n");
    return applied;
}

bool BandRemesher::planStar(const StarDisk& disk, StarPlan& best) {
    StarView sv;
    if (!viewStar(disk, sv)) return false;
    // Variants: the loop alone; with the old interior points; refined for quality with the local size.
    struct Variant {
        bool innerPoints;
        double angle;
    };
    const double aim = in_.minAngleDeg * kBandDeg;
    for (const Variant& var : {Variant{false, 0}, Variant{true, 0}, Variant{false, 25}, Variant{true, 25}}) {
        GapBoundary b = sv.gap;
        if (var.innerPoints && sv.innerUv.empty()) continue;
        if (var.innerPoints) b.points.insert(b.points.end(), sv.innerUv.begin(), sv.innerUv.end());
        GapOptions o;
        o.minAngleDeg = var.angle;
        o.lloydIterations = 0;
        o.maxSteinerPerBoundaryPoint = 1.0;
        const double sizePx = sv.sizePx;
        if (var.angle > 0) o.size = [sizePx](const V2&) { return 1.5 * sizePx; };
        const GapTriangulation t = triangulateGap(b, o);
        StarPlan plan;
        const std::string why = t.ok && !t.triangles.empty() ? judgeStar(sv, t, plan) : t.reason;
        if (bandDiagnosticsVerbose() && !why.empty())
            std::fprintf(stderr, "    variant %d/%.0f: %s\n", int(var.innerPoints), var.angle, why.c_str());
        if (!why.empty()) continue;
        if (plan.minAngle > best.minAngle) best = std::move(plan);
        if (best.minAngle >= aim) break;
    }
    return !best.triangles.empty();
}

bool BandRemesher::viewStar(const StarDisk& disk, StarView& sv) {
    sv.disk = &disk;
    GapBoundary& gap = sv.gap;
    std::unordered_map<std::uint32_t, V2>& uvOf = sv.uvOf;
    // The disk in the view (screen x, -screen y: front-facing triangles counter-clockwise).
    const Eigen::Matrix4d vp = in_.camera->viewProjectionMatrix();
    auto project = [&](const V3& p, V2& uv) {
        const Eigen::Vector4d clip = vp * p.homogeneous();
        if (!(clip.w() > 0) || !clip.allFinite()) return false;
        uv = V2((clip.x() / clip.w() + 1.0) * 0.5 * in_.camera->width,
                -(1.0 - clip.y() / clip.w()) * 0.5 * in_.camera->height);
        return uv.allFinite();
    };
    std::unordered_map<std::uint32_t, int> index; // loop and interior vertices -> GapBoundary point
    double len3 = 0, len2 = 0;
    sv.oldMin = std::numbers::pi;
    for (VertexIndex v : disk.loop) {
        V2 uv;
        if (!project(detail::pos(S_, v), uv)) return false;
        index[std::uint32_t(v)] = int(gap.points.size());
        gap.points.push_back(uv);
    }
    const int n = int(disk.loop.size());
    double area = 0;
    for (int i = 0; i < n; ++i) {
        const int j = (i + 1) % n;
        gap.constraints.push_back({i, j});
        area += cross2(gap.points[std::size_t(i)], gap.points[std::size_t(j)]);
        len2 += (gap.points[std::size_t(j)] - gap.points[std::size_t(i)]).norm();
        len3 +=
            (detail::pos(S_, disk.loop[std::size_t(j)]) - detail::pos(S_, disk.loop[std::size_t(i)])).norm();
    }
    if (!(area > 0) || !(len3 > 0)) return false;
    const double pxPerUnit = len2 / len3;
    // The old faces in the view (to place new points on the draft and to find each new face's reference).
    for (std::size_t i = 0; i < disk.loop.size(); ++i)
        uvOf[std::uint32_t(disk.loop[i])] = gap.points[i];
    for (VertexIndex v : disk.inner) {
        V2 uv;
        if (!project(detail::pos(S_, v), uv)) return false;
        uvOf[std::uint32_t(v)] = uv;
        sv.innerUv.push_back(uv);
    }
    // Crease chords inside the disk (both ends on the loop) stay as constraints; so must existing edges
    // between loop vertices outside the disk not be made twice.
    std::unordered_set<std::uint64_t> chords;
    V3& starNormal = sv.starNormal;
    starNormal = V3(0, 0, 0);
    for (FaceIndex g : disk.faces) {
        sv.oldMin = std::min(sv.oldMin, faceMinAngle(g));
        starNormal += areaVector(g);
        for (HalfedgeIndex h : CGAL::halfedges_around_face(S_.halfedge(g), S_)) {
            const VertexIndex a = S_.source(h), b = S_.target(h);
            sv.diskEdges.insert(bandKey(a, b));
            if (isCrease(a, b) && chords.insert(bandKey(a, b)).second) {
                const int ia = index.at(std::uint32_t(a)), ib = index.at(std::uint32_t(b));
                if (std::abs(ia - ib) != 1 && std::abs(ia - ib) != n - 1) gap.constraints.push_back({ia, ib});
            }
        }
    }
    starNormal.normalize();
    double sizeSum = 0;
    for (VertexIndex v : disk.loop)
        sizeSum += sizeOf(v);
    sv.sizePx = sizeSum / double(disk.loop.size()) * pxPerUnit;
    return true;
}

FaceIndex BandRemesher::starFaceAt(const StarView& sv, const V2& p, std::array<double, 3>& w) const {
    // The old face under p in the view: the one p is most inside of.
    FaceIndex bestFace = Mesh::null_face();
    double bestMin = -std::numeric_limits<double>::infinity();
    for (FaceIndex g : sv.disk->faces) {
        std::array<V2, 3> t;
        int k = 0;
        for (VertexIndex v : CGAL::vertices_around_face(S_.halfedge(g), S_))
            t[std::size_t(k++)] = sv.uvOf.at(std::uint32_t(v));
        std::array<double, 3> b;
        if (!barycentric2(t[0], t[1], t[2], p, b)) continue;
        const double m = std::min({b[0], b[1], b[2]});
        if (m > bestMin) {
            bestMin = m;
            bestFace = g;
            w = b;
        }
    }
    return bestFace;
}

std::string BandRemesher::judgeStar(const StarView& sv, const GapTriangulation& t, StarPlan& plan) {
    const StarDisk& disk = *sv.disk;
    const int n = int(disk.loop.size());
    const V3& starNormal = sv.starNormal;
    auto oldFaceAt = [&](const V2& p, std::array<double, 3>& w) { return starFaceAt(sv, p, w); };
    plan.disk = disk;
    // New points (interior points given and Steiner points) placed on the draft's smooth surface.
    bool placed = true;
    for (std::size_t i = std::size_t(n); i < t.points.size() && placed; ++i) {
        std::array<double, 3> w{};
        const FaceIndex g = oldFaceAt(t.points[i], w);
        if (g == Mesh::null_face()) {
            placed = false;
            break;
        }
        V3 q(0, 0, 0);
        double size = 0;
        FaceIndex hint = Mesh::null_face();
        int k = 0;
        for (VertexIndex v : CGAL::vertices_around_face(S_.halfedge(g), S_)) {
            q += w[std::size_t(k)] * detail::pos(S_, v);
            size += w[std::size_t(k++)] * sizeOf(v);
            const FaceIndex hv = at(hint_, std::size_t(v), Mesh::null_face());
            if (hint == Mesh::null_face()) hint = hv;
        }
        if (hint == Mesh::null_face()) {
            placed = false;
            break;
        }
        const SurfacePoint sp = near2_(q, hint);
        if (!sp) {
            placed = false;
            break;
        }
        plan.points.push_back(smoothPoint(sp.face, sp.point));
        plan.hints.push_back(sp.face);
        plan.sizes.push_back(size);
    }
    if (!placed) return "a point off the draft";
    auto posOf = [&](int i) {
        return i < n ? detail::pos(S_, disk.loop[std::size_t(i)]) : plan.points[std::size_t(i - n)];
    };
    auto hintOf = [&](int i) {
        return i < n ? at(hint_, std::size_t(disk.loop[std::size_t(i)]), Mesh::null_face())
                     : plan.hints[std::size_t(i - n)];
    };
    // Faces: facing, within the normal bound of the old face under them, near the draft.
    bool ok = true;
    double newMin = std::numbers::pi;
    std::map<std::pair<int, int>, int> edgeUse;
    std::vector<int> degree(t.points.size(), 0);
    for (const auto& tri : t.triangles) {
        const V3 a = posOf(tri[0]), bb = posOf(tri[1]), c = posOf(tri[2]);
        const V2 centre =
            (t.points[std::size_t(tri[0])] + t.points[std::size_t(tri[1])] + t.points[std::size_t(tri[2])]) /
            3.0;
        std::array<double, 3> w{};
        const FaceIndex under = oldFaceAt(centre, w);
        if (under == Mesh::null_face() || !acceptableFace(a, bb, c, referenceNormal(under, starNormal))) {
            if (under == Mesh::null_face()) return "a face off the disk";
            char why[96];
            std::snprintf(
                why, sizeof why, "a face turned (facing %d, %.1f deg from face %u)", int(facing(a, bb, c)),
                detail::angleBetween(detail::unitNormal(a, bb, c), referenceNormal(under, starNormal)) /
                    kBandDeg,
                std::uint32_t(under));
            return why;
        }
        newMin = std::min(newMin, detail::minAngle(a, bb, c));
        plan.parents.push_back(under);
        for (int e = 0; e < 3; ++e) {
            const int x = tri[std::size_t(e)], y = tri[std::size_t((e + 1) % 3)];
            if (++edgeUse[{std::min(x, y), std::max(x, y)}] == 1) {
                ++degree[std::size_t(x)];
                ++degree[std::size_t(y)];
            }
        }
    }
    if (!(newMin > sv.oldMin + 0.5 * kBandDeg)) {
        char why[64];
        std::snprintf(why, sizeof why, "%.2f -> %.2f deg", sv.oldMin / kBandDeg, newMin / kBandDeg);
        return why;
    }
    // Interior edges: near the draft; between two loop vertices only where no such edge exists outside.
    for (const auto& [e, uses] : edgeUse) {
        const auto [x, y] = e;
        const bool loopEdge = x < n && y < n && (y - x == 1 || (x == 0 && y == n - 1));
        if (loopEdge) continue;
        if (uses != 2) {
            ok = false;
            break;
        }
        if (x < n && y < n) {
            const VertexIndex a = disk.loop[std::size_t(x)], b2 = disk.loop[std::size_t(y)];
            if (S_.halfedge(a, b2) != Mesh::null_halfedge() && !sv.diskEdges.count(bandKey(a, b2))) {
                ok = false;
                break;
            }
        }
        const V3 pa = posOf(x), pb = posOf(y);
        const SurfacePoint sp = near2_(0.5 * (pa + pb), hintOf(x));
        if (sp && sp.distance > 0.1 * (pa - pb).norm()) {
            ok = false;
            break;
        }
    }
    if (!ok) return "an edge off the draft or made twice";
    // Valences: the loop's vertices lose the old interior edges and gain the new ones; new vertices 4..8.
    for (int i = 0; i < n && ok; ++i) {
        const VertexIndex v = disk.loop[std::size_t(i)];
        // Its old interior edges: the disk's edges at it other than its two loop edges.
        int oldInner = -2;
        for (VertexIndex w : CGAL::vertices_around_target(S_.halfedge(v), S_))
            oldInner += int(sv.diskEdges.count(bandKey(v, w)));
        ok = valenceOk(v, (degree[std::size_t(i)] - 2) - oldInner);
    }
    for (std::size_t i = std::size_t(n); i < degree.size() && ok; ++i)
        ok = degree[i] >= 4 && degree[i] <= 8;
    if (!ok) return "a valence";
    plan.minAngle = newMin;
    plan.triangles = t.triangles;
    return {};
}

bool BandRemesher::applyStar(const StarPlan& plan) {
    const StarDisk& disk = plan.disk;
    const int n = int(disk.loop.size());
    // Rehearsed on a copy: every face must go in without a non-manifold step, else nothing changes. New
    // elements are not recycled, so the removed faces' data stays readable for the new faces (faceData).
    auto build = [&](Mesh& M, std::vector<VertexIndex>& added, std::vector<FaceIndex>& made) {
        const bool recycle = M.does_recycle_garbage();
        M.set_recycle_garbage(false);
        for (FaceIndex g : disk.faces)
            CGAL::Euler::remove_face(M.halfedge(g), M);
        for (const V3& p : plan.points)
            added.push_back(M.add_vertex(Point3(p.x(), p.y(), p.z())));
        auto vertexOf = [&](int i) { return i < n ? disk.loop[std::size_t(i)] : added[std::size_t(i - n)]; };
        std::vector<std::size_t> left(plan.triangles.size());
        for (std::size_t i = 0; i < left.size(); ++i)
            left[i] = i;
        made.assign(plan.triangles.size(), Mesh::null_face());
        while (!left.empty()) {
            std::vector<std::size_t> still;
            for (std::size_t i : left) {
                const auto& t = plan.triangles[i];
                const FaceIndex g = M.add_face(vertexOf(t[0]), vertexOf(t[1]), vertexOf(t[2]));
                if (g == Mesh::null_face())
                    still.push_back(i);
                else
                    made[i] = g;
            }
            if (still.size() == left.size()) break;
            left.swap(still);
        }
        M.set_recycle_garbage(recycle);
        return left.empty();
    };
    {
        Mesh trial = S_;
        std::vector<VertexIndex> added;
        std::vector<FaceIndex> made;
        if (!build(trial, added, made)) return false;
        for (VertexIndex v : disk.loop)
            if (trial.is_border(v) != S_.is_border(v)) return false;
    }
    std::vector<VertexIndex> added;
    std::vector<FaceIndex> made;
    for (FaceIndex g : disk.faces)
        band_[std::size_t(g)] = 0;
    build(S_, added, made);
    for (std::size_t i = 0; i < added.size(); ++i) {
        const VertexIndex v = added[i];
        at(fixed_, std::size_t(v), char(1)) = 0;
        at(size_, std::size_t(v), in_.edgeLength) = plan.sizes[i];
        at(hint_, std::size_t(v), Mesh::null_face()) = plan.hints[i];
        at(touched_, std::size_t(v), char(0)) = 1;
        creasePos_.erase(std::uint32_t(v));
        if (in_.vertexData) in_.vertexData(v, Mesh::null_vertex());
    }
    for (std::size_t i = 0; i < made.size(); ++i) {
        at(band_, std::size_t(made[i]), char(0)) = 1;
        at(unseen_, std::size_t(made[i]), char(0)) = 0;
        if (in_.faceData) in_.faceData(made[i], plan.parents[i]);
    }
    return true;
}

} // namespace fss::stitch::band
