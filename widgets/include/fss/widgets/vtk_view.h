#pragma once
/// \file vtk_view.h
/// VtkView: the 3D view of FSS — VTK rendering inside a Qt6 QOpenGLWidget.
///
/// Debian's VTK 9.1 ships its Qt module for Qt5 only, so FSS hosts VTK itself, the way VTK's own
/// QVTKOpenGLNativeWidget does: the widget owns a vtkGenericOpenGLRenderWindow that renders in the
/// widget's QOpenGLContext into VTK's own framebuffer, which paintGL() blits into the widget's
/// framebuffer. VTK types stay out of this header (pimpl).
///
/// Coordinates: mouse positions are in Qt's device-independent pixels; the view multiplies them by the
/// device pixel ratio before handing them to VTK, and camera() reports the image size in device pixels,
/// so a camera taken from the view matches the pixels of grabImage() on HiDPI screens as well.
/// toImagePixels() does that conversion for tools (lasso, picking); overlays are given in widget pixels
/// and scaled when painted.

#include "fss/camera.h"
#include "fss/mesh.h"
#include "fss/scan_pipeline.h"

#include <QColor>
#include <QImage>
#include <QOpenGLWidget>
#include <QPointF>
#include <QString>

#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

namespace fss::widgets {

/// What the faces of the shown mesh are coloured by.
enum class ColorMap {
    None,     ///< one surface colour, shaded (the default)
    MinAngle, ///< each face's smallest corner angle: red 0°, yellow 30°, green ≥ 60° (equilateral)
    /// each face's worst vertex valence: the largest |valence − 6| over its interior corners; green 0
    /// (regular), yellow 1, orange 2, red ≥ 3; faces whose corners are all on the boundary are grey
    Valence,
    /// the scan that made each face (props::faceScanId): faces of the input mesh (id −1, or no such
    /// property) neutral grey (scanIdColor(-1)), every scan id its own saturated colour (scanIdColor)
    ScanId,
};

/// Parses "none", "angle" (or "min-angle"), "valence" and "scan-id"; std::nullopt for anything else.
std::optional<ColorMap> parseColorMap(std::string_view name);
/// The name accepted by parseColorMap ("none", "angle", "valence", "scan-id").
QString colorMapName(ColorMap map);

/// Colour of the faces of scan \p scanId in ColorMap::ScanId (before shading): neutral grey
/// (0.6, 0.6, 0.6) for ids < 0 (input faces); otherwise a saturated colour whose hue steps by the golden
/// ratio per id, so that consecutive ids differ clearly. Stable: depends on the id only.
QColor scanIdColor(int scanId);

/// A 2D path painted over the 3D image (VtkView::setOverlay): a lasso, a fishbone curve, grid preview
/// points. Coordinates are device-independent widget pixels (those of QMouseEvent::position()), origin
/// at the widget's top-left corner, y down.
struct OverlayPath {
    std::vector<QPointF> points; ///< the path's corners, in widget pixels
    QColor color;                ///< pen (and marker) colour; its alpha is honoured
    bool closed = false;         ///< join the last point to the first (a polygon, not filled)
    bool markers = false;        ///< draw a dot of diameter 2·width + 3 at every point; with a single
                                 ///< point or width 0 lines, only the dots show
    qreal width = 2;             ///< pen width in widget pixels; 0 draws no line (markers only)
};

/// A QOpenGLWidget showing one triangle mesh with VTK: flat shaded with its edges, optionally coloured
/// per face by a quality measure or the scan id (ColorMap), navigated with VTK's trackball camera (left
/// drag rotates, middle drag or Shift+left drag pans, right drag or the wheel zooms, 'r' resets the
/// camera). Optionally also a translucent ghost of the reference mesh, a preview patch and 2D overlays;
/// createMeshRenderer() renders scan buffers in the widget's GL context.
///
/// Every view has its own render window, renderer and camera: several views per process are fine.
/// Before the QApplication is created the application must call setDefaultSurfaceFormat() once (VTK
/// needs an OpenGL 3.2 core context without multisampling).
class VtkView : public QOpenGLWidget {
    Q_OBJECT
public:
    explicit VtkView(QWidget* parent = nullptr);
    ~VtkView() override;
    VtkView(const VtkView&) = delete;
    VtkView& operator=(const VtkView&) = delete;

