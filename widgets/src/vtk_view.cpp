// VtkView: construction, the OpenGL hand-over to VTK, the camera and the input events (vtk_view_impl.h holds
// what VtkView's files share).
#include "vtk_view_impl.h"

namespace fss::widgets {

namespace detail {
vtkStandardNewMacro(NavigationStyle);
} // namespace detail

namespace {

Eigen::Vector3d toEigen(const double* p) {
    return {p[0], p[1], p[2]};
}

} // namespace

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
        vtkNew<detail::FunctionCommand> command;
        command->callback = [f = std::move(f)](unsigned long, void* callData) { f(callData); };
        d.windowObservers.push_back(d.window->AddObserver(event, command));
    };
    // Trap (PLATFORM-NOTES): QOpenGLContext::makeCurrent, not QOpenGLWidget::makeCurrent — the latter
    // rebinds Qt's framebuffer while VTK sets up its own and the image comes out garbage.
    observe(vtkCommand::WindowMakeCurrentEvent, [this](void*) {
        const detail::GlLink& gl = *impl_->gl;
        if (gl.context && gl.surface && QOpenGLContext::currentContext() != gl.context)
            gl.context->makeCurrent(gl.surface);
    });
    observe(vtkCommand::WindowIsCurrentEvent, [this](void* callData) {
        const detail::GlLink& gl = *impl_->gl;
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
        vtkNew<detail::FunctionCommand> command;
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
    d.previewMapper->SetScalarModeToUseCellData();
    d.previewMapper->SetColorModeToDirectScalars();
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

std::unique_ptr<MeshRenderer> VtkView::createMeshRenderer() {
    return std::make_unique<detail::ViewMeshRenderer>(impl_->gl);
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
