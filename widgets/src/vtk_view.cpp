#include "fss/widgets/vtk_view.h"

#include "fss/error.h"
#include "fss/render/colour_maps.h"
#include "fss/render/gpu_mesh_renderer.h"

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

namespace fss::widgets {
namespace {

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
vtkStandardNewMacro(NavigationStyle);

double cornerAngleDeg(const Point3& at, const Point3& a, const Point3& b) {
    const Vector3 u = a - at, v = b - at;
    const double lu = std::sqrt(u.squared_length()), lv = std::sqrt(v.squared_length());
    if (lu == 0 || lv == 0) return 0;
    return std::acos(std::clamp((u * v) / (lu * lv), -1.0, 1.0)) * 180.0 / M_PI;
}

Eigen::Vector3d toEigen(const double* p) {
    return {p[0], p[1], p[2]};
}

// The live vertices and faces of \p mesh as VTK points and polygons (dense VTK ids, faces in the order of
// mesh.faces(), so VTK cell i is the i-th live face). Extends \p bounds by every point when given.
vtkSmartPointer<vtkPolyData> toPolyData(const Mesh& mesh, Eigen::AlignedBox3d* bounds = nullptr) {
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    points->Allocate(vtkIdType(mesh.number_of_vertices()));
    std::vector<vtkIdType> pointId(mesh.num_vertices(), -1); // num_vertices counts removed ones too
    for (VertexIndex v : mesh.vertices()) {
        const Point3& p = mesh.point(v);
        pointId[std::size_t(v)] = points->InsertNextPoint(p.x(), p.y(), p.z());
        if (bounds) bounds->extend(Eigen::Vector3d(p.x(), p.y(), p.z()));
    }
    vtkNew<vtkCellArray> polys;
    polys->AllocateEstimate(vtkIdType(mesh.number_of_faces()), 3);
    std::vector<vtkIdType> ids;
    for (FaceIndex f : mesh.faces()) {
        ids.clear();
        for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f)))
            ids.push_back(pointId[std::size_t(v)]);
        polys->InsertNextCell(vtkIdType(ids.size()), ids.data());
    }
    auto polyData = vtkSmartPointer<vtkPolyData>::New();
    polyData->SetPoints(points);
    polyData->SetPolys(polys);
    return polyData;
}

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

} // namespace

QColor scanIdColor(int scanId) {
    const render::Rgb c = render::scanIdColor(scanId);
    return QColor(c[0], c[1], c[2]);
}

std::optional<ColorMap> parseColorMap(std::string_view name) {
    if (name == "none") return ColorMap::None;
    if (name == "angle" || name == "min-angle") return ColorMap::MinAngle;
    if (name == "valence") return ColorMap::Valence;
    if (name == "scan-id") return ColorMap::ScanId;
    return std::nullopt;
}

QString colorMapName(ColorMap map) {
    switch (map) {
    case ColorMap::None:
        return QStringLiteral("none");
    case ColorMap::MinAngle:
        return QStringLiteral("angle");
    case ColorMap::Valence:
        return QStringLiteral("valence");
    case ColorMap::ScanId:
        return QStringLiteral("scan-id");
    }
    return {};
}

