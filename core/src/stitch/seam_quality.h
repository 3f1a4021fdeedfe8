#pragma once
// Seam quality figures (StitchReport, DESIGN.md §6): the smallest angle of the faces a stitch created, the
// share of them at or above 30 deg, and the valence histogram of the seam's vertices. Eigen only: used by the
// stitch and by its tests as an independent measure.

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

namespace fss::stitch {

/// Smallest interior angle of the triangle abc in degrees (0 for a degenerate one).
inline double smallestAngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    const std::array<Eigen::Vector3d, 3> p{a, b, c};
    double best = 180;
    for (std::size_t i = 0; i < 3; ++i) {
        const Eigen::Vector3d u = p[(i + 1) % 3] - p[i], v = p[(i + 2) % 3] - p[i];
        const double cross = u.cross(v).norm(), dot = u.dot(v);
        if (!(cross > 0)) return 0;
        best = std::min(best, std::atan2(cross, dot) * 180.0 / std::numbers::pi);
    }
    return best;
}

/// Seam figures accumulated over the faces a stitch created and the seam's vertices.
struct SeamQuality {
    std::size_t faces = 0;        ///< faces measured
    std::size_t facesAbove30 = 0; ///< of which the smallest angle is ≥ 30 deg
    double minAngleDeg = 180;     ///< smallest angle over them (180 when none)
    std::vector<std::size_t>
        valence; ///< valence histogram of the seam vertices: valence[k] vertices of valence k

    void addFace(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
        const double angle = smallestAngleDeg(a, b, c);
        ++faces;
        facesAbove30 += angle >= 30.0;
        minAngleDeg = std::min(minAngleDeg, angle);
    }
    void addVertex(std::size_t degree) {
        if (valence.size() <= degree) valence.resize(degree + 1, 0);
        ++valence[degree];
    }
    double fracAbove30() const { return faces ? double(facesAbove30) / double(faces) : 1.0; }
    std::size_t vertices() const {
        std::size_t n = 0;
        for (std::size_t k : valence)
            n += k;
        return n;
    }
    /// Share of the seam vertices of valence 5, 6 or 7 (1 when none).
    double fracValence5To7() const {
        std::size_t good = 0;
        for (std::size_t k = 5; k <= 7 && k < valence.size(); ++k)
            good += valence[k];
        const std::size_t n = vertices();
        return n ? double(good) / double(n) : 1.0;
    }
};

} // namespace fss::stitch
