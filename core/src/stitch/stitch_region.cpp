// Stitch stage "region" (DESIGN.md §6): member functions of ComponentStitcher (stitch_stages.h).

#include "stitch/stitch_stages.h"

namespace fss::detail::stitching {

bool ComponentStitcher::fail(Attempt& a, std::string reason, std::vector<int> bad) {
    a.ok = false;
    a.reason = std::move(reason);
    std::sort(bad.begin(), bad.end());
    bad.erase(std::unique(bad.begin(), bad.end()), bad.end());
    bad.erase(std::remove(bad.begin(), bad.end(), -1), bad.end());
    if (O_.peelTrim) {
        // Peel: of the vertices near the problem, only those on the component's boundary.
        std::vector<int> onBoundary;
        for (int v : bad)
            if (comp_.boundary.count(v)) onBoundary.push_back(v);
        if (!onBoundary.empty()) bad.swap(onBoundary);
    }
    a.bad = std::move(bad);
    return false;
}

// Stage "setup": the component's boundary edges (interior on their left), its vertices, its median edge
// lengths in the view and in 3D, the snapping radius of every boundary vertex and a grid over its
// triangles. Returns why the component cannot be stitched, or nothing.
std::string describeComponent(const PatchData& P, const std::vector<int>& faces, double collapseEdgeRatio,
                              ComponentShape& c, ComponentProgress* progress) {
    c = ComponentShape{};
    // The component's directed edges grouped by source vertex (a counting sort over the patch's vertices,
    // linear in the component where a sort of all edge keys and a binary search per edge cost n log n): an
    // edge is on the boundary when its reverse is not among them. The vertices come out sorted.
    const std::size_t nv = P.pos.size();
    std::vector<std::uint32_t> first(nv + 1, 0); // out-edges of v: to[first[v] .. first[v + 1])
    for (int f : faces)
        for (int v : P.tri[std::size_t(f)])
            ++first[std::size_t(v) + 1]; // each corner is the source of one directed edge of its face
    for (std::size_t v = 0; v < nv; ++v) {
        if (first[v + 1] > 0) c.verts.push_back(int(v));
        first[v + 1] += first[v];
    }
    std::vector<int> to(first[nv]);
    {
        std::vector<std::uint32_t> fill(first.begin(), first.end() - 1);
        for (int f : faces) {
            if (progress) progress->tick();
            const auto& t = P.tri[std::size_t(f)];
            for (int k = 0; k < 3; ++k)
                to[fill[std::size_t(t[std::size_t(k)])]++] = t[std::size_t((k + 1) % 3)];
        }
    }
    auto hasEdge = [&](int p, int q) {
        return std::find(to.begin() + first[std::size_t(p)], to.begin() + first[std::size_t(p) + 1], q) !=
               to.begin() + first[std::size_t(p) + 1];
    };
    std::vector<char> onBoundary(nv, 0);
    std::vector<double> len2, len3;
    for (int f : faces) {
        const auto& t = P.tri[std::size_t(f)];
        for (int k = 0; k < 3; ++k) {
            const int p = t[std::size_t(k)], q = t[std::size_t((k + 1) % 3)];
            const bool border = !hasEdge(q, p);
            if (border) {
                c.pedgeIndex[dirKey(std::uint32_t(p), std::uint32_t(q))] = int(c.pedges.size());
                c.pedges.push_back({p, q, t[std::size_t((k + 2) % 3)], {}, {}});
                c.boundary.insert(p);
                onBoundary[std::size_t(p)] = 1;
            }
            if (border || p < q) {
                len2.push_back(std::sqrt(dist2(P.uv[std::size_t(p)], P.uv[std::size_t(q)])));
                len3.push_back((P.pos[std::size_t(p)] - P.pos[std::size_t(q)]).norm());
            }
        }
    }
    if (c.pedges.empty()) return "it has no boundary in the scan's view (it would cover the whole view)";
    for (int f : faces)
        for (int v : P.tri[std::size_t(f)])
            if (onBoundary[std::size_t(v)]) c.vertexFaces[v].push_back(f);
    auto median = [](std::vector<double> v) {
        std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
        return v[v.size() / 2];
    };
    c.h2 = median(len2);
    c.h3 = median(len3);
    if (!(c.h2 > 0) || !(c.h3 > 0)) return "its triangles have no extent in the scan's view";
    for (const auto& e : c.pedges) {
        const double l = std::sqrt(dist2(P.uv[std::size_t(e.a)], P.uv[std::size_t(e.b)]));
        for (int v : {e.a, e.b}) {
            auto [it, fresh] = c.snapRadius.try_emplace(v, l);
            if (!fresh) it->second = std::min(it->second, l);
        }
    }
    for (auto& [v, r] : c.snapRadius) {
        r *= collapseEdgeRatio;
        c.margin = std::max(c.margin, r);
    }
    c.margin *= 1.01;
    c.box = CGAL::Bbox_2();
    for (int v : c.verts)
        c.box += P.uv[std::size_t(v)].bbox();
    c.grid = BucketGrid(2.0 * c.h2, faces.size(), c.box);
    for (std::size_t i = 0; i < faces.size(); ++i)
        c.grid.insert(int(i), patchTriangleBox(P, faces[i]));
    return {};
}

bool ComponentStitcher::setupComponent(Attempt& a) {
    const std::string why = describeComponent(P_, faces_, O_.collapseEdgeRatio, comp_, &progress_);
    return why.empty() || fail(a, why);
}

CGAL::Bbox_2 ComponentStitcher::triBox(int f) const {
    return patchTriangleBox(P_, f);
}

Triangle2 ComponentStitcher::patchTriangle(int f) const {
    const auto& t = P_.tri[std::size_t(f)];
    return {P_.uv[std::size_t(t[0])], P_.uv[std::size_t(t[1])], P_.uv[std::size_t(t[2])]};
}

std::vector<int> ComponentStitcher::patchVerticesNear(const Point2& q, double radius) {
    std::vector<int> out;
    const CGAL::Bbox_2 box = grown(q.bbox(), radius);
    comp_.grid.query(box, [&](int i) {
        if (CGAL::do_overlap(box, triBox(faces_[std::size_t(i)])))
            for (int v : P_.tri[std::size_t(faces_[std::size_t(i)])])
                out.push_back(v);
    });
    return out;
}

void ComponentStitcher::addNear(std::vector<int>& bad, const Point2& q) {
    bad.push_back(-1);
    for (double r = 1.5 * comp_.h2; r < 100.0 * comp_.h2; r *= 2.0) {
        auto near = patchVerticesNear(q, r);
        if (near.empty()) continue;
        bad.insert(bad.end(), near.begin(), near.end());
        return;
    }
}

void ComponentStitcher::addBad(std::vector<int>& bad, int i) {
    bad.push_back(-1);
    const LVert& l = cut_.L[std::size_t(i)];
    if (l.patchA >= 0 || l.patchB >= 0) {
        bad.push_back(l.patchA);
        bad.push_back(l.patchB);
    } else {
        addNear(bad, l.uv);
    }
}

auto ComponentStitcher::vproj(VertexIndex v) -> VProj {
    auto [it, fresh] = search_.vcache.slot(std::size_t(v), M_.num_vertices());
    if (fresh) {
        VProj p{}; // (value-initialised: a vertex behind the eye keeps uv = (0, 0), as in a map's new entry)
        p.ok = V_.project(toVec(M_.point(v)), p.uv, p.w);
        *it = {p.uv.x(), p.uv.y(), p.w, p.ok};
        return p;
    }
    return {Point2(it->u, it->v), it->w, it->ok};
}

bool ComponentStitcher::acceptable(FaceIndex f) {
    auto [it, fresh] = search_.accept.slot(std::size_t(f), M_.num_faces());
    if (!fresh) return *it != 0;
    *it = 0;
    const HalfedgeIndex h = M_.halfedge(f);
    if (M_.next(M_.next(M_.next(h))) != h) return false;
    const VertexIndex a = M_.source(h), b = M_.target(h), c = M_.target(M_.next(h));
    const VProj &pa = vproj(a), &pb = vproj(b), &pc = vproj(c);
    if (!pa.ok || !pb.ok || !pc.ok || !leftTurn(pa.uv, pb.uv, pc.uv)) return false;
    const Vec3 A = toVec(M_.point(a)), B = toVec(M_.point(b)), C = toVec(M_.point(c));
    const Vec3 n = normalOf(A, B, C);
    if (!(n.norm() > 0)) return false;
    const double cosView = n.normalized().dot(V_.towardsViewer((A + B + C) / 3.0));
    *it = char(cosView >= std::cos(O_.maxViewAngleDeg * kDeg));
    return *it != 0;
}

std::array<VertexIndex, 3> ComponentStitcher::faceVertices(FaceIndex f) const {
    const HalfedgeIndex h = M_.halfedge(f);
    return {M_.source(h), M_.target(h), M_.target(M_.next(h))};
}

Triangle2 ComponentStitcher::faceTriangle(FaceIndex f) {
    const auto v = faceVertices(f);
    return {vproj(v[0]).uv, vproj(v[1]).uv, vproj(v[2]).uv};
}

double ComponentStitcher::gapTo(const Vec3& p, FaceIndex f) const {
    const auto v = faceVertices(f);
    const Vec3 A = toVec(M_.point(v[0])), B = toVec(M_.point(v[1])), C = toVec(M_.point(v[2]));
    return gapToPlane(p, A, normalOf(A, B, C));
}

double ComponentStitcher::gapToPlane(const Vec3& p, const Vec3& A, const Vec3& n) const {
    Vec3 o, d;
    V_.rayThrough(p, o, d);
    const double den = n.dot(d);
    if (!(std::abs(den) > 0)) return std::numeric_limits<double>::infinity();
    const Vec3 q = o + d * (n.dot(A - o) / den);
    return (p - q).norm();
}

double ComponentStitcher::longestEdge(FaceIndex f) const {
    const auto v = faceVertices(f);
    double l = 0;
    for (int k = 0; k < 3; ++k)
        l = std::max(l, std::sqrt(CGAL::squared_distance(M_.point(v[std::size_t(k)]),
                                                         M_.point(v[std::size_t((k + 1) % 3)]))));
    return l;
}

bool ComponentStitcher::meetsComponent(FaceIndex f) {
    const Triangle2 t = faceTriangle(f);
    const double r2 = comp_.margin * comp_.margin;
    const double tolerance = gapTolerance(f);
    const auto fv = faceVertices(f);
    const Vec3 A = toVec(M_.point(fv[0]));
    const Vec3 n = normalOf(A, toVec(M_.point(fv[1])), toVec(M_.point(fv[2])));
    const CGAL::Bbox_2 box = grown(t.bbox(), comp_.margin);
    // Cheap tests first (this runs for every face under the patch): a patch triangle whose box misses
    // the face's box grown by the snapping distance is farther than that; the gaps along the view rays
    // need no triangle test; a corner of either triangle inside the other means they meet.
    return comp_.grid.any(box, [&](int i) {
        const int pf = faces_[std::size_t(i)];
        if (!CGAL::do_overlap(box, triBox(pf))) return false;
        bool onSheet = false;
        for (int v : P_.tri[std::size_t(pf)])
            if (gapToPlane(P_.pos[std::size_t(v)], A, n) <= tolerance) {
                onSheet = true;
                break;
            }
        if (!onSheet) return false;
        const Triangle2 p = patchTriangle(pf);
        return inTriangle(p[0], t[0], t[1], t[2]) || inTriangle(t[0], p[0], p[1], p[2]) ||
               CGAL::do_intersect(t, p) || CGAL::squared_distance(t, p) <= r2;
    });
}

double ComponentStitcher::gapToPatch(const Vec3& p, const Point2& uv) {
    double gap = std::numeric_limits<double>::infinity();
    comp_.grid.query(uv.bbox(), [&](int i) {
        const auto& tri = P_.tri[std::size_t(faces_[std::size_t(i)])];
        const Triangle2 t = patchTriangle(faces_[std::size_t(i)]);
        if (!inTriangle(uv, t[0], t[1], t[2])) return;
        const Vec3 &A = P_.pos[std::size_t(tri[0])], &B = P_.pos[std::size_t(tri[1])],
                   &C = P_.pos[std::size_t(tri[2])];
        const Vec3 n = normalOf(A, B, C);
        Vec3 o, d;
        V_.rayThrough(p, o, d);
        const double den = n.dot(d);
        if (!(std::abs(den) > 0)) return;
        gap = std::min(gap, (p - (o + d * (n.dot(A - o) / den))).norm());
    });
    return gap;
}

void ComponentStitcher::candidatesAt(const Point2& uv, std::vector<FaceIndex>& out) {
    out.clear();
    if (!ids_.empty()) {
        const int W = V_.camera().width, H = V_.camera().height;
        const int px = int(std::floor(uv.x())), py = int(std::floor(-uv.y()));
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int x = px + dx, y = py + dy;
                if (x < 0 || y < 0 || x >= W || y >= H) continue;
                const std::uint32_t id = ids_[std::size_t(y) * std::size_t(W) + std::size_t(x)];
                if (id == kNone) continue;
                const FaceIndex f(id);
                if (!M_.has_valid_index(f) || M_.is_removed(f)) continue;
                if (std::find(out.begin(), out.end(), f) == out.end()) out.push_back(f);
            }
        return;
    }
    if (!search_.fallbackBuilt) buildFallback();
    search_.fallbackGrid.query(uv.bbox(), [&](int i) { out.push_back(search_.fallback[std::size_t(i)]); });
}

