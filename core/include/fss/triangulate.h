#pragma once
/// \file triangulate.h
/// **Triangulate**, DESIGN.md §1: the valid samples of a SampleGrid become a Patch, a regular triangle
/// mesh with interior valence 6. Every quad of four valid samples (r, c), (r, c+1), (r+1, c), (r+1, c+1)
/// is split along the diagonal (r, c)–(r+1, c+1) — the same diagonal everywhere, so every interior vertex
/// has valence exactly 6 — and each of the two triangles is kept unless it
///  - spans a depth discontinuity (silhouette, occlusion boundary): an edge longer than
///    `maxEdgeFootprints` pixel footprints (the smaller footprint of its two end samples);
///  - is a grazing-angle sliver: a corner sample's sampling angle, or the angle between the triangle's own
///    normal and the viewing ray, exceeds `maxSamplingAngleDeg`;
///  - is flipped on the screen: its screen orientation (exact 2D orientation predicate on the samples'
///    screen positions) is not the grid's orientation, or it is degenerate (crossing fishbone ribs);
///  - is back-facing: its 3D normal or a corner's reference normal points away from the viewer;
///  - belongs to a quad with a 3D corner angle below `minQuadAngleDeg` (both triangles are dropped: a
///    sliver of a fishbone grid whose ribs converge, issue #20), or with a triangle whose smallest 3D angle
///    is below `minTriangleAngleDeg` (a long thin quad keeps right corners but splits into slivers).
/// Then every connected set of kept triangles with fewer than `minComponentFaces` is dropped (the
/// fragments a fishbone grid leaves between crease stops and dropped quads, issue #20).
/// Vertices where the kept triangles meet in more than one fan (e.g. two quads touching only at a
/// corner) are made manifold by removing the triangles of all but the largest fan (repeated until no
/// such vertex is left). The result is a valid, edge-manifold, consistently oriented Surface_mesh whose
/// faces face the camera (counter-clockwise as seen by it).
///
/// Defaults, measured on CGAL's sample meshes (iso view, 256², CPU rasterizer; see triangulate_test):
/// a legitimate grid edge on a surface tilted by θ is about footprint / cos θ (√2 times that for the
/// diagonal), so `maxEdgeFootprints = 3` keeps every surface up to about 65–70° of tilt and rejects
/// every jump of more than three pixel footprints; `maxSamplingAngleDeg = 80` additionally rejects
/// grazing slivers when a larger edge limit is chosen. Grazing regions beyond ~70° are left to a later,
/// more frontal scan (the quality mask would prefer that one anyway).

#include "fss/mesh.h"
#include "fss/sample_grid.h"
#include "fss/scan_workspace.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace fss {

/// Grid position (row, column) of a patch vertex: the sample it was made from.
struct GridIndex {
    std::int32_t row = -1;
    std::int32_t col = -1;
    friend bool operator==(const GridIndex&, const GridIndex&) = default;
};

namespace props {
/// `GridIndex` of every patch vertex (vertex property of Patch::mesh).
inline constexpr const char* vertexGridIndex = "v:grid_index";
} // namespace props

/// Options of triangulateGrid.
struct TriangulateOptions {
    /// A triangle with an edge longer than this many pixel footprints (the smaller footprint of the
    /// edge's two samples) spans a depth discontinuity and is dropped. > 0.
    double maxEdgeFootprints = 3.0;
    /// A triangle with a corner sample, or a normal, at a larger angle to the viewing ray is a grazing
    /// sliver and is dropped. Degrees, in (0, 90].
    double maxSamplingAngleDeg = 80.0;
    /// Both triangles of a quad are dropped when one of the quad's four corner angles in 3D is smaller.
    /// Degrees, in [0, 90); 0 = no bound (session files written before it).
    double minQuadAngleDeg = 0.0;
    /// Both triangles of a quad are dropped when one of them has a 3D angle smaller than this. Degrees, in
    /// [0, 60); 0 = no bound (the regular scans; the fishbone scan sets FishboneOptions::minFaceAngleDeg).
    double minTriangleAngleDeg = 0.0;
    /// Connected parts of the patch (triangles sharing an edge, once the vertices are manifold) with fewer
    /// faces are dropped. 0 = none (the regular scans; the fishbone scan sets
    /// FishboneOptions::minComponentFaces).
    int minComponentFaces = 0;

