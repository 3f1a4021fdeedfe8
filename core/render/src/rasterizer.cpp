#include "fss/render/rasterizer.h"

#include "fss/error.h"

// vtk_glew.h first: GLEW must precede any other GL header. VTK initialises GLEW in its own OpenGLInit, so
// the GL entry points below are those VTK uses.
#include <vtk_glew.h>

#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCommand.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkIdTypeArray.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOpenGLActor.h>
#include <vtkOpenGLCamera.h>
#include <vtkOpenGLFramebufferObject.h>
#include <vtkOpenGLPolyDataMapper.h>
#include <vtkOpenGLRenderer.h>
#include <vtkOutputWindow.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkProperty.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace fss::render {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

// ---- VTK messages ------------------------------------------------------------------------------------
// VTK reports problems through its output window (and ErrorEvent observers), never by return values.
// While the Rasterizer works, messages are collected here: errors become one fss::Error, warnings go on to
// the application's own output window, and the known-harmless GLEW message is dropped.

// Debian's GLEW is built for GLX: in an EGL (or any non-GLX) context glewInit loads every GL entry point
// and then fails to find a GLX display (GLEW_ERROR_NO_GLX_DISPLAY, which glewGetErrorString calls
// "Unknown error"), so VTK logs this while rendering correctly. Any other GLEW failure ("Missing GL
// version": no context) is real.
bool isHarmless(const std::string& text) {
    return text.find("GLEW could not be initialized: Unknown error") != std::string::npos;
}

// "ERROR: In /path/file.cxx, line 123\nvtkClass (0x...): message\n\n" → "vtkClass: message".
std::string condense(std::string text) {
    if (text.rfind("ERROR: In ", 0) == 0 || text.rfind("Warning: In ", 0) == 0) {
        const auto nl = text.find('\n');
        if (nl != std::string::npos) text.erase(0, nl + 1);
    }
    const auto open = text.find(" (0x");
    if (open != std::string::npos) {
        const auto close = text.find("): ", open);
        if (close != std::string::npos) text.erase(open, close + 1 - open);
    }
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ' || text.back() == '.'))
        text.pop_back();
    for (char& c : text)
        if (c == '\n') c = ' ';
    return text;
}

struct MessageLog {
    std::vector<std::string> errors;

    void error(const char* text) {
        const std::string s = text ? text : "";
        if (!isHarmless(s)) errors.push_back(condense(s));
    }
    // Throws the first collected error as one sentence and clears the log.
    void throwIfAny(const std::string& during) {
        if (errors.empty()) return;
        std::string first = errors.front();
        errors.clear();
        throw Error("VTK reported an error " + during + ": " + first + ".");
    }
};

class CapturingOutputWindow : public vtkOutputWindow {
public:
    static CapturingOutputWindow* New();
    vtkTypeMacro(CapturingOutputWindow, vtkOutputWindow);

    MessageLog* log = nullptr;
    vtkOutputWindow* forward = nullptr;

    void DisplayErrorText(const char* text) override {
        if (log) log->error(text);
    }
    void DisplayWarningText(const char* text) override {
        if (forward && !isHarmless(text ? text : "")) forward->DisplayWarningText(text);
    }
    void DisplayGenericWarningText(const char* text) override {
        if (forward && !isHarmless(text ? text : "")) forward->DisplayGenericWarningText(text);
    }
    void DisplayText(const char* text) override {
        if (forward && !isHarmless(text ? text : "")) forward->DisplayText(text);
    }
    void DisplayDebugText(const char* text) override {
        if (forward) forward->DisplayDebugText(text);
    }

protected:
    CapturingOutputWindow() = default;
    ~CapturingOutputWindow() override = default;
};
vtkStandardNewMacro(CapturingOutputWindow);

// Routes VTK's process-wide output window into a MessageLog for the lifetime of the object (the
// application's own output window is put back afterwards).
class ScopedVtkMessages {
public:
    explicit ScopedVtkMessages(MessageLog& log) : previous_(vtkOutputWindow::GetInstance()) {
        capture_->log = &log;
        capture_->forward = previous_;
        vtkOutputWindow::SetInstance(capture_);
    }
    ~ScopedVtkMessages() { vtkOutputWindow::SetInstance(previous_); }
    ScopedVtkMessages(const ScopedVtkMessages&) = delete;
    ScopedVtkMessages& operator=(const ScopedVtkMessages&) = delete;

private:
    vtkSmartPointer<vtkOutputWindow> previous_;
    vtkNew<CapturingOutputWindow> capture_;
};