void ComponentStitcher::buildFallback() {
    search_.fallbackBuilt = true;
    const CGAL::Bbox_2 box = grown(comp_.box, 2.0 * comp_.h2);
    std::vector<CGAL::Bbox_2> boxes;
    for (FaceIndex f : M_.faces()) {
        const HalfedgeIndex h = M_.halfedge(f);
        Point2 uv[3];
        double w;
        bool ok = true;
        int k = 0;
        for (VertexIndex v : CGAL::vertices_around_face(h, M_)) {
            if (k == 3 || !V_.project(toVec(M_.point(v)), uv[k], w)) {
                ok = false;
                break;
            }
            ++k;
        }
        if (!ok || k != 3) continue;
        const CGAL::Bbox_2 fb = bboxOf(uv[0], uv[1], uv[2]);
        if (!CGAL::do_overlap(fb, box) || !leftTurn(uv[0], uv[1], uv[2])) continue;
        search_.fallback.push_back(f);
        boxes.push_back(fb);
    }
    const double cell =
        std::max(4.0 * comp_.h2, std::max(box.xmax() - box.xmin(), box.ymax() - box.ymin()) / 64.0);
    search_.fallbackGrid = BucketGrid(cell, search_.fallback.size());
    for (std::size_t i = 0; i < search_.fallback.size(); ++i)
        search_.fallbackGrid.insert(int(i), boxes[i]);
}