struct VtkView::Impl {
    vtkNew<vtkGenericOpenGLRenderWindow> window;
    vtkNew<vtkRenderer> renderer;
    vtkNew<vtkGenericRenderWindowInteractor> interactor;
    vtkNew<NavigationStyle> style;
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
    std::shared_ptr<GlLink> gl = std::make_shared<GlLink>();
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
        const std::vector<ViewMeshRenderer*> renderers = gl->renderers;
        for (ViewMeshRenderer* r : renderers)
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

QSurfaceFormat VtkView::surfaceFormat() {
    QSurfaceFormat format;
    format.setRenderableType(QSurfaceFormat::OpenGL);
    format.setVersion(3, 2);
    format.setProfile(QSurfaceFormat::CoreProfile);
    format.setSwapBehavior(QSurfaceFormat::DoubleBuffer);
    format.setRedBufferSize(8);
    format.setGreenBufferSize(8);
    format.setBlueBufferSize(8);
    format.setAlphaBufferSize(8);
    format.setDepthBufferSize(24);
    format.setStencilBufferSize(8);
    format.setSamples(0);
    return format;
}

void VtkView::setDefaultSurfaceFormat() {
    QSurfaceFormat::setDefaultFormat(surfaceFormat());
}

VtkView::VtkView(QWidget* parent) : QOpenGLWidget(parent), impl_(std::make_unique<Impl>()) {
    auto& d = *impl_;
    setFocusPolicy(Qt::StrongFocus);
    setMouseTracking(true);
    setMinimumSize(64, 64);

    // VTK renders in the widget's context (not one of its own), into its own framebuffer; paintGL blits.
    d.window->SetOwnContext(0);
    d.window->SetMultiSamples(0); // VTK's default of 8 breaks rendering into a QOpenGLWidget
    d.window->SetFrameBlitModeToNoBlit();
    d.window->SetReadyForRendering(false);
    d.window->AddRenderer(d.renderer);

    auto observe = [&](unsigned long event, std::function<void(void*)> f) {
        vtkNew<FunctionCommand> command;
        command->callback = [f = std::move(f)](unsigned long, void* callData) { f(callData); };
        d.windowObservers.push_back(d.window->AddObserver(event, command));
    };
    // Trap (PLATFORM-NOTES): QOpenGLContext::makeCurrent, not QOpenGLWidget::makeCurrent — the latter
    // rebinds Qt's framebuffer while VTK sets up its own and the image comes out garbage.
    observe(vtkCommand::WindowMakeCurrentEvent, [this](void*) {
        const GlLink& gl = *impl_->gl;
        if (gl.context && gl.surface && QOpenGLContext::currentContext() != gl.context)
            gl.context->makeCurrent(gl.surface);
    });
    observe(vtkCommand::WindowIsCurrentEvent, [this](void* callData) {
        const GlLink& gl = *impl_->gl;
        *static_cast<bool*>(callData) = gl.context && QOpenGLContext::currentContext() == gl.context;
    });
    // A render started outside paintGL (by code holding the render window) must reach the screen.
    observe(vtkCommand::WindowFrameEvent, [this](void*) {
        if (!impl_->inPaint) update();
    });

    d.interactor->SetRenderWindow(d.window);
    d.interactor->SetInteractorStyle(d.style);
    d.interactor->EnableRenderOff(); // the interactor asks for renders through RenderEvent → update()
    {
        vtkNew<FunctionCommand> command;
        command->callback = [this](unsigned long, void*) {
            update();
            // Navigation changed the camera (the style asks for a render after every step).
            const vtkMTimeType t = impl_->renderer->GetActiveCamera()->GetMTime();
            if (t != impl_->cameraTime) {
                impl_->cameraTime = t;
                emit cameraChanged();
            }
        };
        d.renderObserver = d.interactor->AddObserver(vtkCommand::RenderEvent, command);
    }
    d.interactor->Initialize();

    d.renderer->SetBackground(kBackground[0], kBackground[1], kBackground[2]);
    d.renderer->SetBackgroundAlpha(1.0); // opaque: Qt composes the widget image with its alpha
    d.mapper->SetInputData(d.polyData);
    d.mapper->ScalarVisibilityOff();
    d.actor->SetMapper(d.mapper);
    vtkProperty* property = d.actor->GetProperty();
    property->SetColor(kSurface[0], kSurface[1], kSurface[2]);
    property->SetAmbient(0.15);
    property->SetDiffuse(0.85);
    property->SetSpecular(0.1);
    property->SetInterpolationToFlat();
    property->EdgeVisibilityOn();
    property->SetEdgeColor(0.12, 0.12, 0.14);
    property->SetLineWidth(1.0f);
    d.actor->VisibilityOff();
    d.renderer->AddActor(d.actor);

    // Ghost: translucent, pushed back where it coincides with the mesh so that the mesh wins. VTK applies
    // an actor's polygon offset only when its edges are drawn (or globally, which would also offset the
    // scan renders' depth): the ghost's edges are drawn in its own colour, a faint wireframe.
    d.ghostMapper->ScalarVisibilityOff();
    d.ghostMapper->SetRelativeCoincidentTopologyPolygonOffsetParameters(2, 40);
    d.ghostActor->SetMapper(d.ghostMapper);
    vtkProperty* ghost = d.ghostActor->GetProperty();
    ghost->SetColor(kGhost[0], kGhost[1], kGhost[2]);
    ghost->SetOpacity(kGhostOpacity);
    ghost->SetAmbient(0.3);
    ghost->SetDiffuse(0.7);
    ghost->SetSpecular(0.0);
    ghost->EdgeVisibilityOn();
    ghost->SetEdgeColor(kGhost[0], kGhost[1], kGhost[2]);
    ghost->SetInterpolationToFlat();
    d.ghostActor->VisibilityOff();
    d.ghostActor->PickableOff();
    d.renderer->AddActor(d.ghostActor);

    // Preview: opaque, its own colour with edges; pulled towards the viewer so that it shows where it
    // coincides with the mesh (a scan patch lies on the surface it was sampled from).
    d.previewMapper->ScalarVisibilityOff();
    d.previewMapper->SetRelativeCoincidentTopologyPolygonOffsetParameters(-2, -40);
    d.previewMapper->SetRelativeCoincidentTopologyLineOffsetParameters(-2, -40);
    d.previewActor->SetMapper(d.previewMapper);
    vtkProperty* preview = d.previewActor->GetProperty();
    preview->SetColor(kPreview[0], kPreview[1], kPreview[2]);
    preview->SetAmbient(0.2);
    preview->SetDiffuse(0.8);
    preview->SetSpecular(0.1);
    preview->SetInterpolationToFlat();
    preview->EdgeVisibilityOn();
    preview->SetEdgeColor(0.02, 0.08, 0.25);
    preview->SetLineWidth(1.0f);
    d.previewActor->VisibilityOff();
    d.previewActor->PickableOff();
    d.renderer->AddActor(d.previewActor);

    // Legend: at the right edge, white text with a shadow (readable on the background and on the mesh).
    d.legend->SetOrientationToVertical();
    d.legend->SetPosition(0.86, 0.12);
    d.legend->SetWidth(0.12);
    d.legend->SetHeight(0.76);
    d.legend->SetMaximumWidthInPixels(130);
    d.legend->SetBarRatio(0.3);
    d.legend->SetLabelFormat("%.0f");
    d.legend->DrawAnnotationsOn();
    d.legend->SetTextPositionToSucceedScalarBar();
    d.legend->UnconstrainedFontSizeOn(); // the font sizes below, not scaled to the bar's height
    for (vtkTextProperty* text : {d.legend->GetTitleTextProperty(), d.legend->GetLabelTextProperty(),
                                  d.legend->GetAnnotationTextProperty()}) {
        text->SetColor(1, 1, 1);
        text->ShadowOn();
        text->ItalicOff();
        text->SetFontSize(14);
    }
    d.legend->SetLookupTable(d.legendTable);
    d.legend->VisibilityOff();
    d.legend->PickableOff();
    d.renderer->AddViewProp(d.legend);

    // Axis triad in the lower-left corner (its own renderer layer, following the camera); hidden until
    // setAxesVisible(true).
    d.axes->SetTotalLength(1, 1, 1);
    d.axes->SetShaftTypeToCylinder();
    d.axesWidget->SetOrientationMarker(d.axes);
    d.axesWidget->SetInteractor(d.interactor);
    d.axesWidget->SetCurrentRenderer(d.renderer);
    d.axesWidget->SetViewport(0.0, 0.0, 0.16, 0.16); // enabled by setAxesVisible
    setStandardView(d.initialView);
}

VtkView::~VtkView() {
    // QOpenGLWidget's destructor deletes the context after this one ran: no callback into impl_ then.
    QObject::disconnect(impl_->contextDestroyed);
    impl_->releaseGraphics(this);
    for (unsigned long tag : impl_->windowObservers)
        impl_->window->RemoveObserver(tag);
    impl_->interactor->RemoveObserver(impl_->renderObserver);
}

void VtkView::initializeGL() {
    auto& d = *impl_;
    d.gl->context = context();
    d.gl->surface = context()->surface();
    // QOpenGLWidget recreates its context when it is re-parented into another window: release VTK's
    // resources in the old one (initializeGL then runs again in the new one).
    QObject::disconnect(d.contextDestroyed);
    d.contextDestroyed = connect(context(), &QOpenGLContext::aboutToBeDestroyed, this,
                                 [this] { impl_->releaseGraphics(this); });
    if (!d.window->InitializeFromCurrentContext()) {
        qWarning("VtkView: VTK could not initialise OpenGL in the widget's context.");
        d.gl->context = nullptr;
        d.gl->surface = nullptr;
        return;
    }
    d.window->SetReadyForRendering(true);
    d.initialized = true;
    resizeGL(width(), height());
}

void VtkView::resizeGL(int width, int height) {
    auto& d = *impl_;
    const qreal dpr = devicePixelRatioF();
    const int w = std::max(1, int(std::lround(width * dpr)));
    const int h = std::max(1, int(std::lround(height * dpr)));
    d.window->SetSize(w, h);
    d.interactor->UpdateSize(w, h);
}

void VtkView::paintGL() {
    auto& d = *impl_;
    if (!d.initialized) return;
    vtkOpenGLState* state = d.window->GetState();
    // Qt changes GL state behind VTK's back: resynchronise VTK's cache, and restore Qt's afterwards.
    state->Reset();
    // Other VTK render windows in this context (the scan renderers of createMeshRenderer) bind their own
    // shader programs: forget which one VTK believes is bound so that ours is bound again.
    d.window->GetShaderCache()->ReleaseCurrentShader();
    state->Push();
    state->vtkglDepthFunc(GL_LEQUAL); // Qt leaves GL_LESS, VTK expects GL_LEQUAL
    d.inPaint = true;
    d.window->Render();
    d.inPaint = false;
    // Rendering may have made another context current (observers of other widgets): back to ours.
    makeCurrent();
    const int* size = d.window->GetSize();
    state->PushDrawFramebufferBinding();
    state->vtkglBindFramebuffer(GL_DRAW_FRAMEBUFFER, defaultFramebufferObject());
    state->vtkglDisable(GL_SCISSOR_TEST);
    state->vtkglViewport(0, 0, size[0], size[1]);
    d.window->BlitDisplayFramebuffer(0, 0, 0, size[0], size[1], 0, 0, size[0], size[1], GL_COLOR_BUFFER_BIT,
                                     GL_NEAREST);
    state->PopDrawFramebufferBinding();
    state->Pop();
    paintOverlay();
}

void VtkView::paintOverlay() {
    const auto& paths = impl_->overlay;
    if (paths.empty()) return;
    // QPainter on a QOpenGLWidget paints into its framebuffer in widget pixels (the device pixel ratio is
    // applied by Qt), over the image blitted above.
    QPainter painter(this);
    painter.setRenderHint(QPainter::Antialiasing);
    for (const OverlayPath& path : paths) {
        if (path.points.empty()) continue;
        if (path.width > 0 && path.points.size() > 1) {
            QPen pen(path.color, path.width, Qt::SolidLine, Qt::RoundCap, Qt::RoundJoin);
            painter.setPen(pen);
            painter.setBrush(Qt::NoBrush);
            if (path.closed)
                painter.drawPolygon(path.points.data(), int(path.points.size()));
            else
                painter.drawPolyline(path.points.data(), int(path.points.size()));
        }
        if (path.markers) {
            painter.setPen(Qt::NoPen);
            painter.setBrush(path.color);
            const qreal r = path.width + 1.5;
            for (const QPointF& p : path.points)
                painter.drawEllipse(p, r, r);
        }
    }
}

void VtkView::setMesh(const Mesh& mesh) {
    auto& d = *impl_;
    d.bounds.setEmpty();
    vtkSmartPointer<vtkPolyData> fresh = toPolyData(mesh, &d.bounds);

    // Per-face measures for the colour maps, in the order of mesh.faces() (= VTK cell order).
    d.faceMinAngle.clear();
    d.faceValenceDeviation.clear();
    d.faceScanId.clear();
    d.faceMinAngle.reserve(mesh.number_of_faces());
    d.faceValenceDeviation.reserve(mesh.number_of_faces());
    d.faceScanId.reserve(mesh.number_of_faces());
    std::vector<int> deviation(mesh.num_vertices(), -1); // |valence − 6| of interior vertices, else −1
    for (VertexIndex v : mesh.vertices())
        if (!mesh.is_border(v) && !mesh.is_isolated(v))
            deviation[std::size_t(v)] = std::abs(int(mesh.degree(v)) - 6);
    const auto scanIds = mesh.property_map<FaceIndex, std::int32_t>(props::faceScanId);
    std::vector<Point3> corners;
    for (FaceIndex f : mesh.faces()) {
        corners.clear();
        int worst = -1;
        for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f))) {
            corners.push_back(mesh.point(v));
            worst = std::max(worst, deviation[std::size_t(v)]);
        }
        double minAngle = 180;
        const std::size_t n = corners.size();
        for (std::size_t i = 0; i < n; ++i)
            minAngle = std::min(minAngle,
                                cornerAngleDeg(corners[i], corners[(i + n - 1) % n], corners[(i + 1) % n]));
        d.faceMinAngle.push_back(minAngle);
        d.faceValenceDeviation.push_back(worst);
        d.faceScanId.push_back(scanIds.second ? scanIds.first[f] : -1);
    }
    d.polyData->ShallowCopy(fresh);
    d.applyColorMap();
    d.polyData->Modified();
    d.actor->SetVisibility(d.polyData->GetNumberOfCells() > 0);
    setStandardView(d.initialView);
}

