#include "fss/render/gl_context.h"

#include "fss/error.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>

#include <cstring>
#include <string>
#include <string_view>

namespace fss::render {
namespace {

bool hasExtension(const char* list, std::string_view name) {
    if (!list) return false;
    std::string_view all(list);
    for (std::size_t pos = 0; pos < all.size();) {
        const std::size_t end = std::min(all.find(' ', pos), all.size());
        if (all.substr(pos, end - pos) == name) return true;
        pos = end + 1;
    }
    return false;
}

std::string eglErrorName(EGLint code) {
    switch (code) {
    case EGL_SUCCESS:
        return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
        return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
        return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
        return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
        return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
        return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
        return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
        return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
        return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
        return "EGL_BAD_PARAMETER";
    default:
        return "EGL error " + std::to_string(code);
    }
}

[[noreturn]] void fail(const std::string& why) {
    throw Error("No OpenGL context could be created: " + why + ".");
}

std::string glString(GLenum name) {
    const auto* s = reinterpret_cast<const char*>(glGetString(name));
    return s ? std::string(s) : std::string();
}

// Binds the OpenGL API for the lifetime of the object and restores the previously bound API.
class ScopedOpenGLApi {
public:
    ScopedOpenGLApi() : previous_(eglQueryAPI()) {
        if (previous_ != EGL_OPENGL_API) eglBindAPI(EGL_OPENGL_API);
    }
    ~ScopedOpenGLApi() {
        if (previous_ != EGL_OPENGL_API && previous_ != EGL_NONE) eglBindAPI(previous_);
    }
    ScopedOpenGLApi(const ScopedOpenGLApi&) = delete;
    ScopedOpenGLApi& operator=(const ScopedOpenGLApi&) = delete;

private:
    EGLenum previous_;
};

} // namespace

struct HeadlessGlContext::Impl {
    EGLDisplay display = EGL_NO_DISPLAY;
    EGLContext context = EGL_NO_CONTEXT;
    std::string renderer, version;

    // What was current before makeCurrent() (restored by doneCurrent()).
    bool saved = false;
    EGLenum savedApi = EGL_OPENGL_API;
    EGLDisplay savedDisplay = EGL_NO_DISPLAY;
    EGLContext savedContext = EGL_NO_CONTEXT;
    EGLSurface savedDraw = EGL_NO_SURFACE, savedRead = EGL_NO_SURFACE;
};

HeadlessGlContext::HeadlessGlContext() : impl_(std::make_unique<Impl>()) {
    const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!hasExtension(clientExtensions, "EGL_MESA_platform_surfaceless") ||
        !(hasExtension(clientExtensions, "EGL_EXT_platform_base") ||
          hasExtension(clientExtensions, "EGL_KHR_platform_base")))
        fail("EGL surfaceless platform is unavailable (install libegl-mesa0)");
    auto getPlatformDisplay =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!getPlatformDisplay) fail("EGL lacks eglGetPlatformDisplayEXT (install libegl-mesa0)");

    // Mesa returns the same EGLDisplay for every request of the default surfaceless display, so it is
    // never terminated here: eglTerminate would invalidate the contexts of every other user of it.
    EGLDisplay display = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (display == EGL_NO_DISPLAY) fail("EGL surfaceless platform is unavailable (install libegl-mesa0)");
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor))
        fail("the EGL surfaceless display failed to initialise (" + eglErrorName(eglGetError()) +
             "; is libgl1-mesa-dri installed?)");
    const char* displayExtensions = eglQueryString(display, EGL_EXTENSIONS);
    if (!hasExtension(displayExtensions, "EGL_KHR_surfaceless_context"))
        fail("the EGL display does not support surfaceless contexts (EGL_KHR_surfaceless_context)");

    ScopedOpenGLApi api;
    if (!eglBindAPI(EGL_OPENGL_API)) fail("EGL does not support the desktop OpenGL API");

    EGLConfig config = nullptr; // EGL_NO_CONFIG_KHR
    if (!hasExtension(displayExtensions, "EGL_KHR_no_config_context")) {
        const EGLint configAttribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLint count = 0;
        if (!eglChooseConfig(display, configAttribs, &config, 1, &count) || count < 1)
            fail("EGL offers no configuration for desktop OpenGL");
    }
    const EGLint contextAttribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                     3,
                                     EGL_CONTEXT_MINOR_VERSION,
                                     2,
                                     EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                     EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                     EGL_NONE};
    EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, contextAttribs);
    if (context == EGL_NO_CONTEXT)
        fail("EGL could not create an OpenGL 3.2 core context (" + eglErrorName(eglGetError()) + ")");
    impl_->display = display;
    impl_->context = context;

    try {
        makeCurrent();
    } catch (const Error&) {
        eglDestroyContext(display, context);
        fail("the new EGL context could not be made current without a surface");
    }
    impl_->renderer = glString(GL_RENDERER);
    impl_->version = glString(GL_VERSION);
    doneCurrent();
}

HeadlessGlContext::~HeadlessGlContext() {
    if (!impl_) return;
    ScopedOpenGLApi api;
    if (eglGetCurrentContext() == impl_->context)
        eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(impl_->display, impl_->context);
}

void HeadlessGlContext::makeCurrent() {
    Impl& d = *impl_;
    const EGLenum api = eglQueryAPI();
    if (api != EGL_OPENGL_API) eglBindAPI(EGL_OPENGL_API);
    const EGLContext current = eglGetCurrentContext();
    if (current == d.context) return; // the common case while VTK renders
    d.saved = true;
    d.savedApi = api;
    d.savedContext = current;
    d.savedDisplay = eglGetCurrentDisplay();
    d.savedDraw = eglGetCurrentSurface(EGL_DRAW);
    d.savedRead = eglGetCurrentSurface(EGL_READ);
    if (!eglMakeCurrent(d.display, EGL_NO_SURFACE, EGL_NO_SURFACE, d.context)) {
        const EGLint code = eglGetError();
        d.saved = false;
        if (api != EGL_OPENGL_API) eglBindAPI(api);
        throw Error("The head-less OpenGL context could not be made current (" + eglErrorName(code) + ").");
    }
}

bool HeadlessGlContext::isCurrent() const {
    ScopedOpenGLApi api;
    return eglGetCurrentContext() == impl_->context;
}

void HeadlessGlContext::doneCurrent() {
    Impl& d = *impl_;
    {
        ScopedOpenGLApi api;
        if (eglGetCurrentContext() != d.context) return;
        if (d.saved && d.savedContext != EGL_NO_CONTEXT) {
            eglMakeCurrent(d.savedDisplay, d.savedDraw, d.savedRead, d.savedContext);
        } else {
            eglMakeCurrent(d.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        }
    }
    if (d.saved && d.savedApi != EGL_OPENGL_API && d.savedApi != EGL_NONE) eglBindAPI(d.savedApi);
    d.saved = false;
}

const std::string& HeadlessGlContext::renderer() const {
    return impl_->renderer;
}
const std::string& HeadlessGlContext::version() const {
    return impl_->version;
}

} // namespace fss::render