    /// Checks the ranges: maxEdgeFootprints finite and > 0, maxSamplingAngleDeg in (0, 90],
    /// minQuadAngleDeg in [0, 90), minTriangleAngleDeg in [0, 60), minComponentFaces ≥ 0.
    /// \throw InvalidOptionError naming the field ("TriangulateOptions::maxEdgeFootprints must be a positive
    ///        finite number, not 0.").
    void validate() const;
};

/// What triangulateGrid did. Each dropped triangle is counted once, under the first test it failed in
/// the order below.
struct TriangulateReport {
    std::size_t quads = 0;                ///< grid quads with four valid samples (2 candidate triangles each)
    std::size_t flipped = 0;              ///< dropped: screen orientation against the grid's, or degenerate
    std::size_t sliverQuads = 0;          ///< dropped: a quad or triangle angle below the bounds
    std::size_t backFacing = 0;           ///< dropped: 3D or reference normal facing away from the viewer
    std::size_t longEdges = 0;            ///< dropped: an edge longer than maxEdgeFootprints footprints
    std::size_t grazing = 0;              ///< dropped: sampling angle beyond maxSamplingAngleDeg
    std::size_t nonManifoldVertices = 0;  ///< vertices that had more than one fan of triangles
    std::size_t nonManifoldTriangles = 0; ///< triangles removed to make those vertices manifold
    std::size_t smallParts = 0;           ///< dropped: in a part with fewer than minComponentFaces
    std::size_t faces = 0;                ///< faces of the patch
    std::size_t vertices = 0;             ///< vertices of the patch
};

/// A scan's patch: the mesh plus where its vertices came from.
struct Patch {
    /// The patch. Properties: props::vertexGridIndex (GridIndex) per vertex, props::faceQuality (float,
    /// the mean quality of the face's three samples, scan.h) and props::faceScanId (the grid's scanId)
    /// per face.
    Mesh mesh;
    int rows = 0;             ///< the grid's rows
    int cols = 0;             ///< the grid's columns
    std::int32_t scanId = -1; ///< the grid's scanId
    /// Vertex made from sample (r, c) at index r·cols + c; Mesh::null_vertex() for unused samples.
    std::vector<VertexIndex> vertexOfSample;
    TriangulateReport report;

    /// The vertex made from sample (r, c), or Mesh::null_vertex().
    VertexIndex vertexAt(int r, int c) const {
        return vertexOfSample[std::size_t(r) * std::size_t(cols) + std::size_t(c)];
    }
};

/// Triangulates the valid samples of \p grid (see the file comment for the rules and the guarantees).
/// Works for regular and fishbone grids alike (only the (row, col) neighbourhood, the samples' screen
/// positions and points are used). Samples that are valid but not `hit` or whose point is not finite are
/// treated as invalid. Cost: linear in the number of samples.
/// \throw InvalidInputError when the grid's sample count differs from rows × cols, maxEdgeFootprints is
///        not positive or maxSamplingAngleDeg is not in (0, 90].
Patch triangulateGrid(const SampleGrid& grid, const TriangulateOptions& options = {});

/// As triangulateGrid above, with the scratch buffers of \p workspace and, when a patch was recycled into
/// it, that patch's storage (scan_workspace.h): the same patch, without allocating when the workspace has
/// served a scan of this size before.
Patch triangulateGrid(const SampleGrid& grid, const TriangulateOptions& options, ScanWorkspace& workspace);

} // namespace fss