// ---- VTK objects -------------------------------------------------------------------------------------

// The OpenGL poly-data mapper, counting how often it sends the mesh to the GL (uploadCount()).
class CountingMapper : public vtkOpenGLPolyDataMapper {
public:
    static CountingMapper* New();
    vtkTypeMacro(CountingMapper, vtkOpenGLPolyDataMapper);
    std::uint64_t* uploads = nullptr;

protected:
    CountingMapper() = default;
    ~CountingMapper() override = default;
    void BuildBufferObjects(vtkRenderer* renderer, vtkActor* actor) override {
        if (uploads) ++*uploads;
        Superclass::BuildBufferObjects(renderer, actor);
    }
};
vtkStandardNewMacro(CountingMapper);

// One ID pass: its own renderer (only the pass being drawn has Draw on: toggling an actor's visibility
// would touch its modification time and make the mapper rebuild its buffers), actor and mapper. All passes
// share the points and triangles of their poly data; each has its own cell colours.
struct IdPass {
    vtkNew<vtkOpenGLRenderer> renderer;
    vtkNew<vtkOpenGLActor> actor;
    vtkNew<CountingMapper> mapper;
};

// Makes a GlContext current for a scope, releasing it at the end only if it was not current before.
class ScopedCurrent {
public:
    explicit ScopedCurrent(GlContext& context) : context_(context), wasCurrent_(context.isCurrent()) {
        if (!wasCurrent_) context_.makeCurrent();
    }
    ~ScopedCurrent() {
        if (!wasCurrent_) context_.doneCurrent();
    }
    ScopedCurrent(const ScopedCurrent&) = delete;
    ScopedCurrent& operator=(const ScopedCurrent&) = delete;

private:
    GlContext& context_;
    bool wasCurrent_;
};

// Saves the caller's GL state that the scan could change (framebuffer bindings, viewport, scissor box,
// pixel-pack set-up) and restores it at the end of the scope. Queries use GL 1.x entry points only, so it
// may be created before VTK has initialised GLEW.
class ScopedGlState {
public:
    ScopedGlState() {
        glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &drawFramebuffer_);
        glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &readFramebuffer_);
        glGetIntegerv(GL_VIEWPORT, viewport_.data());
        glGetIntegerv(GL_SCISSOR_BOX, scissor_.data());
        glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &packBuffer_);
        glGetIntegerv(GL_PACK_ALIGNMENT, &packAlignment_);
        glGetIntegerv(GL_PACK_ROW_LENGTH, &packRowLength_);
        glGetIntegerv(GL_PACK_SKIP_ROWS, &packSkipRows_);
        glGetIntegerv(GL_PACK_SKIP_PIXELS, &packSkipPixels_);
    }
    ~ScopedGlState() {
        if (!glBindFramebuffer || !glBindBuffer) return; // VTK never initialised GLEW: nothing was changed
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, GLuint(drawFramebuffer_));
        glBindFramebuffer(GL_READ_FRAMEBUFFER, GLuint(readFramebuffer_));
        glViewport(viewport_[0], viewport_[1], viewport_[2], viewport_[3]);
        glScissor(scissor_[0], scissor_[1], scissor_[2], scissor_[3]);
        glBindBuffer(GL_PIXEL_PACK_BUFFER, GLuint(packBuffer_));
        glPixelStorei(GL_PACK_ALIGNMENT, packAlignment_);
        glPixelStorei(GL_PACK_ROW_LENGTH, packRowLength_);
        glPixelStorei(GL_PACK_SKIP_ROWS, packSkipRows_);
        glPixelStorei(GL_PACK_SKIP_PIXELS, packSkipPixels_);
    }
    ScopedGlState(const ScopedGlState&) = delete;
    ScopedGlState& operator=(const ScopedGlState&) = delete;

