#pragma once
/// \file figures_measurer.h
/// FiguresMeasurer: the whole-mesh figures an accept shows before → after (the share of interior vertices
/// of valence 6 and the smallest corner angle, valenceAndMinAngle in fss/metrics.h), measured on the
/// caller's worker thread in a way another thread can stop: a stop token checked every
/// kFiguresProgressFaces steps of the valence count and faces of the angle loop (no copy of the mesh, even
/// one with garbage), and a newer request stops the older one. RemeshWidget's trial stitches and
/// accepts measure through one, so a user who scans again on a large mesh does not wait for the abandoned
/// trial's measure of the whole mesh to end.

#include "fss/mesh.h"

#include <atomic>
#include <cstddef>
#include <mutex>
#include <optional>
#include <stop_token>

namespace fss::widgets {

/// The two figures (RemeshWidget::acceptSummary shows them before → after).
struct MeshFigures {
    double valence6 = 0; ///< fraction of interior vertices with valence 6
    double minAngle = 0; ///< smallest corner angle, degrees
};

/// What one request measured: the figures (none when it was stopped), the steps its valence count had
/// taken (halfedges and vertices visited; all of them when it got past that count) and the faces its angle
/// loop had measured when it ended (all of them when it finished).
struct FiguresResult {
    std::optional<MeshFigures> figures;
    std::size_t valenceSteps = 0;
    std::size_t facesMeasured = 0;
};

/// Measures MeshFigures on the calling thread (see the file comment); thread-safe.
class FiguresMeasurer {
public:
    /// Measures \p mesh. Stops the request running before (on any thread) first; ends early, without
    /// figures, when \p stop is requested or when a newer request comes. \pre every face is a triangle.
    /// \throw InvalidInputError when a face is not a triangle.
    /// A request whose \p stop is already requested ends at once and stops nothing.
    FiguresResult measure(const Mesh& mesh, std::stop_token stop = {});
    /// Measures \p mesh outside the newer-stops-older rule: only \p stop ends it early (an accept's
    /// measures, which only its own Cancel may stop).
    static FiguresResult measureAlone(const Mesh& mesh, std::stop_token stop = {});
    /// Stops the running request, if any.
    void stop();
    /// How many requests measure() has taken (a request has begun when this has grown).
    std::size_t requests() const { return requests_.load(); }

private:
    std::mutex mutex_;
    std::stop_source newest_; // the newest request's
    std::atomic<std::size_t> requests_{0};
};

} // namespace fss::widgets
