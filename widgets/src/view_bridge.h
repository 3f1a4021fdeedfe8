#pragma once
// Private: everything the tools and the RemeshWidget ask of a VtkView beyond its first public API goes
// through these few functions. VtkView is being extended (overlays, ghost and preview meshes, a GPU
// MeshRenderer sharing its GL context, a scan-id colour map); view_bridge.cpp detects at compile time
// whether the VtkView it is built against has each of those members and uses them, and otherwise falls
// back to what works without them (a QPainter overlay widget over the view, a wire overlay of the preview
// patch's border, CpuMeshRenderer). Nothing here is public API.

#include "fss/mesh.h"
#include "fss/scan_pipeline.h"
#include "fss/widgets/vtk_view.h"

#include <QColor>
#include <QPointF>
#include <QString>

#include <memory>
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
enum class Layer { Lasso, Fishbone, Preview, Count };

/// Replaces the strokes of \p layer over \p view.
void setLayer(VtkView* view, Layer layer, std::vector<Stroke> strokes);
/// Removes the strokes of \p layer.
void clearLayer(VtkView* view, Layer layer);
/// All strokes currently shown over \p view (tests).
std::vector<Stroke> strokes(const VtkView* view);

/// Shows \p mesh keeping the current camera (VtkView::setMesh alone resets it to the initial view).
void showMeshKeepCamera(VtkView* view, const Mesh& mesh);
/// Shows \p reference as a translucent ghost when the view can, else nothing.
void setGhost(VtkView* view, const Mesh* reference);
/// Shows the pending patch in a distinct colour (when the view can; otherwise its border as an overlay
/// projected with the view's current camera, refreshed by refreshPreview after camera changes).
void setPreview(VtkView* view, const Mesh* patch);
/// Re-projects the fallback preview overlay after a camera change (no-op with the view's own preview).
void refreshPreview(VtkView* view);

/// A renderer for the scan pipeline: the view's GPU renderer when the view offers one and it works,
/// else nullptr (the caller then uses CpuMeshRenderer). GUI thread only.
std::unique_ptr<MeshRenderer> createRenderer(VtkView* view);

/// Whether the view has the scan-id colour map; when it does, selects it.
bool setScanIdColorMap(VtkView* view);

/// What the VtkView in this build offers, e.g. "overlay ghost preview renderer scan-id" (for reports).
QString features();

} // namespace fss::widgets::bridge
