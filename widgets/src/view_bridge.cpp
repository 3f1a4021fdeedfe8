#include "view_bridge.h"

#include <QEvent>
#include <QPainter>
#include <QPainterPath>
#include <QWidget>

#include <array>
#include <type_traits>
#include <utility>

namespace fss::widgets::bridge {

namespace {

// ---- compile-time detection of VtkView's extended API ------------------------------------------------

template <class F> struct FirstArgument;
template <class R, class C, class A, class... Rest> struct FirstArgument<R (C::*)(A, Rest...)> {
    using type = std::remove_cvref_t<A>;
};

template <class V>
concept HasOverlay = requires(V& v) {
    v.clearOverlay();
    &V::setOverlay;
};
template <class V>
concept HasGhost = requires(V& v, const Mesh& m) {
    v.setGhostMesh(m);
    v.clearGhostMesh();
    v.setGhostVisible(true);
};
template <class V>
concept HasPreview = requires(V& v, const Mesh& m) {
    v.setPreviewMesh(m);
    v.clearPreviewMesh();
};
template <class V>
concept HasRenderer = requires(V& v) {
    { v.createMeshRenderer() } -> std::convertible_to<std::unique_ptr<MeshRenderer>>;
};
template <class E>
concept HasScanIdMap = requires {
    E::ScanId;
};

constexpr const char* kStateName = "fss_widgets_bridge_overlay";

// Per-view state: the overlay layers, and the fallback painter of them (and of the preview's border)
// when the view cannot paint overlays itself. A child widget over the view, transparent for the mouse.
class OverlayState final : public QWidget {
public:
    explicit OverlayState(VtkView* view) : QWidget(view), view_(view) {
        setObjectName(QString::fromLatin1(kStateName));
        setAttribute(Qt::WA_TransparentForMouseEvents);
        setAttribute(Qt::WA_NoSystemBackground);
        setAttribute(Qt::WA_TranslucentBackground);
        setFocusPolicy(Qt::NoFocus);
        setGeometry(view->rect());
        view->installEventFilter(this);
        if constexpr (HasOverlay<VtkView>)
            hide();
        else
            show();
    }

    std::array<std::vector<Stroke>, std::size_t(Layer::Count)> layers;
    // Fallback preview: the patch's border edges in world space.
    std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> previewBorder;

    std::vector<Stroke> all() const {
        std::vector<Stroke> out;
        for (const auto& layer : layers)
            out.insert(out.end(), layer.begin(), layer.end());
        return out;
    }

    void changed();

protected:
    bool eventFilter(QObject* watched, QEvent* event) override {
        if (watched == view_ && event->type() == QEvent::Resize) setGeometry(view_->rect());
        return false;
    }

