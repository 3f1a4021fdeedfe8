#include "view_bridge.h"

#include <QObject>

#include <array>
#include <utility>

namespace fss::widgets::bridge {

namespace {

constexpr const char* kStateName = "fss_widgets_bridge_overlay";

// Per-view state: the overlay layers, a child object of the view (it goes with the view).
class OverlayState final : public QObject {
public:
    explicit OverlayState(VtkView* view) : QObject(view), view_(view) {
        setObjectName(QString::fromLatin1(kStateName));
    }

    std::array<std::vector<Stroke>, std::size_t(Layer::Count)> layers;

    std::vector<Stroke> all() const {
        std::vector<Stroke> out;
        for (const auto& layer : layers)
            out.insert(out.end(), layer.begin(), layer.end());
        return out;
    }

    // Hands every layer's strokes to the view's overlay.
    void changed() {
        std::vector<OverlayPath> paths;
        for (const Stroke& s : all()) {
            OverlayPath p;
            p.points = s.points;
            p.color = s.color;
            p.closed = s.closed;
            p.markers = s.markers;
            p.width = s.width;
            paths.push_back(std::move(p));
        }
        if (paths.empty())
            view_->clearOverlay();
        else
            view_->setOverlay(std::move(paths));
    }

private:
    VtkView* view_;
};

OverlayState* state(const VtkView* view) {
    for (QObject* child : view->children())
        if (child->objectName() == QLatin1String(kStateName))
            if (auto* s = dynamic_cast<OverlayState*>(child)) return s;
    return nullptr;
}

OverlayState* ensureState(VtkView* view) {
    if (OverlayState* s = state(view)) return s;
    return new OverlayState(view);
}

} // namespace

void setLayer(VtkView* view, Layer layer, std::vector<Stroke> strokes) {
    OverlayState* s = ensureState(view);
    s->layers[std::size_t(layer)] = std::move(strokes);
    s->changed();
}

void clearLayer(VtkView* view, Layer layer) {
    OverlayState* s = state(view);
    if (!s || s->layers[std::size_t(layer)].empty()) return;
    s->layers[std::size_t(layer)].clear();
    s->changed();
}

std::vector<Stroke> strokes(const VtkView* view) {
    const OverlayState* s = state(view);
    return s ? s->all() : std::vector<Stroke>{};
}

void showMeshKeepCamera(VtkView* view, const Mesh& mesh) {
    if (!view->hasMesh() || mesh.is_empty()) {
        view->setMesh(mesh);
        return;
    }
    const Camera camera = view->camera();
    view->setMesh(mesh);
    view->setCamera(camera);
}

} // namespace fss::widgets::bridge
