#pragma once
// The StitchReport as JSON with snake_case keys, shared by `scan --into` and `run`.
#include "fss/stitch.h"

#include <nlohmann/json.hpp>

namespace fss::cli {

/// \p r as a JSON object (nlohmann::json or nlohmann::ordered_json).
template <class Json> Json stitchReportJson(const StitchReport& r) {
    return Json{{"faces_removed", r.facesRemoved},
                {"faces_added", r.facesAdded},
                {"seam_edges", r.seamEdges},
                {"seam_length", r.seamLength},
                {"seam_faces", r.seamFaces},
                {"seam_min_angle_deg", r.seamMinAngleDeg},
                {"seam_frac_min_angle_above_25", r.seamFracMinAngleAbove25},
                {"seam_frac_min_angle_above_30", r.seamFracMinAngleAbove30},
                {"seam_vertices", r.seamVertices},
                {"seam_valence_histogram", r.seamValenceHistogram},
                {"seam_frac_valence_5_to_7", r.seamFracValence5To7},
                {"components_stitched", r.componentsStitched},
                {"components_skipped", r.componentsSkipped},
                {"pieces_stitched", r.piecesStitched},
                {"patch_faces_trimmed", r.patchFacesTrimmed},
                {"collapses", r.collapses},
                {"flips", r.flips},
                {"skipped", r.skipped},
                {"seconds", r.seconds}};
}

} // namespace fss::cli