    void paintEvent(QPaintEvent*) override {
        QPainter painter(this);
        painter.setRenderHint(QPainter::Antialiasing);
        for (const Stroke& s : all()) {
            if (s.points.empty()) continue;
            QPen pen(s.color, s.width);
            pen.setCapStyle(Qt::RoundCap);
            pen.setJoinStyle(Qt::RoundJoin);
            painter.setPen(pen);
            painter.setBrush(Qt::NoBrush);
            QPainterPath path(s.points.front());
            for (std::size_t i = 1; i < s.points.size(); ++i)
                path.lineTo(s.points[i]);
            if (s.closed) path.closeSubpath();
            painter.drawPath(path);
            if (s.markers) {
                painter.setBrush(s.color);
                for (const QPointF& p : s.points)
                    painter.drawEllipse(p, s.width + 2, s.width + 2);
            }
        }
    }

private:
    VtkView* view_;
};

// Hands the strokes to the view's own overlay (a template so that the branch compiles only when V has it).
template <class V> void pushOverlay(V* view, QWidget* fallback, const std::vector<Stroke>& all) {
    if constexpr (HasOverlay<V>) {
        using Paths = typename FirstArgument<decltype(&V::setOverlay)>::type;
        Paths paths;
        for (const Stroke& s : all) {
            typename Paths::value_type p;
            p.points = s.points;
            p.color = s.color;
            p.closed = s.closed;
            p.markers = s.markers;
            p.width = s.width;
            paths.push_back(std::move(p));
        }
        if (paths.empty())
            view->clearOverlay();
        else
            view->setOverlay(std::move(paths));
    } else {
        (void)view;
        (void)all;
        fallback->raise();
        fallback->update();
    }
}

void OverlayState::changed() {
    pushOverlay(view_, this, all());
}

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

// Projects the fallback preview border with the view's current camera into the Preview layer.
[[maybe_unused]] void projectPreview(VtkView* view, OverlayState& s) {
    std::vector<Stroke> strokes;
    if (!s.previewBorder.empty() && view->hasMesh()) {
        const Camera camera = view->camera();
        const double sx = double(view->width()) / camera.width, sy = double(view->height()) / camera.height;
        for (const auto& [a, b] : s.previewBorder) {
            if (camera.viewDepth(a) <= 0 || camera.viewDepth(b) <= 0) continue;
            const Eigen::Vector3d pa = camera.project(a), pb = camera.project(b);
            strokes.push_back({{QPointF(pa.x() * sx, pa.y() * sy), QPointF(pb.x() * sx, pb.y() * sy)},
                               QColor(40, 200, 255),
                               false,
                               false,
                               2.0});
        }
    }
    s.layers[std::size_t(Layer::Preview)] = std::move(strokes);
    s.changed();
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

namespace {
template <class V> void setGhostImpl(V* view, const Mesh* reference) {
    if constexpr (HasGhost<V>) {
        if (reference)
            view->setGhostMesh(*reference);
        else
            view->clearGhostMesh();
    } else {
        (void)view;
        (void)reference;
    }
}

template <class V> void setPreviewImpl(V* view, const Mesh* patch) {
    if constexpr (HasPreview<V>) {
        if (patch)
            view->setPreviewMesh(*patch);
        else
            view->clearPreviewMesh();
    } else {
        OverlayState* s = ensureState(view);
        s->previewBorder.clear();
        if (patch)
            for (HalfedgeIndex h : patch->halfedges()) {
                if (!patch->is_border(h)) continue;
                const Point3& a = patch->point(patch->source(h));
                const Point3& b = patch->point(patch->target(h));
                s->previewBorder.emplace_back(Eigen::Vector3d(a.x(), a.y(), a.z()),
                                              Eigen::Vector3d(b.x(), b.y(), b.z()));
            }
        projectPreview(view, *s);
    }
}

template <class V> void refreshPreviewImpl(V* view) {
    if constexpr (!HasPreview<V>) {
        if (OverlayState* s = state(view); s && !s->previewBorder.empty()) projectPreview(view, *s);
    } else {
        (void)view;
    }
}

template <class V> std::unique_ptr<MeshRenderer> createRendererImpl(V* view) {
    if constexpr (HasRenderer<V>) {
        try {
            return view->createMeshRenderer();
        } catch (const std::exception&) {
            return nullptr; // no GL context yet (never shown) or no usable GL: the CPU renderer serves
        }
    } else {
        (void)view;
        return nullptr;
    }
}

template <class E> bool setScanIdImpl(VtkView* view) {
    if constexpr (HasScanIdMap<E>) {
        view->setColorMap(E::ScanId);
        return true;
    } else {
        (void)view;
        return false;
    }
}

} // namespace

void setGhost(VtkView* view, const Mesh* reference) {
    setGhostImpl(view, reference);
}
void setPreview(VtkView* view, const Mesh* patch) {
    setPreviewImpl(view, patch);
}
void refreshPreview(VtkView* view) {
    refreshPreviewImpl(view);
}
std::unique_ptr<MeshRenderer> createRenderer(VtkView* view) {
    return createRendererImpl(view);
}
bool setScanIdColorMap(VtkView* view) {
    return setScanIdImpl<ColorMap>(view);
}

QString features() {
    QStringList f;
    if constexpr (HasOverlay<VtkView>) f << QStringLiteral("overlay");
    if constexpr (HasGhost<VtkView>) f << QStringLiteral("ghost");
    if constexpr (HasPreview<VtkView>) f << QStringLiteral("preview");
    if constexpr (HasRenderer<VtkView>) f << QStringLiteral("renderer");
    if constexpr (HasScanIdMap<ColorMap>) f << QStringLiteral("scan-id");
    return f.isEmpty() ? QStringLiteral("none") : f.join(QLatin1Char(' '));
}

} // namespace fss::widgets::bridge
