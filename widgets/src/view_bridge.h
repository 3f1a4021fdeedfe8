#pragma once
// Private: the overlay layers of a VtkView. Each tool (lasso, fishbone) owns one layer of 2D strokes;
// VtkView::setOverlay shows one list of paths, so the layers are kept here, per view, and handed to it
// together whenever one changes. Nothing here is public API.

#include "fss/mesh.h"
#include "fss/widgets/vtk_view.h"

#include <QColor>
#include <QPointF>

#include <vector>

namespace fss::widgets::bridge {

/// One polyline painted over the 3D image, in device-independent widget pixels (as VtkView's OverlayPath).
struct Stroke {
    std::vector<QPointF> points;
    QColor color;
    bool closed = false;
    bool markers = false;
    qreal width = 2.0;
};

/// Overlay layers: each tool owns one, the view shows all of them (in this order).
enum class Layer { Lasso, Fishbone, Count };

/// Replaces the strokes of \p layer over \p view.
void setLayer(VtkView* view, Layer layer, std::vector<Stroke> strokes);
/// Removes the strokes of \p layer.
void clearLayer(VtkView* view, Layer layer);
/// All strokes currently shown over \p view (tests).
std::vector<Stroke> strokes(const VtkView* view);

/// Shows \p mesh keeping the current camera (VtkView::setMesh alone resets it to the initial view).
void showMeshKeepCamera(VtkView* view, const Mesh& mesh);

} // namespace fss::widgets::bridge