private:
    GLint drawFramebuffer_ = 0, readFramebuffer_ = 0, packBuffer_ = 0;
    GLint packAlignment_ = 4, packRowLength_ = 0, packSkipRows_ = 0, packSkipPixels_ = 0;
    std::array<GLint, 4> viewport_{}, scissor_{};
};

std::string glErrorName(GLenum code) {
    switch (code) {
    case GL_INVALID_ENUM:
        return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE:
        return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION:
        return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION:
        return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY:
        return "GL_OUT_OF_MEMORY";
    default:
        return "GL error " + std::to_string(code);
    }
}

// The 24-bit value of an RGBA8 pixel read as one 32-bit word (R = lowest 8 bits of the value).
inline std::uint32_t rgbValue(std::uint32_t pixel) {
    if constexpr (std::endian::native == std::endian::little) {
        return pixel & 0x00FFFFFFu;
    } else {
        return ((pixel >> 24) & 0xFFu) | ((pixel >> 8) & 0xFF00u) | ((pixel << 8) & 0xFF0000u);
    }
}

// Sets a VTK camera exactly to an fss::Camera (same matrices, see camera.h).
void applyCamera(vtkCamera* vc, const Camera& c) {
    vc->SetPosition(c.eye.x(), c.eye.y(), c.eye.z());
    vc->SetFocalPoint(c.focal.x(), c.focal.y(), c.focal.z());
    vc->SetViewUp(c.up.x(), c.up.y(), c.up.z());
    vc->SetParallelProjection(c.parallel ? 1 : 0);
    vc->SetViewAngle(c.viewAngleDeg);
    vc->SetParallelScale(c.parallelScale);
    vc->SetUseHorizontalViewAngle(0);
    vc->SetWindowCenter(0.0, 0.0);
    vc->SetClippingRange(c.nearPlane, c.farPlane);
    // VTK caches its matrices by modification time: make sure they are recomputed from the values above.
    vc->Modified();
}

} // namespace

// ---- Rasterizer ----------------------------------------------------------------------------------------

struct Rasterizer::Impl {
    // Declared first so it is destroyed last, after every VTK object that may hold GL resources in it.
    std::unique_ptr<HeadlessGlContext> ownContext;
    GlContext* context = nullptr;

    MessageLog messages;
    vtkNew<vtkCallbackCommand> windowCallback;
    vtkNew<vtkCallbackCommand> errorCallback;
    vtkSmartPointer<vtkGenericOpenGLRenderWindow> window;
    vtkNew<vtkOpenGLCamera> vtkCam;
    std::vector<std::unique_ptr<IdPass>> passes;
    bool glInitialised = false;
    std::string renderer;

    // Mesh data (shared by all passes).
    vtkSmartPointer<vtkPoints> points;
    vtkSmartPointer<vtkCellArray> triangles;
    std::vector<std::uint32_t> cellToFace; // VTK cell id → Face_index
    Eigen::AlignedBox3d box;

    int bitsPerPass = 24;
    std::uint64_t uploads = 0;
    RenderStats stats;
    std::vector<std::uint32_t> scratch; // colours of passes after the first
    std::exception_ptr callbackError;   // exception thrown by the GlContext inside a VTK callback

    explicit Impl(GlContext* ctx) : context(ctx) {
        windowCallback->SetClientData(this);
        windowCallback->SetCallback(&Impl::onWindowEvent);
        errorCallback->SetClientData(this);
        errorCallback->SetCallback(&Impl::onError);

        window = vtkSmartPointer<vtkGenericOpenGLRenderWindow>::New();
        for (auto event : {vtkCommand::WindowMakeCurrentEvent, vtkCommand::WindowIsCurrentEvent,
                           vtkCommand::WindowFrameEvent, vtkCommand::WindowSupportsOpenGLEvent,
                           vtkCommand::WindowIsDirectEvent})
            window->AddObserver(event, windowCallback);
        window->AddObserver(vtkCommand::ErrorEvent, errorCallback);
        window->SetOwnContext(0);
        window->SetMultiSamples(0);         // multisampling blends ids at face borders
        window->SetFrameBlitModeToNoBlit(); // the image stays in VTK's framebuffer; we read it there
        // No Frame(): it would copy the image into VTK's display framebuffer, which nobody reads.
        window->SetSwapBuffers(0);
        window->SetUseSRGBColorSpace(false);
        window->SetSize(1, 1);
        window->SetReadyForRendering(false);
        vtkCam->AddObserver(vtkCommand::ErrorEvent, errorCallback);
    }