bool ComponentStitcher::findRegion(Attempt& a) {
    // Seeds: under every boundary vertex and a sample of the interior, the acceptable face containing
    // the vertex in the view whose plane is nearest to it along the view ray.
    std::vector<int> samples(comp_.boundary.begin(), comp_.boundary.end());
    std::sort(samples.begin(), samples.end());
    {
        std::vector<int> interior;
        for (int v : comp_.verts)
            if (!comp_.boundary.count(v)) interior.push_back(v);
        std::sort(interior.begin(), interior.end());
        const std::size_t stride = std::max<std::size_t>(1, interior.size() / 2048);
        for (std::size_t i = 0; i < interior.size(); i += stride)
            samples.push_back(interior[i]);
    }
    std::vector<FaceIndex> seeds, cands;
    for (int pass = 0; pass < 2 && seeds.empty(); ++pass) {
        if (pass == 1) {
            if (ids_.empty()) break;
            ids_ = {}; // the ID buffer found nothing valid (stale after earlier components): fall back
        }
        for (int v : samples) {
            progress_.tick();
            const Point2& uv = P_.uv[std::size_t(v)];
            candidatesAt(uv, cands);
            FaceIndex best;
            double bestGap = std::numeric_limits<double>::infinity();
            for (FaceIndex f : cands) {
                if (!acceptable(f)) continue;
                const Triangle2 t = faceTriangle(f);
                if (!inTriangle(uv, t[0], t[1], t[2])) continue;
                const double g = gapTo(P_.pos[std::size_t(v)], f);
                if (g < bestGap) {
                    bestGap = g;
                    best = f;
                }
            }
            if (best != FaceIndex()) seeds.push_back(best);
        }
    }
    if (seeds.empty()) return fail(a, "no visible face of the mesh lies under it in the scan's view");
    // Grow over faces sharing a vertex, keeping the acceptable ones that meet the component in the view.
    DenseSet visited(M_.num_faces());
    std::vector<FaceIndex> stack;
    for (FaceIndex f : seeds)
        if (visited.insert(std::size_t(f))) stack.push_back(f);
    while (!stack.empty()) {
        const FaceIndex f = stack.back();
        stack.pop_back();
        progress_.tick();
        if (!acceptable(f) || !meetsComponent(f)) continue;
        reg_.index[std::uint32_t(f)] = int(reg_.faces.size());
        reg_.faces.push_back(f);
        for (VertexIndex v : faceVertices(f))
            for (FaceIndex g : CGAL::faces_around_target(M_.halfedge(v), M_))
                if (g != Mesh::null_face() && visited.insert(std::size_t(g))) stack.push_back(g);
    }
    if (reg_.faces.empty()) return fail(a, "no visible face of the mesh lies under it in the scan's view");
    return true;
}