void VtkView::clearMesh() {
    setMesh(Mesh{});
}

bool VtkView::hasMesh() const {
    return impl_->polyData->GetNumberOfCells() > 0;
}

void VtkView::setColorMap(ColorMap map) {
    impl_->colorMap = map;
    impl_->applyColorMap();
    impl_->polyData->Modified();
    update();
}

ColorMap VtkView::colorMap() const {
    return impl_->colorMap;
}

void VtkView::setLegendVisible(bool visible) {
    impl_->legendEnabled = visible;
    impl_->updateLegend();
    update();
}

bool VtkView::legendVisible() const {
    return impl_->legendEnabled;
}

bool VtkView::legendShown() const {
    return impl_->legend->GetVisibility() != 0;
}

void VtkView::setEdgesVisible(bool visible) {
    impl_->actor->GetProperty()->SetEdgeVisibility(visible);
    update();
}

bool VtkView::edgesVisible() const {
    return impl_->actor->GetProperty()->GetEdgeVisibility() != 0;
}

void VtkView::setAxesVisible(bool visible) {
    impl_->axesWidget->SetEnabled(visible);
    if (visible) impl_->axesWidget->InteractiveOff();
    update();
}

bool VtkView::axesVisible() const {
    return impl_->axesWidget->GetEnabled() != 0;
}