    ~Impl() {
        if (!window) return;
        // Free the GL resources while the context is current; VTK objects are deleted afterwards.
        try {
            ScopedVtkMessages route(messages);
            ScopedCurrent current(*context);
            if (glInitialised) {
                ScopedGlState state;
                window->Finalize();
            }
            for (auto& pass : passes)
                window->RemoveRenderer(pass->renderer);
            passes.clear();
            window->RemoveAllObservers();
            window = nullptr;
        } catch (...) {
            // A destructor must not throw; the context is gone anyway.
        }
    }

    static void onWindowEvent(vtkObject*, unsigned long event, void* clientData, void* callData) {
        auto* self = static_cast<Impl*>(clientData);
        try {
            switch (event) {
            case vtkCommand::WindowMakeCurrentEvent:
                self->context->makeCurrent();
                break;
            case vtkCommand::WindowIsCurrentEvent:
                *static_cast<bool*>(callData) = self->context->isCurrent();
                break;
            case vtkCommand::WindowSupportsOpenGLEvent:
                *static_cast<int*>(callData) = 1;
                break;
            case vtkCommand::WindowIsDirectEvent:
                *static_cast<int*>(callData) = 1;
                break;
            case vtkCommand::WindowFrameEvent:
                break; // nothing to present: the scan is read back
            default:
                break;
            }
        } catch (...) {
            if (!self->callbackError) self->callbackError = std::current_exception();
        }
    }

    static void onError(vtkObject*, unsigned long, void* clientData, void* callData) {
        static_cast<Impl*>(clientData)->messages.error(static_cast<const char*>(callData));
    }

    void rethrowCallbackError() {
        if (callbackError) {
            auto e = callbackError;
            callbackError = nullptr;
            std::rethrow_exception(e);
        }
    }

    // VTK carries on (and crashes) after failing to initialise GL: check the context first.
    static void checkContext() {
        const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
        if (!version)
            throw Error("No OpenGL context is current: the Rasterizer's GlContext did not make one current.");
        int major = 0, minor = 0;
        if (std::sscanf(version, "%d.%d", &major, &minor) != 2 || major < 3 || (major == 3 && minor < 2))
            throw Error("The OpenGL context has version " + std::string(version) +
                        "; the Rasterizer needs OpenGL 3.2 or later.");
    }

    // First use of GL: let VTK take over the (current, checked) context.
    void initialiseGl() {
        if (glInitialised) return;
        window->SetReadyForRendering(true);
        window->InitializeFromCurrentContext();
        rethrowCallbackError();
        messages.throwIfAny("while initialising OpenGL");
        if (const auto* s = reinterpret_cast<const char*>(glGetString(GL_RENDERER))) renderer = s;
        glInitialised = true;
    }

    int passCountFor(std::size_t faces) const {
        int n = 1;
        while (bitsPerPass * n < 32 && (std::uint64_t(faces) >> (bitsPerPass * n)) != 0)
            ++n;
        return n;
    }

    // Makes the pass objects match the pass count of the current mesh and gives every pass new poly data
    // (points and triangles shared, its own bits of the ids as cell colours). Mappers notice the new input
    // and upload it at the next render. Needs the GL context current once GL is initialised (removing a
    // renderer frees its GL resources).
    void buildPasses() {
        const std::size_t faces = cellToFace.size();
        const int count = passCountFor(faces);
        while (int(passes.size()) > count) {
            window->RemoveRenderer(passes.back()->renderer);
            passes.pop_back();
        }
        while (int(passes.size()) < count)
            passes.push_back(makePass());
        const std::uint32_t mask = (1u << bitsPerPass) - 1u;
        for (int p = 0; p < count; ++p) {
            vtkNew<vtkUnsignedCharArray> colours;
            colours->SetName("fss_face_id");
            colours->SetNumberOfComponents(3);
            colours->SetNumberOfTuples(vtkIdType(faces));
            unsigned char* c = colours->GetPointer(0);
            const int shift = bitsPerPass * p;
            for (std::size_t i = 0; i < faces; ++i) {
                const std::uint32_t v = std::uint32_t((std::uint64_t(i) + 1) >> shift) & mask;
                c[3 * i + 0] = static_cast<unsigned char>(v & 0xFFu);
                c[3 * i + 1] = static_cast<unsigned char>((v >> 8) & 0xFFu);
                c[3 * i + 2] = static_cast<unsigned char>((v >> 16) & 0xFFu);
            }
            vtkNew<vtkPolyData> polyData;
            polyData->SetPoints(points);
            polyData->SetPolys(triangles);
            polyData->GetCellData()->SetScalars(colours);
            passes[p]->mapper->SetInputData(polyData);
            passes[p]->renderer->SetDraw(p == 0);
        }
    }

