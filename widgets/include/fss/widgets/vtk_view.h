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

#include "fss/camera.h"
#include "fss/mesh.h"

#include <QImage>
#include <QOpenGLWidget>
#include <QString>

#include <memory>
#include <optional>
#include <string_view>

namespace fss::widgets {

/// What the faces of the shown mesh are coloured by.
enum class ColorMap {
    None,     ///< one surface colour, shaded (the default)
    MinAngle, ///< each face's smallest corner angle: red 0°, yellow 30°, green ≥ 60° (equilateral)
    /// each face's worst vertex valence: the largest |valence − 6| over its interior corners; green 0
    /// (regular), yellow 1, orange 2, red ≥ 3; faces whose corners are all on the boundary are grey
    Valence,
};

/// Parses "none", "angle" (or "min-angle") and "valence"; std::nullopt for anything else.
std::optional<ColorMap> parseColorMap(std::string_view name);
/// The name accepted by parseColorMap ("none", "angle", "valence").
QString colorMapName(ColorMap map);

/// A QOpenGLWidget showing one triangle mesh with VTK: flat shaded with its edges, optionally coloured
/// per face by a quality measure (ColorMap), navigated with VTK's trackball camera (left drag rotates,
/// middle drag or Shift+left drag pans, right drag or the wheel zooms, 'r' resets the camera).
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

    /// The current camera; width/height are the widget size times the device pixel ratio (at least 1).
    Camera camera() const;
    /// Makes \p camera the view's camera (eye, focal point, up, projection, clipping range). Its
    /// width/height are ignored: the view's size decides the aspect.
    /// \throw fss::InvalidInputError when camera.validate() fails; the view is unchanged then.
    void setCamera(const Camera& camera);
    /// Looks at the shown mesh from \p view (fss::Camera::standardView: the whole mesh is visible, up is
    /// +z except for ±z views). Without a mesh the unit cube is framed.
    void setStandardView(StandardView view);
    /// The standard view used for a newly set mesh; Iso unless changed.
    void setInitialView(StandardView view);

    /// Renders the current frame and returns it (size × device pixel ratio). Returns a null QImage when
    /// the widget has never been shown (no GL context yet).
    QImage grabImage();

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
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace fss::widgets
