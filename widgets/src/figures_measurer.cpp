#include "fss/widgets/figures_measurer.h"

#include "fss/error.h"
#include "fss/metrics.h"
#include "fss/progress.h"

#include <cmath>
#include <string_view>

namespace fss::widgets {

namespace {

// The measure itself: ends early when \p mine or \p stop is requested.
FiguresResult measureUntil(const Mesh& mesh, const std::stop_token& mine, const std::stop_token& stop) {
    FiguresResult result;
    const double faces = double(mesh.number_of_faces());
    const double steps = double(mesh.number_of_halfedges() + mesh.number_of_vertices());
    const Progress progress([&](double fraction, std::string_view stage) {
        if (stage == "valence") result.valenceSteps = std::size_t(std::llround(fraction * steps));
        if (stage == "smallest angle") {
            result.valenceSteps = std::size_t(steps);
            result.facesMeasured = std::size_t(std::llround(fraction * faces));
        }
        return !mine.stop_requested() && !stop.stop_requested();
    });
    try {
        const ValenceAndMinAngle m = valenceAndMinAngle(mesh, progress);
        result.figures = MeshFigures{m.fracValence6Interior, m.minAngleDeg};
    } catch (const CancelledError&) {
        result.figures.reset();
    }
    return result;
}

} // namespace

FiguresResult FiguresMeasurer::measure(const Mesh& mesh, std::stop_token stop) {
    if (stop.stop_requested()) return {};
    std::stop_source mine;
    {
        const std::lock_guard lock(mutex_);
        newest_.request_stop();
        newest_ = mine;
        ++requests_;
    }
    return measureUntil(mesh, mine.get_token(), stop);
}

FiguresResult FiguresMeasurer::measureAlone(const Mesh& mesh, std::stop_token stop) {
    return measureUntil(mesh, {}, stop);
}

void FiguresMeasurer::stop() {
    const std::lock_guard lock(mutex_);
    newest_.request_stop();
}

} // namespace fss::widgets