bool ComponentStitcher::preTrim(Attempt& a) {
    double edge = 0;
    CGAL::Bbox_2 bounds;
    reg_.tris.clear();
    reg_.tris.reserve(reg_.faces.size());
    for (FaceIndex f : reg_.faces) {
        const Triangle2& t = reg_.tris.emplace_back(faceTriangle(f));
        edge += std::sqrt(dist2(t[0], t[1]));
        bounds += t.bbox();
    }
    edge /= double(reg_.faces.size());
    reg_.grid = BucketGrid(std::max(2.0 * comp_.h2, edge), reg_.faces.size(), bounds);
    for (std::size_t i = 0; i < reg_.faces.size(); ++i)
        reg_.grid.insert(int(i), reg_.tris[i].bbox());
    std::vector<int> bad;
    for (int v : comp_.verts) {
        progress_.tick();
        const Point2& uv = P_.uv[std::size_t(v)];
        bool inside = false;
        reg_.grid.query(uv.bbox(), [&](int i) {
            if (inside) return;
            const Triangle2& t = reg_.tris[std::size_t(i)];
            inside = inTriangle(uv, t[0], t[1], t[2]);
        });
        if (!inside) bad.push_back(v);
    }
    if (!bad.empty()) return fail(a, "it reaches past the visible part of the mesh", std::move(bad));
    return true;
}