void VtkView::setUpAxis(UpAxis axis) {
    impl_->upAxis = axis;
}

VtkView::UpAxis VtkView::upAxis() const {
    return impl_->upAxis;
}

void VtkView::frameMesh() {
    Eigen::AlignedBox3d box = impl_->bounds;
    if (box.isEmpty()) return setStandardView(impl_->initialView);
    double b[6] = {box.min().x(), box.max().x(), box.min().y(), box.max().y(), box.min().z(), box.max().z()};
    impl_->renderer->ResetCamera(b);
    vtkCamera* c = impl_->renderer->GetActiveCamera();
    c->Modified();
    impl_->cameraTime = c->GetMTime();
    update();
    emit cameraChanged();
}

Camera VtkView::camera() const {
    vtkCamera* c = impl_->renderer->GetActiveCamera();
    Camera camera;
    camera.eye = toEigen(c->GetPosition());
    camera.focal = toEigen(c->GetFocalPoint());
    camera.up = toEigen(c->GetViewUp());
    camera.parallel = c->GetParallelProjection() != 0;
    camera.viewAngleDeg = c->GetViewAngle();
    camera.parallelScale = c->GetParallelScale();
    const double* range = c->GetClippingRange();
    camera.nearPlane = range[0];
    camera.farPlane = range[1];
    const qreal dpr = devicePixelRatioF();
    camera.width = std::clamp(int(std::lround(width() * dpr)), 1, Camera::kMaxResolution);
    camera.height = std::clamp(int(std::lround(height() * dpr)), 1, Camera::kMaxResolution);
    return camera;
}

