#pragma once
// Private to VtkView: what its source files share. vtk_view.cpp: construction, OpenGL, camera and input
// events; vtk_view_scene.cpp: the shown meshes (mesh, ghost, preview), colour maps, legend, axes, overlay.

#include "fss/error.h"
#include "fss/render/colour_maps.h"
#include "fss/render/gpu_mesh_renderer.h"
#include "fss/widgets/vtk_view.h"

// GL constants come from Qt's qopengl.h (through QOpenGLWidget); vtk_glew.h cannot be combined with it
// and is not needed: every GL call goes through VTK (vtkOpenGLState, the render window).
#include <vtkActor.h>
#include <vtkAxesActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCommand.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkGenericRenderWindowInteractor.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOpenGLShaderCache.h>
#include <vtkOpenGLState.h>
#include <vtkOrientationMarkerWidget.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSmartPointer.h>
#include <vtkTextProperty.h>
#include <vtkUnsignedCharArray.h>
#include <vtkVariant.h>

#include <QKeyEvent>
#include <QMouseEvent>
#include <QOpenGLContext>
#include <QPainter>
#include <QPainterPath>
#include <QPointer>
#include <QSurfaceFormat>
#include <QWheelEvent>
#include <QtDebug>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace fss::widgets::detail {

// A vtkCommand calling a std::function: observers that capture the view.
class FunctionCommand : public vtkCommand {
public:
    static FunctionCommand* New() { return new FunctionCommand; }
    std::function<void(unsigned long event, void* callData)> callback;
    void Execute(vtkObject*, unsigned long event, void* callData) override {
        if (callback) callback(event, callData);
    }
};

// VTK's trackball camera without its keyboard shortcuts: 'e'/'q' would call exit(), 'w'/'s' switch the
// representation (and lose the edges), 'f'/'p' fly to and pick (timers and pickers the view does not
// drive), '3' stereo. Only 'r' (reset the camera onto the mesh) is kept.
class NavigationStyle : public vtkInteractorStyleTrackballCamera {
public:
    static NavigationStyle* New();
    vtkTypeMacro(NavigationStyle, vtkInteractorStyleTrackballCamera);
    void OnChar() override {
        const char key = this->Interactor ? this->Interactor->GetKeyCode() : 0;
        if (key == 'r' || key == 'R') vtkInteractorStyleTrackballCamera::OnChar();
    }
};

// What a VtkView shares with the MeshRenderers it created: its GL context while VTK lives in it, and the
// renderers to tell when that context goes away. Owned jointly, so a renderer may outlive the view.
class ViewMeshRenderer;
struct GlLink {
    QOpenGLContext* context = nullptr; // the widget's context while VTK is initialised in it
    QSurface* surface = nullptr;       // the surface the widget makes that context current with
    std::vector<ViewMeshRenderer*> renderers;
};

// render::GlContext on a VtkView's QOpenGLContext. makeCurrent() uses QOpenGLContext::makeCurrent (never
// QOpenGLWidget::makeCurrent, which would rebind the widget's framebuffer) and doneCurrent() makes the
// previously current context current again (another view's, typically), or releases the context.
class ViewGlContext final : public render::GlContext {
public:
    explicit ViewGlContext(std::shared_ptr<GlLink> link) : link_(std::move(link)) {}

    void makeCurrent() override {
        QOpenGLContext* context = link_->context;
        if (!context)
            throw Error("The 3D view has no OpenGL context: scans from the view need the widget shown "
                        "(and not destroyed).");
        QOpenGLContext* current = QOpenGLContext::currentContext();
        if (current == context) return;
        previous_ = current;
        previousSurface_ = current ? current->surface() : nullptr;
        if (!context->makeCurrent(link_->surface))
            throw Error("The 3D view's OpenGL context could not be made current.");
    }
    bool isCurrent() const override {
        return link_->context && QOpenGLContext::currentContext() == link_->context;
    }
    void doneCurrent() override {
        QOpenGLContext* previous = previous_;
        QSurface* previousSurface = previousSurface_;
        previous_ = nullptr;
        previousSurface_ = nullptr;
        if (previous && previousSurface && previous->makeCurrent(previousSurface)) return;
        if (link_->context && QOpenGLContext::currentContext() == link_->context)
            link_->context->doneCurrent();
    }

private:
    std::shared_ptr<GlLink> link_;
    QPointer<QOpenGLContext> previous_;
    QSurface* previousSurface_ = nullptr;
};