    /// The surface format VtkView needs: OpenGL 3.2 core profile, RGBA8, depth 24, stencil 8, no
    /// multisampling.
    static QSurfaceFormat surfaceFormat();
    /// Makes surfaceFormat() the default of QSurfaceFormat. Call it before constructing the QApplication.
    static void setDefaultSurfaceFormat();

    /// Shows \p mesh (copied into VTK's representation; the view keeps no reference to it) and points
    /// the camera at it from the iso view. An empty mesh clears the view.
    /// \pre every face of \p mesh is a triangle (as fss::readMesh guarantees)
    void setMesh(const Mesh& mesh);
    /// Removes the mesh from the view.
    void clearMesh();
    /// Whether a non-empty mesh is shown.
    bool hasMesh() const;

    /// Colours the faces by \p map (recomputed from the mesh shown; kept for later setMesh calls).
    void setColorMap(ColorMap map);
    ColorMap colorMap() const;

    /// Shows a colour legend (a vtkScalarBarActor at the right edge of the view) for every colour map but
    /// ColorMap::None: the minimum angle 0°–60°, the valence deviation 0, 1, 2, ≥ 3 and boundary, or the
    /// scan ids of the shown mesh (input and each scan, at most kMaxLegendScans entries). Shown by default.
    void setLegendVisible(bool visible);
    /// Whether the legend is enabled (it is drawn only while a colour map other than None is active).
    bool legendVisible() const;
    /// Whether a legend is drawn now (enabled, a colour map, a mesh).
    bool legendShown() const;
    /// Entries of the scan-id legend at most (the lowest ids; the input first).
    static constexpr int kMaxLegendScans = 12;
    /// Draws the triangle edges of the mesh (default on). Dense meshes look black with edges: turn off.
    void setEdgesVisible(bool visible);
    bool edgesVisible() const;
    /// Shows an axis triad (vtkOrientationMarkerWidget with a vtkAxesActor) in the lower-left corner,
    /// turning with the camera. Hidden by default (RemeshWidget shows it).
    void setAxesVisible(bool visible);
    bool axesVisible() const;
    /// Which world axis points up in the standard views (setStandardView): Z (the default, as in
    /// fss::Camera::standardView) or Y (as in many mesh files from graphics tools).
    enum class UpAxis { Z, Y };
    void setUpAxis(UpAxis axis);
    UpAxis upAxis() const;
    /// Frames the shown mesh (the whole mesh visible) keeping the viewing direction — the 'r' key.
    void frameMesh();

    /// The current camera; width/height are the widget size times the device pixel ratio (at least 1).
    Camera camera() const;
    /// Makes \p camera the view's camera (eye, focal point, up, projection, clipping range). Its
    /// width/height are ignored: the view's size decides the aspect.
    /// \throw fss::InvalidInputError when camera.validate() fails; the view is unchanged then.
    void setCamera(const Camera& camera);
    /// Looks at the shown mesh from \p view (fss::Camera::standardView: the whole mesh is visible, up is
    /// +z except for ±z views; with UpAxis::Y the up vector is +y except for ±y views, which keep
    /// standardView's). Without a mesh the unit cube is framed.
    void setStandardView(StandardView view);
    /// The standard view used for a newly set mesh; Iso unless changed.
    void setInitialView(StandardView view);

    /// Renders the current frame and returns it (size × device pixel ratio), overlays included. Returns a
    /// null QImage when the widget has never been shown (no GL context yet).
    QImage grabImage();

    /// Widget position (device-independent pixels, as in mouse events and OverlayPath) → position in
    /// the image of camera() and grabImage() (device pixels, origin top-left, y down): \p widgetPoint times
    /// the device pixel ratio. Feed the result to Camera::ray / FrameBuffers lookups / Lasso.
    QPointF toImagePixels(QPointF widgetPoint) const;

    // ---- overlays and extra meshes ----

    /// Replaces the overlay: \p paths are painted with QPainter over the 3D image (after VTK's frame), in
    /// the order given, antialiased. An empty list shows no overlay. Repaints the widget.
    void setOverlay(std::vector<OverlayPath> paths);
    /// Removes every overlay path (setOverlay({})).
    void clearOverlay();
    /// The overlay paths currently shown.
    const std::vector<OverlayPath>& overlay() const;