void VtkView::setCamera(const Camera& camera) {
    Camera checked = camera;
    checked.width = checked.height = 1; // the view's own size decides; validate the rest
    checked.validate();
    vtkCamera* c = impl_->renderer->GetActiveCamera();
    c->SetPosition(camera.eye.data());
    c->SetFocalPoint(camera.focal.data());
    c->SetViewUp(camera.up.data());
    c->OrthogonalizeViewUp();
    c->SetParallelProjection(camera.parallel);
    c->SetViewAngle(camera.viewAngleDeg);
    c->SetParallelScale(camera.parallelScale);
    c->SetClippingRange(camera.nearPlane, camera.farPlane);
    c->Modified();
    impl_->cameraTime = c->GetMTime();
    update();
    emit cameraChanged();
}

void VtkView::setStandardView(StandardView view) {
    Eigen::AlignedBox3d box = impl_->bounds;
    if (box.isEmpty())
        box = Eigen::AlignedBox3d(Eigen::Vector3d(-0.5, -0.5, -0.5), Eigen::Vector3d(0.5, 0.5, 0.5));
    const Camera current = camera();
    vtkCamera* c = impl_->renderer->GetActiveCamera();
    Camera standard = Camera::standardView(view, box, current.width, current.height,
                                           c->GetParallelProjection() != 0, c->GetViewAngle());
    if (impl_->upAxis == UpAxis::Y && view != StandardView::PosY && view != StandardView::NegY)
        standard.up = Eigen::Vector3d::UnitY(); // the views along x, z and iso are never parallel to y
    setCamera(standard);
}