// The MeshRenderer of VtkView::createMeshRenderer: a GpuMeshRenderer in the view's context. Its GL
// resources belong to one QOpenGLContext: when the view drops that context (re-parenting, destruction) it
// calls releaseGl() with the context current, and the next render() builds a new GpuMeshRenderer in the
// view's new context from the mesh of setMesh() (which MeshRenderer's contract keeps alive).
class ViewMeshRenderer final : public MeshRenderer {
public:
    explicit ViewMeshRenderer(std::shared_ptr<GlLink> link) : link_(std::move(link)), context_(link_) {
        link_->renderers.push_back(this);
    }
    ~ViewMeshRenderer() override {
        auto& list = link_->renderers;
        list.erase(std::remove(list.begin(), list.end(), this), list.end());
        // GpuMeshRenderer frees its GL resources making the view's context current when it still exists.
        gpu_.reset();
    }
    ViewMeshRenderer(const ViewMeshRenderer&) = delete;
    ViewMeshRenderer& operator=(const ViewMeshRenderer&) = delete;

    void setMesh(const Mesh& mesh) override {
        if (mesh.number_of_faces() == 0) throw InvalidInputError("Cannot render a mesh without faces.");
        if (!gpu_) gpu_ = std::make_unique<render::GpuMeshRenderer>(context_);
        gpu_->setMesh(mesh); // copies and checks the mesh; touches GL only when GL was initialised
        mesh_ = &mesh;
    }

    FrameBuffers render(const Camera& camera) override {
        if (!mesh_) throw InvalidInputError("Cannot render a scan before a mesh was given (setMesh).");
        if (!link_->context)
            throw Error("The 3D view has no OpenGL context: scans from the view need the widget shown "
                        "(and not destroyed).");
        if (!gpu_) {
            auto gpu = std::make_unique<render::GpuMeshRenderer>(context_);
            gpu->setMesh(*mesh_);
            gpu_ = std::move(gpu);
        }
        return gpu_->render(camera);
    }

    // Frees the GL resources in the view's context, which the caller has made current.
    void releaseGl() { gpu_.reset(); }

private:
    std::shared_ptr<GlLink> link_;
    ViewGlContext context_;
    const Mesh* mesh_ = nullptr;
    std::unique_ptr<render::GpuMeshRenderer> gpu_;
};

} // namespace fss::widgets::detail

namespace fss::widgets {

struct VtkView::Impl {
    vtkNew<vtkGenericOpenGLRenderWindow> window;
    vtkNew<vtkRenderer> renderer;
    vtkNew<vtkGenericRenderWindowInteractor> interactor;
    vtkNew<detail::NavigationStyle> style;
    vtkNew<vtkPolyData> polyData;
    vtkNew<vtkPolyDataMapper> mapper;
    vtkNew<vtkActor> actor;
    std::vector<unsigned long> windowObservers;
    unsigned long renderObserver = 0;

    // The translucent reference (ghost) and the pending patch (preview).
    vtkNew<vtkPolyDataMapper> ghostMapper;
    vtkNew<vtkActor> ghostActor;
    bool ghostVisible = true;
    vtkNew<vtkPolyDataMapper> previewMapper;
    vtkNew<vtkActor> previewActor;
    std::vector<OverlayPath> overlay;

    // The widget's GL context (while VTK is initialised in it), shared with createMeshRenderer()'s.
    std::shared_ptr<detail::GlLink> gl = std::make_shared<detail::GlLink>();
    QMetaObject::Connection contextDestroyed;
    bool initialized = false;
    bool inPaint = false;

    // Per-face measures of the shown mesh (kept so that switching the colour map needs no mesh).
    std::vector<double> faceMinAngle;
    std::vector<int> faceValenceDeviation;
    std::vector<std::int32_t> faceScanId; // −1 for input faces
    Eigen::AlignedBox3d bounds;
    ColorMap colorMap = ColorMap::None;
    StandardView initialView = StandardView::Iso;
    UpAxis upAxis = UpAxis::Z;
    vtkMTimeType cameraTime = 0;

    // The colour legend and the axis triad.
    vtkNew<vtkScalarBarActor> legend;
    vtkNew<vtkLookupTable> legendTable;
    bool legendEnabled = true;
    vtkNew<vtkAxesActor> axes;
    vtkNew<vtkOrientationMarkerWidget> axesWidget;

