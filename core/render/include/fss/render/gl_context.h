#pragma once
/// \file gl_context.h
/// The OpenGL context a Rasterizer renders in: a small interface so that the same Rasterizer runs
/// head-less (HeadlessGlContext, the default) or inside an application's context (a Qt widget's
/// QOpenGLContext, an own EGL context, ...).

#include <memory>
#include <string>

namespace fss::render {

/// An OpenGL 3.2+ core (or compatibility) context that a Rasterizer may make current on its thread.
///
/// The Rasterizer calls makeCurrent() before every use of GL and doneCurrent() afterwards **only if the
/// context was not current when it started** (isCurrent() tells), so a caller that renders with its own
/// context current keeps it current. Implementations are used from one thread at a time.
class GlContext {
public:
    virtual ~GlContext() = default;

    /// Makes the context current on the calling thread. Must be cheap when it already is (VTK calls it
    /// often). \throw fss::Error when the context cannot be made current.
    virtual void makeCurrent() = 0;
    /// Whether this context is current on the calling thread.
    virtual bool isCurrent() const = 0;
    /// Releases the context from the calling thread (an implementation may restore whatever context was
    /// current before makeCurrent()).
    virtual void doneCurrent() = 0;
};

/// A head-less OpenGL core context from Mesa's EGL **surfaceless** platform: needs neither an X server
/// nor a GPU (llvmpipe renders on the CPU). Rendering goes to framebuffer objects only: the context has no
/// default framebuffer.
///
/// makeCurrent() remembers the EGL context that was current on the thread (if any) and doneCurrent()
/// restores it, so nesting inside another EGL user is harmless. A GLX context current on the same thread
/// cannot be combined with it (EGL refuses); pass that application context to the Rasterizer instead.
class HeadlessGlContext final : public GlContext {
public:
    /// Creates the context (EGL_PLATFORM_SURFACELESS_MESA, OpenGL API, core profile 3.2 or later).
    /// \throw fss::Error (one sentence) when EGL, its surfaceless platform or an OpenGL 3.2 context is not
    ///        available, e.g. "No OpenGL context could be created: EGL surfaceless platform is unavailable
    ///        (install libegl-mesa0)."
    HeadlessGlContext();
    ~HeadlessGlContext() override;
    HeadlessGlContext(const HeadlessGlContext&) = delete;
    HeadlessGlContext& operator=(const HeadlessGlContext&) = delete;

    /// \throw fss::Error when eglMakeCurrent fails.
    void makeCurrent() override;
    bool isCurrent() const override;
    void doneCurrent() override;

    /// GL_RENDERER of the context, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
    const std::string& renderer() const;
    /// GL_VERSION of the context, e.g. "4.5 (Core Profile) Mesa 22.3.6".
    const std::string& version() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace fss::render