    /// Shows \p reference (copied) as a translucent ghost (kGhost, opacity kGhostOpacity, its edges a
    /// faint wireframe in the same colour) in the same world coordinates as the mesh. Where it coincides with
    /// the shown mesh the mesh wins (polygon offset pushes the ghost back), so the ghost shows where the
    /// current mesh departs from it or has no surface. Visible unless setGhostVisible(false). An empty mesh
    /// clears the ghost. The camera is not moved. \pre every face is a triangle.
    void setGhostMesh(const Mesh& reference);
    /// Removes the ghost mesh.
    void clearGhostMesh();
    /// Shows or hides the ghost mesh (kept while hidden). Visible by default.
    void setGhostVisible(bool visible);
    /// Whether a ghost mesh is set and visible.
    bool ghostVisible() const;

    /// Shows \p patch (copied), e.g. a scan waiting to be accepted, in kPreview with dark edges, drawn over
    /// the mesh: polygon offset pulls it towards the viewer so it stays visible where it coincides with the
    /// mesh. An empty mesh clears the preview. The camera is not moved. \pre every face is a triangle.
    void setPreviewMesh(const Mesh& patch);
    /// As setPreviewMesh(patch), shading each face by what a stitch does with it: \p stitched has one entry
    /// per face index of \p patch (stitchPatch's stitchedPatchFaces), non-zero: kPreview (the face will
    /// replace the mesh), zero: kPreviewTrimmed (trimmed: the mesh stays as it is there). An empty
    /// \p stitched shows the whole patch in kPreview. \pre stitched is empty or has patch.num_faces()
    /// entries.
    void setPreviewMesh(const Mesh& patch, const std::vector<std::uint8_t>& stitched);
    /// Removes the preview mesh.
    void clearPreviewMesh();
    /// Whether a preview mesh is shown.
    bool hasPreviewMesh() const;

    // ---- scan buffers from the view ----

    /// A MeshRenderer (FSS::render's GpuMeshRenderer) that renders in this widget's QOpenGLContext into
    /// its own off-screen framebuffer at the requested camera's width × height, so scans taken with
    /// camera() use the view's exact projection. The visible image is not disturbed, and nothing is
    /// repainted. GUI thread only.
    ///
    /// setMesh() may be called before the widget was ever shown: the mesh is uploaded by the first
    /// render(). The renderer keeps a reference to that mesh (MeshRenderer's contract: it must stay alive
    /// and unchanged until the next setMesh()) so that it can upload it again when the widget's context
    /// is replaced (re-parenting); GL resources are released when the context goes away or the widget is
    /// destroyed, whichever comes first. The renderer may outlive the widget (render() then throws).
    /// \throw (from render()) fss::Error when the widget has no GL context (never shown, or destroyed) or
    ///         the GL / VTK fail; InvalidInputError as MeshRenderer::render.
    std::unique_ptr<MeshRenderer> createMeshRenderer();

    /// RGB colour of the ghost mesh (components in [0, 1]).
    static constexpr double kGhost[3] = {0.55, 0.75, 1.00};
    /// Opacity of the ghost mesh.
    static constexpr double kGhostOpacity = 0.35;
    /// RGB colour of the preview mesh (components in [0, 1]): a saturated blue, unlike every colour map.
    static constexpr double kPreview[3] = {0.15, 0.45, 0.95};
    /// RGB colour of the preview's faces a stitch trims (setPreviewMesh with `stitched`): a brick red.
    static constexpr double kPreviewTrimmed[3] = {0.85, 0.22, 0.15};

    /// RGB background colour of the view (components in [0, 1]).
    static constexpr double kBackground[3] = {0.32, 0.34, 0.43};
    /// RGB colour of the surface when ColorMap::None is active (components in [0, 1]).
    static constexpr double kSurface[3] = {0.90, 0.76, 0.52};

signals:
    /// The camera moved (navigation, setCamera, setStandardView, setMesh).
    void cameraChanged();

protected:
    void initializeGL() override;
    void resizeGL(int width, int height) override;
    void paintGL() override;
    void mousePressEvent(QMouseEvent* event) override;
    void mouseReleaseEvent(QMouseEvent* event) override;
    void mouseMoveEvent(QMouseEvent* event) override;
    void mouseDoubleClickEvent(QMouseEvent* event) override;
    void wheelEvent(QWheelEvent* event) override;
    void keyPressEvent(QKeyEvent* event) override;
    void keyReleaseEvent(QKeyEvent* event) override;
    void enterEvent(QEnterEvent* event) override;
    void leaveEvent(QEvent* event) override;

private:
    void paintOverlay();

    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace fss::widgets