void VtkView::setInitialView(StandardView view) {
    impl_->initialView = view;
}

QImage VtkView::grabImage() {
    return grabFramebuffer();
}

QPointF VtkView::toImagePixels(QPointF widgetPoint) const {
    return widgetPoint * devicePixelRatioF();
}

void VtkView::setOverlay(std::vector<OverlayPath> paths) {
    impl_->overlay = std::move(paths);
    update();
}

void VtkView::clearOverlay() {
    setOverlay({});
}

const std::vector<OverlayPath>& VtkView::overlay() const {
    return impl_->overlay;
}

void VtkView::setGhostMesh(const Mesh& reference) {
    auto& d = *impl_;
    if (reference.number_of_faces() == 0) {
        clearGhostMesh();
        return;
    }
    d.ghostMapper->SetInputData(toPolyData(reference));
    d.ghostActor->SetVisibility(d.ghostVisible);
    update();
}

void VtkView::clearGhostMesh() {
    auto& d = *impl_;
    d.ghostMapper->SetInputData(nullptr);
    d.ghostActor->VisibilityOff();
    update();
}

void VtkView::setGhostVisible(bool visible) {
    auto& d = *impl_;
    d.ghostVisible = visible;
    d.ghostActor->SetVisibility(visible && d.ghostMapper->GetInput() != nullptr);
    update();
}

bool VtkView::ghostVisible() const {
    return impl_->ghostActor->GetVisibility() != 0;
}

void VtkView::setPreviewMesh(const Mesh& patch) {
    auto& d = *impl_;
    if (patch.number_of_faces() == 0) {
        clearPreviewMesh();
        return;
    }
    d.previewMapper->SetInputData(toPolyData(patch));
    d.previewActor->VisibilityOn();
    update();
}

void VtkView::clearPreviewMesh() {
    auto& d = *impl_;
    d.previewMapper->SetInputData(nullptr);
    d.previewActor->VisibilityOff();
    update();
}

bool VtkView::hasPreviewMesh() const {
    return impl_->previewActor->GetVisibility() != 0;
}

std::unique_ptr<MeshRenderer> VtkView::createMeshRenderer() {
    return std::make_unique<ViewMeshRenderer>(impl_->gl);
}

// ---- events: forwarded to VTK's interactor in device pixels, y flipped (VTK's origin is bottom-left) ----

namespace {
struct EventInfo {
    int x, y, ctrl, shift, alt;
};
EventInfo eventInfo(const QPointF& pos, Qt::KeyboardModifiers modifiers, qreal dpr) {
    return {int(std::lround(pos.x() * dpr)), int(std::lround(pos.y() * dpr)),
            modifiers.testFlag(Qt::ControlModifier) ? 1 : 0, modifiers.testFlag(Qt::ShiftModifier) ? 1 : 0,
            modifiers.testFlag(Qt::AltModifier) ? 1 : 0};
}
unsigned long buttonEvent(Qt::MouseButton button, bool press) {
    switch (button) {
    case Qt::LeftButton:
        return press ? vtkCommand::LeftButtonPressEvent : vtkCommand::LeftButtonReleaseEvent;
    case Qt::MiddleButton:
        return press ? vtkCommand::MiddleButtonPressEvent : vtkCommand::MiddleButtonReleaseEvent;
    case Qt::RightButton:
        return press ? vtkCommand::RightButtonPressEvent : vtkCommand::RightButtonReleaseEvent;
    default:
        return vtkCommand::NoEvent;
    }
}
} // namespace

