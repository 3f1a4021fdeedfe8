#pragma once
/// \file metrics.h
/// Quality metrics of a triangle mesh: counts, topology, regularity (valence), triangle shape, and the
/// distance to a reference surface. The JSON keys used by `fss-remesh info --json` are the snake_case
/// names given in the comments.

#include "fss/mesh.h"
#include "fss/progress.h"

#include <cstddef>
#include <map>
#include <optional>
#include <string>

namespace fss {

/// Options of computeMetrics.
struct MetricsOptions {
    /// Count self-intersecting face pairs (CGAL PMP); skipped automatically above selfIntersectionMaxFaces.
    bool selfIntersections = true;
    std::size_t selfIntersectionMaxFaces = 2'000'000;
    /// When set, Hausdorff and RMS distances to this surface are measured.
    const Mesh* reference = nullptr;
    /// Sampling density of the distance measurement: points per squared bbox diagonal (both ways).
    double distanceSamplesPerArea = 0; ///< 0: choose automatically (about 100k samples each way)
};

/// All metrics of one mesh. Fields that were not measured are std::nullopt (JSON null).
struct Metrics {
    std::size_t vertices = 0;            ///< vertices
    std::size_t faces = 0;               ///< faces
    std::size_t edges = 0;               ///< edges
    std::size_t boundaryEdges = 0;       ///< boundary_edges
    std::size_t boundaryLoops = 0;       ///< boundary_loops
    std::size_t components = 0;          ///< components (connected by edges)
    bool closed = false;                 ///< closed (no boundary edge)
    std::size_t nonManifoldVertices = 0; ///< non_manifold_vertices of the mesh (pinched vertices)
    std::size_t degenerateFaces = 0;     ///< degenerate_faces (collinear corners, exact predicate)
    std::optional<std::size_t> selfIntersections; ///< self_intersections (face pairs), null when skipped

    std::map<int, std::size_t> valenceHistogram; ///< valence_histogram (interior vertices only)
    std::size_t interiorVertices = 0;            ///< interior_vertices
    double fracValence6Interior = 0;             ///< frac_valence6_interior

    double minAngleDeg = 0;            ///< min_angle_deg over all corners
    double maxAngleDeg = 0;            ///< max_angle_deg over all corners
    double meanMinAngleDeg = 0;        ///< mean_min_angle_deg: mean of each triangle's smallest angle
    double fracMinAngleBelow30 = 0;    ///< frac_min_angle_below_30
    double fracMinAngleBelow10 = 0;    ///< frac_min_angle_below_10
    double radiusRatioMean = 0;        ///< radius_ratio_mean: 2 r_in / r_circ, 1 for equilateral
    double radiusRatioMin = 0;         ///< radius_ratio_min
    double edgeLengthMean = 0;         ///< edge_length_mean
    double edgeLengthCv = 0;           ///< edge_length_cv: standard deviation / mean
    double bboxDiagonal = 0;           ///< bbox_diagonal
    double area = 0;                   ///< area

    /// Distances to the reference (MetricsOptions::reference), absolute and relative to its bbox diagonal.
    std::optional<double> hausdorffToRef;      ///< hausdorff_to_ref: max over this mesh of distance to ref
    std::optional<double> hausdorffFromRef;    ///< hausdorff_from_ref: max over ref of distance to this mesh
    std::optional<double> hausdorffToRefRel;   ///< hausdorff_to_ref_rel
    std::optional<double> hausdorffFromRefRel; ///< hausdorff_from_ref_rel
    std::optional<double> rmsToRef;            ///< rms_to_ref
};

/// Computes the metrics of \p mesh. Linear in the mesh size except self-intersections (O(n log n)) and
/// the distance measurement (AABB trees of both meshes).
/// \throw InvalidInputError when the reference is given but empty. CancelledError through \p progress.
Metrics computeMetrics(const Mesh& mesh, const MetricsOptions& options = {}, const Progress& progress = {});

/// The metrics as one JSON object with the snake_case keys documented above (no trailing newline).
std::string metricsToJson(const Metrics& metrics, int indent = 2);

/// A human-readable multi-line summary (for `fss-remesh info` without --json).
std::string metricsToText(const Metrics& metrics);

} // namespace fss