    // commit() then buildPasses(), with VTK's messages routed and, once GL is initialised, the context
    // current and the caller's GL state kept. commit() runs only once the context is current.
    template <class Commit> void updatePasses(Commit&& commit) {
        ScopedVtkMessages route(messages);
        std::optional<ScopedCurrent> current;
        std::optional<ScopedGlState> saved;
        if (glInitialised) {
            current.emplace(*context);
            rethrowCallbackError();
            saved.emplace();
        }
        commit();
        buildPasses();
        rethrowCallbackError();
        messages.throwIfAny("while storing the mesh");
    }

    std::unique_ptr<IdPass> makePass() {
        auto pass = std::make_unique<IdPass>();
        CountingMapper* mapper = pass->mapper;
        mapper->uploads = &uploads;
        mapper->SetStatic(1); // no pipeline behind the data: never ask it for updates
        mapper->ScalarVisibilityOn();
        mapper->SetScalarModeToUseCellData();
        mapper->SetColorModeToDirectScalars(); // RGB bytes as they are: no lookup table
        mapper->InterpolateScalarsBeforeMappingOff();
        mapper->AddObserver(vtkCommand::ErrorEvent, errorCallback);

        // Flat, unlit, both sides: the fragment colour is exactly the cell colour.
        vtkProperty* property = pass->actor->GetProperty();
        property->LightingOff();
        property->SetInterpolationToFlat();
        property->SetRepresentationToSurface();
        property->EdgeVisibilityOff();
        property->BackfaceCullingOff();
        property->FrontfaceCullingOff();
        property->SetAmbient(0.0);
        property->SetDiffuse(1.0);
        property->SetSpecular(0.0);
        property->SetOpacity(1.0);
        pass->actor->SetMapper(mapper);
        pass->actor->PickableOff();

        vtkOpenGLRenderer* renderer = pass->renderer;
        renderer->SetBackground(0.0, 0.0, 0.0); // colour 0 = no face
        renderer->SetBackgroundAlpha(0.0);
        renderer->UseFXAAOff();
        renderer->UseDepthPeelingOff();
        renderer->UseShadowsOff();
        renderer->AutomaticLightCreationOff();
        renderer->SetActiveCamera(vtkCam);
        renderer->AddActor(pass->actor);
        renderer->AddObserver(vtkCommand::ErrorEvent, errorCallback);
        window->AddRenderer(renderer);
        return pass;
    }

    // Reads the colour attachment of VTK's render framebuffer as RGBA8 words into dst (GL row order).
    void readColour(std::uint32_t* dst, int w, int h) {
        glReadBuffer(GL_COLOR_ATTACHMENT0);
        glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, dst);
    }

    void render(const Camera& requested, FrameBuffers& out, const RenderOptions& options);
};

Rasterizer::Rasterizer() : impl_(nullptr) {
    auto own = std::make_unique<HeadlessGlContext>();
    GlContext* ctx = own.get();
    impl_ = std::make_unique<Impl>(ctx);
    impl_->ownContext = std::move(own);
}

Rasterizer::Rasterizer(GlContext& context) : impl_(std::make_unique<Impl>(&context)) {}

Rasterizer::~Rasterizer() = default;
Rasterizer::Rasterizer(Rasterizer&&) noexcept = default;
Rasterizer& Rasterizer::operator=(Rasterizer&&) noexcept = default;