bool ComponentStitcher::insidePatch(const Point2& p) {
    return comp_.grid.any(p.bbox(), [&](int i) {
        const Triangle2 t = patchTriangle(faces_[std::size_t(i)]);
        return inTriangle(p, t[0], t[1], t[2]);
    });
}

bool ComponentStitcher::interiorsOverlap(const Triangle2& s, const Triangle2& t) {
    for (const auto& [x, y] : {std::pair{&s, &t}, std::pair{&t, &s}})
        for (int k = 0; k < 3; ++k) {
            const Point2 &p = (*x)[k], &q = (*x)[(k + 1) % 3];
            if (CGAL::orientation(p, q, (*y)[0]) != CGAL::LEFT_TURN &&
                CGAL::orientation(p, q, (*y)[1]) != CGAL::LEFT_TURN &&
                CGAL::orientation(p, q, (*y)[2]) != CGAL::LEFT_TURN)
                return false;
        }
    return true;
}

Point2 ComponentStitcher::overlapCentre(const Triangle2& s, const Triangle2& t) {
    std::vector<Point2> poly{s[0], s[1], s[2]};
    for (int k = 0; k < 3 && !poly.empty(); ++k) {
        const Point2 &a = t[k], &b = t[(k + 1) % 3];
        std::vector<Point2> out;
        for (std::size_t i = 0; i < poly.size(); ++i) {
            const Point2 &p = poly[i], &q = poly[(i + 1) % poly.size()];
            const double dp = area2(a, b, p), dq = area2(a, b, q);
            if (dp >= 0) out.push_back(p);
            if ((dp >= 0) != (dq >= 0)) {
                const double u = dp / (dp - dq);
                out.emplace_back(p.x() + u * (q.x() - p.x()), p.y() + u * (q.y() - p.y()));
            }
        }
        poly.swap(out);
    }
    if (poly.empty()) return CGAL::centroid(s);
    double x = 0, y = 0;
    for (const Point2& p : poly) {
        x += p.x();
        y += p.y();
    }
    return {x / double(poly.size()), y / double(poly.size())};
}

