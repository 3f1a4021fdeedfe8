// Stitching a scanned patch into the current mesh (DESIGN.md §1 "Stitch", §6).
//
// Per patch component (connected through vertices), without touching the mesh:
//  1. region     the faces of the current mesh under the component in the scan's view: front-facing, not
//                grazing, on the sheet the patch lies on (seeds: under the patch vertices, the face whose
//                plane is nearest along the view ray; grown over faces meeting the component's projection).
//                Faces near the patch boundary ("seam faces") are re-triangulated; the faces under the
//                patch, away from its boundary, are removed whole (folds and all).
//  2. insert     snap patch boundary vertices onto nearby mesh vertices / edges and mesh vertices onto nearby
//                patch boundary edges (no slivers), compute where patch boundary edges cross mesh edges (the
//                new vertex lies on the 3D mesh edge, perspective-correct), and build a constrained Delaunay
//                triangulation of the seam faces' edges and the patch boundary in the view (exact
//                predicates). A patch boundary vertex snapped onto an edge at the region's rim (a crease
//                whose far face the view does not see) splits that far face too, in its plane (checked in
//                3D, not in the view); its neighbours are opened to the seam flips.
//  3. cut, glue  flood-fill the triangulation: which seam face each triangle lies in, inside or outside the
//                patch. Seam faces are replaced by their outside triangles (in the face's plane: the surface
//                outside does not move); patch triangles on the boundary are re-triangulated over the seam
//                vertices of their edges (max-min angle, never three collinear points).
//  4. optimise   on a local copy (the star of the replaced faces): collapse short seam edges, refine the
//                pieces outside the patch with a graded size (new vertices on the old surface), flip for
//                angles and valence; never flip a face in the view, fold, move a vertex or bend the surface
//                outside the patch.
//  5. check      on the local copy: manifold, oriented, no degenerate or needle faces, every new face facing
//                the camera, border edges (so holes and boundary loops) unchanged, no self-intersections;
//                then rehearse the exact sequence of edits on a fresh local copy; only then edit the mesh.
// A problem that can be located (the patch reaching past a silhouette, a border, a grazing face, a fold,
// another sheet; a degenerate contact; a failed check) trims the patch faces there and the component is
// retried; what cannot be made stitchable is skipped and reported.

#include "fss/stitch.h"

#include "stitch/stitch_stages.h"

#include "fss/error.h"