void Rasterizer::setMesh(const Mesh& mesh) {
    if (mesh.number_of_faces() == 0) throw InvalidInputError("Cannot rasterize a mesh without faces.");
    Impl& d = *impl_;

    // Dense VTK point ids for the live vertices (the mesh may hold removed elements).
    std::vector<vtkIdType> pointId(mesh.num_vertices(), -1);
    auto points = vtkSmartPointer<vtkPoints>::New();
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(vtkIdType(mesh.number_of_vertices()));
    double* xyz = static_cast<double*>(points->GetVoidPointer(0));
    Eigen::AlignedBox3d box;
    vtkIdType next = 0;
    for (VertexIndex v : mesh.vertices()) {
        const Point3& p = mesh.point(v);
        const Eigen::Vector3d q(p.x(), p.y(), p.z());
        if (!q.allFinite())
            throw InvalidInputError("Cannot rasterize the mesh: vertex " + std::to_string(std::size_t(v)) +
                                    " has a non-finite coordinate.");
        xyz[3 * next + 0] = q.x();
        xyz[3 * next + 1] = q.y();
        xyz[3 * next + 2] = q.z();
        box.extend(q);
        pointId[std::size_t(v)] = next++;
    }

    std::vector<std::uint32_t> cellToFace;
    cellToFace.reserve(mesh.number_of_faces());
    auto offsets = vtkSmartPointer<vtkIdTypeArray>::New();
    auto connectivity = vtkSmartPointer<vtkIdTypeArray>::New();
    offsets->SetNumberOfValues(vtkIdType(mesh.number_of_faces()) + 1);
    vtkIdType* off = offsets->GetPointer(0);
    vtkIdType cell = 0, corners = 0;
    off[0] = 0;
    for (FaceIndex f : mesh.faces()) {
        corners += vtkIdType(CGAL::degree(f, mesh));
        off[++cell] = corners;
        cellToFace.push_back(std::uint32_t(f));
    }
    connectivity->SetNumberOfValues(corners);
    vtkIdType* conn = connectivity->GetPointer(0);
    for (FaceIndex f : mesh.faces())
        for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
            *conn++ = pointId[std::size_t(v)];
    auto triangles = vtkSmartPointer<vtkCellArray>::New();
    triangles->SetData(offsets, connectivity);

    // Nothing above touched the Rasterizer.
    d.updatePasses([&] {
        d.points = points;
        d.triangles = triangles;
        d.cellToFace = std::move(cellToFace);
        d.box = box;
    });
}

bool Rasterizer::hasMesh() const {
    return !impl_->cellToFace.empty();
}
std::size_t Rasterizer::faceCount() const {
    return impl_->cellToFace.size();
}
const Eigen::AlignedBox3d& Rasterizer::bounds() const {
    return impl_->box;
}
std::uint64_t Rasterizer::uploadCount() const {
    return impl_->uploads;
}
const RenderStats& Rasterizer::lastStats() const {
    return impl_->stats;
}
std::string Rasterizer::glRenderer() const {
    return impl_->renderer;
}
int Rasterizer::idBitsPerPass() const {
    return impl_->bitsPerPass;
}

Eigen::Matrix4d Rasterizer::vtkViewProjectionMatrix(const Camera& camera) const {
    camera.validate();
    vtkNew<vtkOpenGLCamera> vc;
    applyCamera(vc, camera);
    vtkMatrix4x4* m = vc->GetCompositeProjectionTransformMatrix(camera.aspect(), -1.0, 1.0);
    Eigen::Matrix4d result;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            result(i, j) = m->GetElement(i, j);
    return result;
}

void Rasterizer::setIdBitsPerPass(int bits) {
    if (bits < 1 || bits > 24)
        throw InvalidInputError("The number of id bits per pass " + std::to_string(bits) +
                                " is outside the range 1 to 24.");
    Impl& d = *impl_;
    if (bits == d.bitsPerPass) return;
    if (d.cellToFace.empty())
        d.bitsPerPass = bits;
    else
        d.updatePasses([&] { d.bitsPerPass = bits; });
}

FrameBuffers Rasterizer::render(const Camera& camera, const RenderOptions& options) {
    FrameBuffers out;
    render(camera, out, options);
    return out;
}

void Rasterizer::render(const Camera& camera, FrameBuffers& out, const RenderOptions& options) {
    impl_->render(camera, out, options);
}