double ComponentStitcher::depthAt(FaceIndex f, const Point2& q) const {
    const Ray ray = V_.camera().ray(q.x(), -q.y());
    const auto v = faceVertices(f);
    const Vec3 A = toVec(M_.point(v[0])), n = normalOf(A, toVec(M_.point(v[1])), toVec(M_.point(v[2])));
    const double den = n.dot(ray.direction);
    if (!(std::abs(den) > 0)) return std::numeric_limits<double>::infinity();
    return V_.camera().viewDepth(ray.origin + ray.direction * (n.dot(A - ray.origin) / den));
}

bool ComponentStitcher::splitRegion(Attempt& a) {
    BucketGrid segments(2.0 * comp_.h2, comp_.pedges.size());
    for (std::size_t i = 0; i < comp_.pedges.size(); ++i)
        segments.insert(int(i),
                        bboxOf(P_.uv[std::size_t(comp_.pedges[i].a)], P_.uv[std::size_t(comp_.pedges[i].b)]));
    const double reach2 = comp_.margin * comp_.margin; // the snapping distance
    std::vector<FaceIndex> seam;
    std::vector<FaceIndex> stack;
    DenseSet isSeam(M_.num_faces()), isInterior(M_.num_faces());
    for (std::size_t i = 0; i < reg_.faces.size(); ++i) {
        progress_.tick();
        const FaceIndex f = reg_.faces[i];
        const Triangle2& t = reg_.tris[i];
        bool near = false;
        segments.query(grown(t.bbox(), comp_.margin), [&](int k) {
            if (near) return;
            const Segment2 e(P_.uv[std::size_t(comp_.pedges[std::size_t(k)].a)],
                             P_.uv[std::size_t(comp_.pedges[std::size_t(k)].b)]);
            near = CGAL::do_intersect(t, e) || CGAL::squared_distance(t, e) <= reach2;
        });
        if (near) {
            seam.push_back(f);
            isSeam.insert(std::size_t(f));
        } else if (insidePatch(CGAL::centroid(t))) {
            isInterior.insert(std::size_t(f));
            stack.push_back(f);
        }
    }
    std::vector<int> bad;
    // Folds: front-facing faces overlapping in the view (a step of the mesh seen obliquely). Under the
    // patch they are simply replaced; where the patch boundary crosses them there is no height field
    // to cut, so the patch is cut back around every fold that reaches its boundary.
    {
        detail::DisjointSets clusters(reg_.faces.size());
        auto find = [&](int x) { return int(clusters.find(std::size_t(x))); };
        std::vector<char> folded(reg_.faces.size(), 0), hidden(reg_.faces.size(), 0);
        // Only the clusters of overlapping faces that reach a seam face matter: found by a flood over
        // overlaps from the seam faces (work proportional to the seam and its folds, not to the faces
        // under the patch).
        std::vector<char> reached(reg_.faces.size(), 0);
        std::vector<std::size_t> todo;
        for (std::size_t i = 0; i < reg_.faces.size(); ++i)
            if (isSeam.contains(std::size_t(reg_.faces[i]))) {
                reached[i] = 1;
                todo.push_back(i);
            }
        while (!todo.empty()) {
            const std::size_t i = todo.back();
            todo.pop_back();
            progress_.tick();
            reg_.grid.query(reg_.tris[i].bbox(), [&](int jj) {
                const std::size_t j = std::size_t(jj);
                if (j == i) return;
                // Each pair in the order (lower, higher index), as a scan over all pairs would.
                const std::size_t lo = std::min(i, j), hi = std::max(i, j);
                if (!interiorsOverlap(reg_.tris[lo], reg_.tris[hi])) return;
                folded[lo] = folded[hi] = 1;
                clusters.unite(lo, hi);
                // The one farther from the eye where they overlap is hidden there.
                const Point2 q = overlapCentre(reg_.tris[lo], reg_.tris[hi]);
                hidden[depthAt(reg_.faces[lo], q) > depthAt(reg_.faces[hi], q) ? lo : hi] = 1;
                if (!reached[j]) {
                    reached[j] = 1;
                    todo.push_back(j);
                }
            });
        }
        std::unordered_map<int, bool> clusterAtSeam;
        for (std::size_t i = 0; i < reg_.faces.size(); ++i)
            if (folded[i] && isSeam.contains(std::size_t(reg_.faces[i]))) clusterAtSeam[find(int(i))] = true;
        // Cut the patch back around the hidden faces, where it lies on their sheet; if that frees
        // nothing, around the whole fold.
        // (Peeling: only the patch triangles within snapping distance; the next round sees what is left.)
        const double r = O_.peelTrim ? comp_.margin : comp_.margin + comp_.h2;
        for (int pass = 0; pass < 2 && bad.empty(); ++pass)
            for (std::size_t i = 0; i < reg_.faces.size(); ++i) {
                if (!folded[i] || !clusterAtSeam.count(find(int(i))) || (pass == 0 && !hidden[i])) continue;
                const FaceIndex g = reg_.faces[i];
                const Triangle2& t = reg_.tris[i];
                const double tolerance = gapTolerance(g);
                comp_.grid.query(grown(t.bbox(), r), [&](int k) {
                    const auto& tri = P_.tri[std::size_t(faces_[std::size_t(k)])];
                    const Triangle2 p = patchTriangle(faces_[std::size_t(k)]);
                    if (!CGAL::do_intersect(t, p) && CGAL::squared_distance(t, p) > r * r) return;
                    bool onSheet = pass == 1;
                    for (int v : tri)
                        onSheet = onSheet || gapTo(P_.pos[std::size_t(v)], g) <= tolerance;
                    if (onSheet) bad.insert(bad.end(), tri.begin(), tri.end());
                });
            }
        if (!bad.empty())
            return fail(a, "the mesh under its boundary folds over itself in the scan's view",
                        std::move(bad));
    }
    // Faces connected to the interior ones, away from the seam, lying under the patch in the view.
    IndexMap<double> gapOfVertex;
    while (!stack.empty()) {
        const FaceIndex f = stack.back();
        stack.pop_back();
        progress_.tick();
        reg_.interior.push_back(f);
        for (HalfedgeIndex h : CGAL::halfedges_around_face(M_.halfedge(f), M_)) {
            const FaceIndex g = M_.face(M_.opposite(h));
            if (g == Mesh::null_face()) {
                addNear(bad, vproj(M_.target(h)).uv); // the mesh's border under the patch
                continue;
            }
            if (isSeam.contains(std::size_t(g)) || isInterior.contains(std::size_t(g))) continue;
            // Under the patch in the view, on its sheet (not a part of the mesh far behind or in front).
            bool under = true;
            const double tolerance = gapTolerance(g);
            for (VertexIndex v : CGAL::vertices_around_face(M_.halfedge(g), M_)) {
                const VProj& p = vproj(v);
                if (!p.ok) {
                    under = false;
                    continue;
                }
                // Each vertex is asked by every face around it: its gap is computed once.
                auto [gap, fresh] = gapOfVertex.try_emplace(std::uint32_t(v), 0.0);
                if (fresh) *gap = gapToPatch(toVec(M_.point(v)), p.uv);
                if (!(*gap <= tolerance)) under = false;
            }
            if (!under) {
                addNear(bad,
                        vproj(M_.target(h)).uv); // a face reaching out without a seam: a fold, a hole
                continue;
            }
            isInterior.insert(std::size_t(g));
            stack.push_back(g);
        }
    }
    if (!bad.empty())
        return fail(a, "the mesh under it folds or has a hole in the scan's view", std::move(bad));
    reg_.faces = std::move(seam);
    reg_.tris.clear(); // (it described the faces before)
    reg_.index.clear();
    for (std::size_t i = 0; i < reg_.faces.size(); ++i)
        reg_.index[std::uint32_t(reg_.faces[i])] = int(i);
    if (reg_.faces.empty()) return fail(a, "no visible face of the mesh lies under its boundary");
    return true;
}

} // namespace fss::detail::stitching