    // The legend of the active colour map: the render layer's colours (colour_maps.h) in a lookup table.
    void updateLegend() {
        const bool show = legendEnabled && colorMap != ColorMap::None && polyData->GetNumberOfCells() > 0;
        legend->SetVisibility(show);
        if (!show) return;
        vtkLookupTable* t = legendTable;
        t->ResetAnnotations();
        auto set = [t](vtkIdType i, const render::Rgb& c) {
            t->SetTableValue(i, c[0] / 255.0, c[1] / 255.0, c[2] / 255.0, 1.0);
        };
        if (colorMap == ColorMap::MinAngle) {
            t->IndexedLookupOff();
            t->SetNumberOfTableValues(61);
            for (int a = 0; a <= 60; ++a)
                set(a, render::minAngleColor(a));
            t->SetTableRange(0, 60);
            legend->SetTitle("Min angle (deg)");
            legend->SetNumberOfLabels(5);
        } else {
            // Categories: one swatch per annotation, in the table's order.
            std::vector<std::pair<int, std::string>> entries;
            if (colorMap == ColorMap::Valence) {
                entries = {{0, "0 (regular)"}, {1, "1"}, {2, "2"}, {3, ">= 3"}, {-1, "boundary"}};
                legend->SetTitle("|valence - 6|");
            } else {
                std::vector<std::int32_t> ids = faceScanId;
                std::sort(ids.begin(), ids.end());
                ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
                for (std::int32_t id : ids) {
                    if (int(entries.size()) == kMaxLegendScans) break;
                    entries.emplace_back(id, id < 0 ? std::string("input") : "scan " + std::to_string(id));
                }
                legend->SetTitle("Made by");
            }
            t->IndexedLookupOn();
            t->SetNumberOfTableValues(vtkIdType(entries.size()));
            for (std::size_t i = 0; i < entries.size(); ++i) {
                const int v = entries[i].first;
                set(vtkIdType(i),
                    colorMap == ColorMap::Valence ? render::valenceColor(v) : render::scanIdColor(v));
                t->SetAnnotation(vtkVariant(v), entries[i].second);
            }
        }
        t->Build();
        legend->SetLookupTable(t);
        legend->Modified();
    }

    void applyColorMap() {
        vtkProperty* property = actor->GetProperty();
        updateLegend();
        if (colorMap == ColorMap::None || polyData->GetNumberOfCells() == 0) {
            polyData->GetCellData()->SetScalars(nullptr);
            mapper->ScalarVisibilityOff();
            property->SetSpecularColor(kSurface[0], kSurface[1], kSurface[2]);
            return;
        }
        // The face colours replace ambient and diffuse colour; a white highlight keeps them true (a tan
        // one would tint the neutral grey of input faces in the scan-id map).
        property->SetSpecularColor(1.0, 1.0, 1.0);
        vtkNew<vtkUnsignedCharArray> colors;
        colors->SetName("face colour");
        colors->SetNumberOfComponents(3);
        const auto n = static_cast<vtkIdType>(faceMinAngle.size());
        colors->SetNumberOfTuples(n);
        for (vtkIdType f = 0; f < n; ++f) {
            const std::size_t i = std::size_t(f);
            // The render layer's colour maps (colour_maps.h), the snapshots' colours.
            render::Rgb c;
            switch (colorMap) {
            case ColorMap::MinAngle:
                c = render::minAngleColor(faceMinAngle[i]);
                break;
            case ColorMap::Valence:
                c = render::valenceColor(faceValenceDeviation[i]);
                break;
            default:
                c = render::scanIdColor(faceScanId[i]);
            }
            for (int k = 0; k < 3; ++k)
                colors->SetTypedComponent(f, k, c[std::size_t(k)]);
        }
        polyData->GetCellData()->SetScalars(colors);
        mapper->ScalarVisibilityOn();
        mapper->SetScalarModeToUseCellData();
        mapper->SetColorModeToDirectScalars();
    }

    // Frees every GL resource held in the widget's context (VTK's and those of the MeshRenderers made
    // by createMeshRenderer) while it still exists; afterwards nothing refers to it.
    void releaseGraphics(VtkView* view) {
        if (!gl->context) return;
        view->makeCurrent();
        // Copy: a renderer's release must not invalidate the iteration.
        const std::vector<detail::ViewMeshRenderer*> renderers = gl->renderers;
        for (detail::ViewMeshRenderer* r : renderers)
            r->releaseGl();
        if (initialized) {
            window->Finalize();
            window->SetReadyForRendering(false);
        }
        view->doneCurrent();
        initialized = false;
        gl->context = nullptr;
        gl->surface = nullptr;
    }
};

} // namespace fss::widgets