void Rasterizer::Impl::render(const Camera& requested, FrameBuffers& out, const RenderOptions& options) {
    if (cellToFace.empty())
        throw InvalidInputError("Cannot render a scan before a mesh was given (setMesh).");
    requested.validate();
    Camera cam = requested;
    if (!options.keepClippingRange) cam.fitClippingRange(box);

    const int w = cam.width, h = cam.height;
    const std::size_t n = std::size_t(w) * std::size_t(h);
    out.camera = cam;
    out.depth.resize(n);
    out.faceId.resize(n);
    if (int(passes.size()) > 1) scratch.resize(n);

    ScopedVtkMessages route(messages);
    ScopedCurrent current(*context);
    rethrowCallbackError();
    checkContext();
    ScopedGlState savedState;
    initialiseGl();

    const auto t0 = Clock::now();
    window->SetSize(w, h);
    applyCamera(vtkCam, cam);

    const int passCount = int(passes.size());
    const int bits = bitsPerPass;
    const std::uint32_t mask = (1u << bits) - 1u;
    double readSeconds = 0;
    for (int p = 0; p < passCount; ++p) {
        for (int q = 0; q < passCount; ++q)
            passes[q]->renderer->SetDraw(q == p);
        window->Render();
        rethrowCallbackError();
        messages.throwIfAny("while rendering the scan");
        glFinish();

        const auto r0 = Clock::now();
        vtkOpenGLFramebufferObject* fbo = window->GetRenderFramebuffer();
        if (!fbo) throw Error("VTK rendered the scan without an off-screen framebuffer.");
        glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo->GetFBOIndex());
        glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glPixelStorei(GL_PACK_ROW_LENGTH, 0);
        glPixelStorei(GL_PACK_SKIP_ROWS, 0);
        glPixelStorei(GL_PACK_SKIP_PIXELS, 0);
        if (p == 0) {
            glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, out.depth.data());
            readColour(out.faceId.data(), w, h);
            if (passCount > 1)
                for (auto& v : out.faceId)
                    v = rgbValue(v) & mask;
        } else {
            readColour(scratch.data(), w, h);
            const int shift = bits * p;
            for (std::size_t i = 0; i < n; ++i)
                out.faceId[i] |= (rgbValue(scratch[i]) & mask) << shift;
        }
        const GLenum err = glGetError();
        if (err != GL_NO_ERROR) throw Error("Reading back the scan failed with " + glErrorName(err) + ".");
        readSeconds += secondsSince(r0);
    }
    for (int q = 0; q < passCount; ++q)
        passes[q]->renderer->SetDraw(q == 0);

    // GL rows go bottom-up: flip to row 0 = top while decoding the ids.
    const auto d0 = Clock::now();
    const std::uint32_t faces = std::uint32_t(cellToFace.size());
    std::uint32_t bad = 0;
    auto decode = [&](std::uint32_t raw) -> std::uint32_t {
        const std::uint32_t v = passCount > 1 ? raw : rgbValue(raw);
        if (v == 0) return FrameBuffers::kNoFace;
        if (v > faces) {
            ++bad;
            return FrameBuffers::kNoFace;
        }
        return cellToFace[v - 1];
    };
    for (int top = 0, bottom = h - 1; top <= bottom; ++top, --bottom) {
        std::uint32_t* a = out.faceId.data() + std::size_t(top) * w;
        std::uint32_t* b = out.faceId.data() + std::size_t(bottom) * w;
        if (a == b) {
            for (int x = 0; x < w; ++x)
                a[x] = decode(a[x]);
        } else {
            for (int x = 0; x < w; ++x) {
                const std::uint32_t va = a[x];
                a[x] = decode(b[x]);
                b[x] = decode(va);
            }
            std::swap_ranges(out.depth.data() + std::size_t(top) * w,
                             out.depth.data() + std::size_t(top + 1) * w,
                             out.depth.data() + std::size_t(bottom) * w);
        }
    }
    if (bad)
        throw Error(
            "The ID render produced " + std::to_string(bad) +
            " pixels with colours that are no face id (multisampling or colour management interfered).");
    readSeconds += secondsSince(d0);

    stats.passes = passCount;
    stats.readSeconds = readSeconds;
    stats.renderSeconds = secondsSince(t0) - readSeconds;
}

} // namespace fss::render
