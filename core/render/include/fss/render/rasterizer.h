#pragma once
/// \file rasterizer.h
/// The scan rasterizer: renders a mesh off-screen with a Camera into FrameBuffers (window depth and the
/// Face_index under every pixel centre), the "scan" of the paper (Vorsatz et al. 2000, §3) and the ID
/// buffer used by masks, direction fields and stitching.
///
/// One ID render per pass: every face is drawn flat, unlit, without multisampling or anti-aliasing, in
/// the colour (RGB = bits of its index + 1), so the colour under a pixel centre decodes exactly to the
/// face the rasterizer covered it with; the z-buffer of the same render is the depth. Meshes with more
/// than 2^24 − 1 faces take more passes (24 bits of the id each); depth comes from the first pass.
///
/// The mesh is uploaded once by setMesh(); render() may then be called any number of times with
/// different cameras without sending the mesh to the GL again.
///
/// Uses VTK (OpenGL2 backend) behind this header: consumers need only FSS headers. While a Rasterizer
/// call runs, VTK's process-wide output window is replaced by one that turns VTK errors into fss::Error
/// (warnings are passed on to the previous one); it is put back before the call returns.

#include "fss/camera.h"
#include "fss/frame_buffers.h"
#include "fss/mesh.h"
#include "fss/render/gl_context.h"

#include <cstddef>
#include <cstdint>
#include <memory>

namespace fss::render {

/// Options of one Rasterizer::render call.
struct RenderOptions {
    /// Use the camera's near/far planes as given. By default (false) they are replaced by a tight range
    /// around the mesh's bounding box (Camera::fitClippingRange), which maximises depth precision;
    /// FrameBuffers::camera holds the range actually used either way.
    bool keepClippingRange = false;
};

/// Wall-clock cost of the last render() (GL work finished before each figure is taken).
struct RenderStats {
    int passes = 0;           ///< ID passes rendered (1 unless the mesh has more than 2^24 − 1 faces)
    double renderSeconds = 0; ///< camera set-up + drawing all passes, until the GL finished
    double readSeconds = 0;   ///< glReadPixels of depth and colours, row flip and id decoding
};

/// Off-screen ID + depth renderer of one mesh. Not copyable; movable. Several may live in one process.
/// Use each from one thread at a time (the thread its context is used on), and VTK from one thread.
class Rasterizer {
public:
    /// Creates a Rasterizer with its own head-less HeadlessGlContext (Mesa EGL surfaceless): works
    /// without an X server (DISPLAY unset).
    /// \throw fss::Error when no OpenGL context could be created (see HeadlessGlContext).
    Rasterizer();

    /// Creates a Rasterizer that renders in the caller's context \p context (e.g. a Qt widget's). Rendering
    /// happens in framebuffer objects of the Rasterizer; the caller's framebuffer bindings, viewport,
    /// scissor box and pixel-pack state are restored after every call. Does not use GL yet: the context
    /// is first made current by render(), where problems with it are reported.
    /// \pre \p context outlives the Rasterizer and is an OpenGL 3.2+ context usable on the calling thread.
    explicit Rasterizer(GlContext& context);

    /// Releases the GL resources (making the context current for that). A moved-from Rasterizer may only be
    /// destroyed or assigned to.
    ~Rasterizer();
    Rasterizer(Rasterizer&&) noexcept;
    Rasterizer& operator=(Rasterizer&&) noexcept;
    Rasterizer(const Rasterizer&) = delete;
    Rasterizer& operator=(const Rasterizer&) = delete;

    /// Copies the mesh's points and faces; they are sent to the GL once, by the next render(), and reused by
    /// every later render(). Face ids in the FrameBuffers are the mesh's own Face_index values, valid also
    /// when the mesh has removed elements (garbage): only live faces are drawn. Polygons with more than
    /// three corners are drawn as fans. The Rasterizer keeps no reference to \p mesh. When the mesh is
    /// rejected or the context cannot be made current, the previous mesh stays (strong guarantee).
    /// \pre the mesh has at least one face, all vertex coordinates are finite.
    /// \throw InvalidInputError when the mesh has no face or a non-finite point.
    /// \throw fss::Error when the context cannot be made current or VTK reports an error.
    void setMesh(const Mesh& mesh);

    /// Whether setMesh() has been called.
    bool hasMesh() const;
    /// Number of faces drawn (live faces of the mesh given to setMesh()).
    std::size_t faceCount() const;
    /// Bounding box of the mesh given to setMesh() (empty before).
    const Eigen::AlignedBox3d& bounds() const;

    /// Renders the mesh with \p camera (camera.width × camera.height pixels) and reads back depth and face
    /// ids into a new FrameBuffers. See render(const Camera&, FrameBuffers&, const RenderOptions&).
    FrameBuffers render(const Camera& camera, const RenderOptions& options = {});

    /// Renders the mesh with \p camera and reads back into \p out, reusing its storage. out.camera is the
    /// camera used (with the fitted clipping range unless options.keepClippingRange), out.depth the window
    /// depth (1 where no face is), out.faceId the Face_index under each pixel centre (kNoFace where none),
    /// both with row 0 = top image row. Camera::unproject of (x+½, y+½, depth) gives the world point.
    /// \pre setMesh() was called; camera.validate() passes; with the fitted range, the mesh is not
    ///      entirely behind the eye.
    /// \throw InvalidInputError when there is no mesh, the camera is invalid or the mesh is behind it.
    /// \throw fss::Error when the context cannot be made current, is not OpenGL 3.2+, or VTK or the GL
    ///        report an error (the message names it). \p out is then unspecified.
    void render(const Camera& camera, FrameBuffers& out, const RenderOptions& options = {});

    /// Number of times mesh data were uploaded to the GL (VTK buffer objects built): one per ID pass after
    /// each setMesh(), never because of a camera change.
    std::uint64_t uploadCount() const;

    /// Timings and pass count of the last render().
    const RenderStats& lastStats() const;

    /// GL_RENDERER of the context in use (empty before the first GL use).
    std::string glRenderer() const;

    /// Diagnostic: VTK's composite projection matrix (vtkCamera::GetCompositeProjectionTransformMatrix
    /// with the camera's aspect and depth range [−1, 1]: world → clip coordinates) of a VTK camera set from
    /// \p camera exactly as render() sets it (with the clipping range as given). It equals
    /// camera.viewProjectionMatrix() up to rounding, which is why Camera::unproject is exact for the
    /// buffers. Needs no GL context. \throw InvalidInputError when camera.validate() fails.
    Eigen::Matrix4d vtkViewProjectionMatrix(const Camera& camera) const;

    /// **Testing option**: bits of the face id carried by one ID pass, 1 to 24 (default 24: meshes with at
    /// most 2^24 − 1 faces take one pass). Smaller values force the multi-pass path on small meshes. The
    /// pass colours of a mesh already set are rebuilt (an upload per pass at the next render).
    /// \throw InvalidInputError when \p bits is outside [1, 24].
    void setIdBitsPerPass(int bits);
    /// Current bits per ID pass.
    int idBitsPerPass() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace fss::render