void VtkView::mousePressEvent(QMouseEvent* event) {
    const EventInfo e = eventInfo(event->position(), event->modifiers(), devicePixelRatioF());
    auto& iren = *impl_->interactor;
    iren.SetEventInformationFlipY(e.x, e.y, e.ctrl, e.shift, 0, event->type() == QEvent::MouseButtonDblClick);
    iren.SetAltKey(e.alt);
    const unsigned long id = buttonEvent(event->button(), true);
    if (id != vtkCommand::NoEvent) iren.InvokeEvent(id, event);
    event->accept();
}

void VtkView::mouseDoubleClickEvent(QMouseEvent* event) {
    mousePressEvent(event);
}

void VtkView::mouseReleaseEvent(QMouseEvent* event) {
    const EventInfo e = eventInfo(event->position(), event->modifiers(), devicePixelRatioF());
    auto& iren = *impl_->interactor;
    iren.SetEventInformationFlipY(e.x, e.y, e.ctrl, e.shift, 0, 0);
    iren.SetAltKey(e.alt);
    const unsigned long id = buttonEvent(event->button(), false);
    if (id != vtkCommand::NoEvent) iren.InvokeEvent(id, event);
    event->accept();
}

void VtkView::mouseMoveEvent(QMouseEvent* event) {
    const EventInfo e = eventInfo(event->position(), event->modifiers(), devicePixelRatioF());
    auto& iren = *impl_->interactor;
    iren.SetEventInformationFlipY(e.x, e.y, e.ctrl, e.shift, 0, 0);
    iren.SetAltKey(e.alt);
    iren.InvokeEvent(vtkCommand::MouseMoveEvent, event);
    event->accept();
}

void VtkView::wheelEvent(QWheelEvent* event) {
    const EventInfo e = eventInfo(event->position(), event->modifiers(), devicePixelRatioF());
    auto& iren = *impl_->interactor;
    iren.SetEventInformationFlipY(e.x, e.y, e.ctrl, e.shift, 0, 0);
    iren.SetAltKey(e.alt);
    const QPoint delta = event->angleDelta();
    const int steps = delta.y() != 0 ? delta.y() : delta.x();
    if (steps > 0)
        iren.InvokeEvent(vtkCommand::MouseWheelForwardEvent, event);
    else if (steps < 0)
        iren.InvokeEvent(vtkCommand::MouseWheelBackwardEvent, event);
    event->accept();
}

namespace {
void forwardKey(vtkRenderWindowInteractor& iren, QKeyEvent* event, bool press) {
    const QString text = event->text();
    const char ascii = text.size() == 1 && text.at(0).unicode() < 128 ? char(text.at(0).unicode()) : 0;
    std::string keysym = ascii ? std::string(1, ascii) : std::string();
    if (event->key() == Qt::Key_Escape) keysym = "Escape";
    const Qt::KeyboardModifiers m = event->modifiers();
    iren.SetKeyEventInformation(m.testFlag(Qt::ControlModifier), m.testFlag(Qt::ShiftModifier), ascii,
                                event->count(), keysym.empty() ? nullptr : keysym.c_str());
    iren.SetAltKey(m.testFlag(Qt::AltModifier));
    iren.InvokeEvent(press ? vtkCommand::KeyPressEvent : vtkCommand::KeyReleaseEvent, event);
    if (press && ascii) iren.InvokeEvent(vtkCommand::CharEvent, event);
}
} // namespace

void VtkView::keyPressEvent(QKeyEvent* event) {
    forwardKey(*impl_->interactor, event, true);
    event->accept();
}

void VtkView::keyReleaseEvent(QKeyEvent* event) {
    forwardKey(*impl_->interactor, event, false);
    event->accept();
}

void VtkView::enterEvent(QEnterEvent* event) {
    impl_->interactor->InvokeEvent(vtkCommand::EnterEvent, event);
    QOpenGLWidget::enterEvent(event);
}

void VtkView::leaveEvent(QEvent* event) {
    impl_->interactor->InvokeEvent(vtkCommand::LeaveEvent, event);
    QOpenGLWidget::leaveEvent(event);
}

} // namespace fss::widgets

#include "fss/widgets/moc_vtk_view.cpp" // meta-object code compiled here: widgets/CMakeLists.txt says why