namespace fss {
namespace detail::stitching {
// ---------------------------------------------------------------------------------------------------
PatchData readPatch(const Mesh& patch, const View& view, std::size_t& dropped) {
    PatchData P;
    std::unordered_map<std::uint32_t, int> index;
    for (VertexIndex v : patch.vertices()) {
        const Vec3 p = toVec(patch.point(v));
        if (!p.allFinite()) throw InvalidInputError("The patch has a vertex with a non-finite coordinate.");
        index[std::uint32_t(v)] = int(P.pos.size());
        P.pos.push_back(p);
        Point2 uv;
        double w = 0;
        if (!view.project(p, uv, w)) uv = Point2(std::numeric_limits<double>::quiet_NaN(), 0);
        P.uv.push_back(uv);
    }
    auto q = patch.property_map<FaceIndex, float>(props::faceQuality);
    auto s = patch.property_map<FaceIndex, std::int32_t>(props::faceScanId);
    P.hasQuality = q.second;
    P.hasScanId = s.second;
    for (FaceIndex f : patch.faces()) {
        std::array<int, 3> t;
        int k = 0;
        for (VertexIndex v : CGAL::vertices_around_face(patch.halfedge(f), patch)) {
            if (k == 3) throw InvalidInputError("The patch has a face that is not a triangle.");
            t[std::size_t(k++)] = index.at(std::uint32_t(v));
        }
        if (k != 3) throw InvalidInputError("The patch has a face that is not a triangle.");
        const Point2 &a = P.uv[std::size_t(t[0])], &b = P.uv[std::size_t(t[1])], &c = P.uv[std::size_t(t[2])];
        if (std::isnan(a.x()) || std::isnan(b.x()) || std::isnan(c.x()) || !leftTurn(a, b, c)) {
            ++dropped;
            continue;
        }
        P.tri.push_back(t);
        P.face.push_back(std::uint32_t(f));
        P.quality.push_back(q.second ? q.first[f] : kInputFaceQuality);
        P.scanId.push_back(s.second ? s.first[f] : -1);
    }
    return P;
}

// Components of patch faces connected through vertices, largest first.
std::vector<std::vector<int>> components(const PatchData& P, const std::vector<int>& faces) {
    detail::DisjointSets sets(P.uv.size());
    auto find = [&](int x) { return int(sets.find(std::size_t(x))); };
    for (int f : faces) {
        const auto& t = P.tri[std::size_t(f)];
        sets.unite(std::size_t(t[0]), std::size_t(t[1]));
        sets.unite(std::size_t(t[0]), std::size_t(t[2]));
    }
    std::unordered_map<int, std::size_t> which;
    std::vector<std::vector<int>> out;
    for (int f : faces) {
        const int r = find(P.tri[std::size_t(f)][0]);
        auto [it, fresh] = which.try_emplace(r, out.size());
        if (fresh) out.emplace_back();
        out[it->second].push_back(f);
    }
    std::stable_sort(out.begin(), out.end(),
                     [](const auto& x, const auto& y) { return x.size() > y.size(); });
    return out;
}

} // namespace detail::stitching

using namespace detail::stitching;

StitchReport stitchPatch(Mesh& current, const Mesh& patch, const Camera& scanCamera,
                         const StitchOptions& options, std::span<const std::uint32_t> faceIds,
                         const Progress& progress, std::vector<std::uint8_t>* stitchedPatchFaces) {
    return detail::stitchPatch(current, patch, scanCamera, options, faceIds, progress, {},
                               stitchedPatchFaces);
}

StitchReport detail::stitchPatch(Mesh& current, const Mesh& patch, const Camera& scanCamera,
                                 const StitchOptions& options, std::span<const std::uint32_t> faceIds,
                                 const Progress& progress, const BeforeStitchEdit& beforeEdit,
                                 std::vector<std::uint8_t>* stitchedPatchFaces) {
    const auto start = std::chrono::steady_clock::now();
    StageClock::start();
    if (stitchedPatchFaces) stitchedPatchFaces->assign(patch.num_faces(), 0);
    scanCamera.validate();
    if (patch.number_of_faces() == 0) throw InvalidInputError("The patch has no faces.");
    if (!faceIds.empty() && faceIds.size() != std::size_t(scanCamera.width) * std::size_t(scanCamera.height))
        throw InvalidInputError(
            "The ID buffer has " + std::to_string(faceIds.size()) +
            " pixels but the scan camera's image has " +
            std::to_string(std::size_t(scanCamera.width) * std::size_t(scanCamera.height)) + ".");
    options.validate();

    const View view(scanCamera);
    StitchReport report;
    std::size_t dropped = 0;
    const PatchData P = readPatch(patch, view, dropped);
    if (dropped > 0)
        report.skipped.push_back(std::to_string(dropped) +
                                 " patch faces were behind the camera or not facing it and were left out.");
    report.patchFacesTrimmed += dropped;

    std::vector<int> all(P.tri.size());
    for (std::size_t i = 0; i < all.size(); ++i)
        all[i] = int(i);
    struct Work {
        std::vector<int> faces;
        int name;   // number of the original component (1-based)
        int rounds; // trim rounds used
    };
    std::deque<Work> work;
    std::vector<std::size_t> componentFaces; // faces of each original component
    for (auto& c : components(P, all)) {
        componentFaces.push_back(c.size());
        work.push_back({std::move(c), int(componentFaces.size()), 0});
    }
    const int componentCount = int(componentFaces.size());
    std::map<int, std::string> firstReason; // per original component: the first reason a piece was dropped
    std::set<int> stitched;                 // original components with at least one piece glued in
    auto drop = [&](const Work& w, const std::string& why) {
        report.patchFacesTrimmed += w.faces.size();
        firstReason.try_emplace(w.name, why);
    };

    bool propsReady = false;
    std::size_t seamFacesAbove25 = 0, seamFacesAbove30 = 0, seamValence5To7 = 0;
    const double totalFaces = double(std::max<std::size_t>(P.tri.size(), 1));
    std::size_t facesDone = dropped; // faces stitched, trimmed or dropped so far
    double lastFraction = 0;         // reported fractions never go back
    while (!work.empty()) {
        // Cancellation points: between components and trim rounds, and inside a component's computation
        // (ComponentProgress), never inside an application.
        lastFraction = std::max(lastFraction, std::min(1.0, double(facesDone) / totalFaces));
        progress.report(lastFraction, "stitch");
        Work w = std::move(work.front());
        work.pop_front();
        if (w.faces.size() < options.minComponentFaces) {
            drop(w, w.rounds == 0
                        ? "it has fewer than " + std::to_string(options.minComponentFaces) + " faces"
                        : "what trimming left of it was too small");
            continue;
        }
        const bool curQ = current.property_map<FaceIndex, float>(props::faceQuality).second;
        const bool curS = current.property_map<FaceIndex, std::int32_t>(props::faceScanId).second;
        ComponentProgress componentProgress(progress, lastFraction, double(facesDone) / totalFaces,
                                            double(facesDone + w.faces.size()) / totalFaces);
        ComponentStitcher stitcher(current, P, view, options, faceIds, w.faces, curQ, curS,
                                   componentProgress);
        Attempt a;
        try {
            a = stitcher.run(); // never touches `current`
        } catch (const CGAL::Failure_exception& e) {
            a.reason = "an internal geometric check failed (" + std::string(e.what()) + ")";
        } catch (const std::logic_error& e) {
            a.reason = "an internal consistency check failed (" + std::string(e.what()) + ")";
        }
        if (!a.ok) {
            // Trim the faces around the problem and retry what is left (it may fall apart).
            std::unordered_set<int> bad(a.bad.begin(), a.bad.end());
            std::vector<int> rest;
            for (int f : w.faces) {
                const auto& t = P.tri[std::size_t(f)];
                if (!bad.count(t[0]) && !bad.count(t[1]) && !bad.count(t[2])) rest.push_back(f);
            }
            if (rest.size() == w.faces.size() || w.rounds >= options.maxTrimRounds) {
                drop(w, a.reason);
                continue;
            }
            report.patchFacesTrimmed += w.faces.size() - rest.size();
            firstReason.try_emplace(w.name, a.reason);
            for (auto& c : components(P, rest))
                work.push_front({std::move(c), w.name, w.rounds + 1});
            continue;
        }
        // Apply: every check has passed on the local copy and the rehearsal succeeded.
        StageClock::lap("other");
        if (beforeEdit) {
            std::vector<VertexIndex> used(a.plan.reused);
            for (const auto& face : a.plan.faces)
                for (const PlanVertex& v : face)
                    if (!v.fresh) used.push_back(VertexIndex(v.index));
            beforeEdit(current, a.plan.removed, used);
        }
        if (!propsReady) {
            if (P.hasQuality)
                current.add_property_map<FaceIndex, float>(props::faceQuality, kInputFaceQuality);
            if (P.hasScanId) current.add_property_map<FaceIndex, std::int32_t>(props::faceScanId, -1);
            propsReady = true;
        }
        auto q = current.property_map<FaceIndex, float>(props::faceQuality);
        auto s = current.property_map<FaceIndex, std::int32_t>(props::faceScanId);
        const Plan& plan = a.plan;
        const bool applied = replay(
            current, plan, [](VertexIndex v) { return v; }, [](FaceIndex f) { return f; },
            [&](std::size_t i, FaceIndex f) {
                const std::size_t n = plan.faces.size();
                if (q.second) q.first[f] = i < n ? plan.quality[i] : plan.coreQuality[i - n];
                if (s.second) s.first[f] = i < n ? plan.scanId[i] : plan.coreScanId[i - n];
            });
        if (!applied) throw Error("Internal error: a rehearsed stitch could not be applied to the mesh.");
        StageClock::lap("apply");
        stitched.insert(w.name);
        if (stitchedPatchFaces)
            for (int f : w.faces)
                (*stitchedPatchFaces)[P.face[std::size_t(f)]] = 1;
        facesDone += w.faces.size();
        ++report.piecesStitched;
        report.facesRemoved += plan.removed.size();
        report.facesAdded += plan.faces.size() + plan.coreFaces.size();
        report.seamEdges += plan.seamEdges;
        report.seamLength += plan.seamLength;
        report.collapses += plan.collapses;
        report.flips += plan.flips;
        for (double ang : plan.seamFaceMinAngles) {
            report.seamMinAngleDeg = std::min(report.seamMinAngleDeg, ang);
            seamFacesAbove25 += ang >= 25.0;
            seamFacesAbove30 += ang >= 30.0;
        }
        for (std::size_t k : plan.seamValences) {
            if (report.seamValenceHistogram.size() <= k) report.seamValenceHistogram.resize(k + 1, 0);
            ++report.seamValenceHistogram[k];
            seamValence5To7 += k >= 5 && k <= 7;
        }
        report.seamVertices += plan.seamValences.size();
        report.seamFaces += plan.seamFaceMinAngles.size();
    }
    report.componentsStitched = int(stitched.size());
    for (int c = 1; c <= componentCount; ++c) {
        if (stitched.count(c)) continue;
        ++report.componentsSkipped;
        report.skipped.push_back("Patch component " + std::to_string(c) + " (" +
                                 std::to_string(componentFaces[std::size_t(c - 1)]) +
                                 " faces) was not stitched: " + firstReason[c] + ".");
    }
    report.seamFracMinAngleAbove25 =
        report.seamFaces ? double(seamFacesAbove25) / double(report.seamFaces) : 1.0;
    report.seamFracMinAngleAbove30 =
        report.seamFaces ? double(seamFacesAbove30) / double(report.seamFaces) : 1.0;
    report.seamFracValence5To7 =
        report.seamVertices ? double(seamValence5To7) / double(report.seamVertices) : 1.0;
    if (report.componentsStitched == 0)
        throw InvalidInputError(
            "No part of the patch could be stitched" +
            (componentCount > 1 ? " (" + std::to_string(componentCount) + " components)" : std::string()) +
            ": " + (firstReason.empty() ? std::string("it is empty") : firstReason.begin()->second) + ".");
    if (options.collectGarbage) current.collect_garbage();
    StageClock::lap("other");
    StageClock::print();
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return report;
}

} // namespace fss
