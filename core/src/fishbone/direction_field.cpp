#include "fss/direction_field.h"

#include "fss/error.h"

#include "base/parallel_rows.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <memory>
#include <numbers>
#include <string>

namespace fss {
namespace {

Eigen::Vector3d toEigen(const Point3& p) {
    return {p.x(), p.y(), p.z()};
}

// Camera::unproject / ray with the matrices computed once (Camera rebuilds them on every call), same
// conventions as camera.h.
class Projector {
public:
    explicit Projector(const Camera& c)
        : c_(c), vp_(c.viewProjectionMatrix()), inverse_(vp_.inverse()),
          footprintPerDepth_(2.0 * std::tan(0.5 * c.viewAngleDeg * std::numbers::pi / 180.0) / c.height),
          viewDirection_(c.viewDirection()) {}

    Eigen::Vector3d unproject(double sx, double sy, double depth) const {
        const Eigen::Vector4d ndc(2.0 * sx / c_.width - 1.0, 1.0 - 2.0 * sy / c_.height, 2.0 * depth - 1.0,
                                  1.0);
        const Eigen::Vector4d w = inverse_ * ndc;
        return w.head<3>() / w.w();
    }
    Ray ray(double sx, double sy) const {
        const Eigen::Vector3d a = unproject(sx, sy, 0.0), b = unproject(sx, sy, 1.0);
        return {c_.parallel ? a : c_.eye, (b - a).normalized()};
    }
    const Eigen::Matrix4d& viewProjection() const { return vp_; }
    const Eigen::Matrix4d& inverse() const { return inverse_; }
    double pixelFootprint(const Eigen::Vector3d& p) const {
        if (c_.parallel) return 2.0 * c_.parallelScale / c_.height;
        return std::abs((p - c_.eye).dot(viewDirection_)) * footprintPerDepth_;
    }

private:
    const Camera& c_;
    Eigen::Matrix4d vp_, inverse_;
    double footprintPerDepth_;
    Eigen::Vector3d viewDirection_;
};

constexpr double kMinDirectionWeight = 1e-3;

std::string pixelName(int x, int y) {
    return "(" + std::to_string(x) + ", " + std::to_string(y) + ")";
}

} // namespace

namespace {

// Normalises and stores one pixel's values (DirectionField::setPixel's rule, shared by the lazy tiles so
// both give the same bits). Returns whether the pixel is valid.
bool storePixel(Eigen::Vector2d& direction, float& anisotropy, const Eigen::Vector2d& dir, double aniso) {
    const double len = dir.norm();
    if (!(len > 0) || !std::isfinite(len) || !std::isfinite(aniso)) {
        direction.setZero();
        anisotropy = 0;
        return false;
    }
    direction = dir / len;
    anisotropy = float(std::clamp(aniso, 0.0, 1.0));
    return true;
}

// What the pixels of one face share (computed once per face, FaceCache): its corners, normal n, the
// barycentric dual vectors gᵢ = n × (edge opposite corner i) / |n|² (so wᵢ = (p − qᵢ)·gᵢ with qᵢ the
// next corner), and per corner the vertex normal, the anisotropy (0 where the curvature is undefined)
// and, per principal direction, the vertex direction flipped to agree with the face's first defined one
// (line field; zero where undefined).
struct FaceGeometry {
    std::uint32_t id = FrameBuffers::kNoFace;
    std::array<Eigen::Vector3d, 3> corner, g, normal;
    std::array<std::array<Eigen::Vector3d, 3>, 2> dir; // [useMax][corner]
    std::array<double, 3> aniso{};
    Eigen::Vector3d n;
    double n2 = 0;
};

// The last faces seen, direct-mapped by id: neighbouring pixels, and the rows of a tile, mostly show the
// faces just seen.
struct FaceCache {
    static constexpr std::size_t kSlots = 64;
    std::array<FaceGeometry, kSlots> slots;
};

// What the per-pixel computation of both principal directions shares: the face, the barycentric
// coordinates, the surface point, its clip coordinates, the interpolated normal and vertex anisotropy.
struct PixelFrame {
    FaceCache cache;
    const FaceGeometry* face = nullptr;
    std::array<double, 3> w;
    Eigen::Vector3d p, N;
    Eigen::Vector4d clip; // VP·(p, 1)
    double aniso = 0;
    double footprint = 0; // pixel footprint at p (world units)
};

// The inputs of a direction field with their checks, and the per-pixel computation (header, steps 1–6).
class FieldSource {
public:
    FieldSource(const Mesh& mesh, const CurvatureField& curvature, const FrameBuffers& buffers)
        : mesh_(mesh), curvature_(curvature), buffers_(buffers), projector_((validate(), buffers.camera)),
          faceSlots_(mesh.number_of_faces() + mesh.number_of_removed_faces()) {
        // Perspective: the homogeneous far point of pixel (nx, ny) in NDC, H = M⁻¹·(nx, ny, 1, 1), is affine
        // in (nx, ny), and so is H.xyz − eye·H.w, a (non-unit) direction of the ray from the eye.
        const Camera& c = buffers.camera;
        const Eigen::Matrix4d& inv = projector_.inverse();
        auto dir = [&](const Eigen::Vector4d& h) { return Eigen::Vector3d(h.head<3>() - c.eye * h.w()); };
        rayX_ = dir(inv.col(0)) * (2.0 / c.width);
        rayY_ = dir(inv.col(1)) * (-2.0 / c.height);
        ray0_ = dir(inv.col(2) + inv.col(3) - inv.col(0) + inv.col(1));
    }

    int width() const { return buffers_.camera.width; }
    int height() const { return buffers_.camera.height; }

    // Steps 1–3 and the shared part of 4: false where the pixel can have no direction (background,
    // degenerate face, barycentric coordinates all clamped away). \p fr caches faces between calls.
    // \throw InvalidInputError for a face id that is no triangle of the mesh.
    bool frame(int x, int y, PixelFrame& fr) const {
        const std::uint32_t id = buffers_.faceAt(x, y);
        if (id == FrameBuffers::kNoFace) return false;
        if (!fr.face || fr.face->id != id) {
            FaceGeometry& slot = fr.cache.slots[id % FaceCache::kSlots];
            if (slot.id != id) fillFace(slot, id, x, y);
            fr.face = &slot;
        }
        const FaceGeometry& face = *fr.face;
        const Eigen::Vector3d &a = face.corner[0], &n = face.n;
        if (!(face.n2 > 0)) return false; // degenerate face: no plane, no direction

        // 3D point under the pixel centre: ray ∩ face plane (double), depth buffer as fallback.
        Ray ray;
        if (buffers_.camera.parallel) {
            ray = projector_.ray(x + 0.5, y + 0.5);
        } else {
            ray.origin = buffers_.camera.eye;
            ray.direction = ray0_ + (x + 0.5) * rayX_ + (y + 0.5) * rayY_;
        }
        const double denom = n.dot(ray.direction);
        Eigen::Vector3d p;
        if (std::abs(denom) > 1e-12 * std::sqrt(face.n2) * ray.direction.norm())
            p = ray.origin + (n.dot(a - ray.origin) / denom) * ray.direction;
        else
            p = projector_.unproject(x + 0.5, y + 0.5, double(buffers_.depthAt(x, y)));

        // Barycentric coordinates, clamped to the triangle (the pixel centre may lie a hair outside).
        std::array<double, 3>& w = fr.w;
        double sum = 0;
        for (std::size_t k = 0; k < 3; ++k)
            sum += (w[k] = std::max(0.0, (p - face.corner[(k + 1) % 3]).dot(face.g[k])));
        if (!(sum > 0)) return false;
        for (double& wi : w)
            wi /= sum;
        fr.p = w[0] * a + w[1] * face.corner[1] + w[2] * face.corner[2];
        fr.clip = projector_.viewProjection() * fr.p.homogeneous();

        // Into the tangent plane of the interpolated vertex normal (the smooth surface's plane at p). The
        // face plane would tilt D by up to half the dihedral angle of the faceting, which the
        // foreshortening near silhouettes turns into screen errors of degrees.
        Eigen::Vector3d N = w[0] * face.normal[0] + w[1] * face.normal[1] + w[2] * face.normal[2];
        if (!(N.norm() > 1e-9)) N = n;
        fr.N = N.normalized();
        fr.aniso = w[0] * face.aniso[0] + w[1] * face.aniso[1] + w[2] * face.aniso[2];
        fr.footprint = projector_.pixelFootprint(fr.p);
        return true;
    }

    // Steps 4–6 for one principal direction: false where it has no screen direction; else the unnormalised
    // screen direction and the anisotropy to store.
    bool direction(const PixelFrame& fr, bool useMax, Eigen::Vector2d& screen, double& anisotropy) const {
        const std::array<Eigen::Vector3d, 3>& d = fr.face->dir[useMax ? 1 : 0];
        Eigen::Vector3d D = fr.w[0] * d[0] + fr.w[1] * d[1] + fr.w[2] * d[2];
        D -= D.dot(fr.N) * fr.N;
        const double coherence = D.norm();
        if (!(coherence > 1e-9)) return false;
        const Eigen::Vector3d unit = D / coherence;
        // The derivative of the projection at p along D̂ (pixels per world unit): the clip coordinates
        // of p + t·D̂ are clip + t·VP·(D̂, 0).
        const Eigen::Vector4d cu =
            projector_.viewProjection() * Eigen::Vector4d(unit.x(), unit.y(), unit.z(), 0.0);
        const Eigen::Vector4d& c = fr.clip;
        const double w2 = c.w() * c.w();
        screen = {0.5 * width() * (cu.x() * c.w() - c.x() * cu.w()) / w2,
                  -0.5 * height() * (cu.y() * c.w() - c.y() * cu.w()) / w2};
        // A direction along the viewing ray projects to (almost) nothing: no screen direction (less than
        // 10⁻⁶ pixels per pixel footprint).
        if (!(screen.norm() * fr.footprint > 1e-6)) return false;
        anisotropy = fr.aniso * std::min(1.0, coherence);
        return true;
    }

private:
    void fillFace(FaceGeometry& g, std::uint32_t id, int x, int y) const {
        const FaceIndex f(id);
        if (std::size_t(id) >= faceSlots_ || mesh_.is_removed(f))
            throw InvalidInputError("The face id " + std::to_string(id) + " at pixel " + pixelName(x, y) +
                                    " is not a face of the mesh.");
        std::array<VertexIndex, 3> v;
        int nv = 0;
        for (VertexIndex u : CGAL::vertices_around_face(mesh_.halfedge(f), mesh_)) {
            if (nv == 3) throw InvalidInputError("Face " + std::to_string(id) + " is not a triangle.");
            v[std::size_t(nv++)] = u;
        }
        if (nv != 3) throw InvalidInputError("Face " + std::to_string(id) + " is not a triangle.");
        for (std::size_t k = 0; k < 3; ++k)
            g.corner[k] = toEigen(mesh_.point(v[k]));
        g.n = (g.corner[1] - g.corner[0]).cross(g.corner[2] - g.corner[0]);
        g.n2 = g.n.squaredNorm();
        for (std::size_t k = 0; k < 3; ++k)
            g.g[k] = g.n2 > 0
                         ? Eigen::Vector3d(g.n.cross(g.corner[(k + 2) % 3] - g.corner[(k + 1) % 3]) / g.n2)
                         : Eigen::Vector3d::Zero();
        for (int useMax = 0; useMax < 2; ++useMax) {
            const Eigen::Vector3d* first = nullptr;
            for (std::size_t k = 0; k < 3; ++k) {
                Eigen::Vector3d& out = g.dir[std::size_t(useMax)][k];
                out.setZero();
                if (!curvature_.isDefined(v[k])) continue;
                // By magnitude: Max is the direction of the principal curvature of larger |k| (across a
                // crease, convex or concave), Min the other.
                const std::size_t vi = v[k].idx();
                const bool swapped = std::abs(curvature_.k2[vi]) > std::abs(curvature_.k1[vi]);
                const Eigen::Vector3d& d = curvature_.direction(v[k], (useMax != 0) != swapped);
                out = first && d.dot(*first) < 0 ? Eigen::Vector3d(-d) : d;
                if (!first) first = &d;
            }
        }
        for (std::size_t k = 0; k < 3; ++k) {
            g.normal[k] = curvature_.normal[v[k].idx()];
            g.aniso[k] = curvature_.isDefined(v[k]) ? curvature_.anisotropy[v[k].idx()] : 0.0;
        }
        g.id = id;
    }

    void validate() const {
        const Camera& camera = buffers_.camera;
        camera.validate();
        const std::size_t pixels = std::size_t(camera.width) * std::size_t(camera.height);
        if (buffers_.faceId.size() != pixels || buffers_.depth.size() != pixels)
            throw InvalidInputError("The frame buffers do not have width × height entries.");
        const std::size_t slots = mesh_.number_of_vertices() + mesh_.number_of_removed_vertices();
        if (curvature_.size() != slots || curvature_.d1.size() != slots || curvature_.d2.size() != slots ||
            curvature_.anisotropy.size() != slots || curvature_.defined.size() != slots ||
            curvature_.normal.size() != slots)
            throw InvalidInputError("The curvature field does not belong to this mesh (it has " +
                                    std::to_string(curvature_.size()) + " vertices, the mesh " +
                                    std::to_string(slots) + ").");
    }

    const Mesh& mesh_;
    const CurvatureField& curvature_;
    const FrameBuffers& buffers_;
    Projector projector_;
    std::size_t faceSlots_;
    Eigen::Vector3d ray0_, rayX_,
        rayY_; // perspective ray direction at pixel (sx, sy): ray0 + sx·rayX + sy·rayY
};

// One computed tile of a lazy field: the pixels [x0, x0 + w) × [y0, y0 + h), row-major.
struct DirectionTile {
    int x0 = 0, y0 = 0, w = 0, h = 0;
    std::vector<DirectionPixel> pixels;
    const DirectionPixel& at(int x, int y) const {
        return pixels[std::size_t(y - y0) * std::size_t(w) + std::size_t(x - x0)];
    }
};

} // namespace

namespace detail {

// The tile cache of a lazy DirectionField. A tile is computed by the first thread that needs it and
// published with one compare-exchange; a thread that loses the race drops its own (identical) copy.
struct LazyDirectionTiles {
    LazyDirectionTiles(const Mesh& mesh, const CurvatureField& curvature, const FrameBuffers& buffers,
                       bool max, int size)
        : source(mesh, curvature, buffers), useMax(max), tileSize(size),
          tileShift((size & (size - 1)) == 0 ? std::countr_zero(unsigned(size)) : -1),
          tilesX((source.width() + size - 1) / size), tilesY((source.height() + size - 1) / size),
          tiles(std::size_t(tilesX) * std::size_t(tilesY)) {}
    LazyDirectionTiles(const LazyDirectionTiles&) = delete;
    LazyDirectionTiles& operator=(const LazyDirectionTiles&) = delete;
    ~LazyDirectionTiles() {
        for (auto& t : tiles)
            delete t.load(std::memory_order_acquire);
    }

    // The tile column (row) of pixel column x (row y): a shift for the usual power-of-two sizes.
    int tileIndex(int x) const { return tileShift >= 0 ? x >> tileShift : x / tileSize; }

    // Tile (tx, ty), computed on first use. \pre 0 ≤ tx < tilesX, 0 ≤ ty < tilesY.
    const DirectionTile& tile(int tx, int ty) const {
        std::atomic<const DirectionTile*>& slot =
            tiles[std::size_t(ty) * std::size_t(tilesX) + std::size_t(tx)];
        if (const DirectionTile* t = slot.load(std::memory_order_acquire)) return *t;
        auto made = std::make_unique<const DirectionTile>(compute(tx * tileSize, ty * tileSize));
        const DirectionTile* expected = nullptr;
        if (slot.compare_exchange_strong(expected, made.get(), std::memory_order_acq_rel,
                                         std::memory_order_acquire))
            return *made.release();
        return *expected; // another thread published the same tile first
    }

    // The tile holding pixel (x, y), computed on first use. \pre (x, y) inside the image.
    const DirectionTile& tileOf(int x, int y) const { return tile(tileIndex(x), tileIndex(y)); }

    std::size_t computedPixels() const {
        std::size_t n = 0;
        for (const auto& t : tiles)
            if (const DirectionTile* p = t.load(std::memory_order_acquire))
                n += std::size_t(p->w) * std::size_t(p->h);
        return n;
    }

    FieldSource source;
    bool useMax;
    int tileSize;
    int tileShift; // log2(tileSize) when it is a power of two, else -1
    int tilesX, tilesY;

private:
    DirectionTile compute(int x0, int y0) const {
        DirectionTile t;
        t.x0 = x0;
        t.y0 = y0;
        t.w = std::min(tileSize, source.width() - x0);
        t.h = std::min(tileSize, source.height() - y0);
        t.pixels.resize(std::size_t(t.w) * std::size_t(t.h));
        PixelFrame& fr = threadFrame();
        Eigen::Vector2d screen;
        double aniso = 0;
        for (int y = y0; y < y0 + t.h; ++y)
            for (int x = x0; x < x0 + t.w; ++x)
                if (source.frame(x, y, fr) && source.direction(fr, useMax, screen, aniso)) {
                    DirectionPixel& px =
                        t.pixels[std::size_t(y - y0) * std::size_t(t.w) + std::size_t(x - x0)];
                    px.valid = storePixel(px.direction, px.anisotropy, screen, aniso);
                }
        return t;
    }

    // The calling thread's pixel frame for this field: the tiles one thread computes one after another
    // are mostly neighbours along its streamlines, so its face cache carries over between them.
    PixelFrame& threadFrame() const {
        thread_local struct {
            std::uint64_t owner = 0;
            std::unique_ptr<PixelFrame> frame;
        } local;
        if (local.owner != serial || !local.frame) {
            local.frame = std::make_unique<PixelFrame>();
            local.owner = serial;
        }
        return *local.frame;
    }

    static std::uint64_t nextSerial() {
        static std::atomic<std::uint64_t> counter{0};
        return ++counter;
    }
    const std::uint64_t serial = nextSerial(); // identifies this field in the threads' frames

    mutable std::vector<std::atomic<const DirectionTile*>> tiles;
};

} // namespace detail

namespace {

// One of the four pixels around a sample position, as DirectionField::sample reads it.
struct NeighbourPixel {
    const Eigen::Vector2d* direction = nullptr; // null: outside the image
    float anisotropy = 0;
    bool valid = false;
};

// The 2×2 pixels (x0 + i, y0 + j), i, j ∈ {0, 1}, at index i + 2j.
using PixelQuad = std::array<NeighbourPixel, 4>;

// Pixel access for DirectionField::sample: the stored arrays.
struct StoredPixels {
    const DirectionField& f;
    void quad(int x0, int y0, PixelQuad& q) const {
        for (int k = 0; k < 4; ++k) {
            const int x = x0 + (k & 1), y = y0 + (k >> 1);
            if (!f.inside(x, y)) continue;
            const std::size_t i = f.index(x, y);
            q[std::size_t(k)] = {&f.direction[i], f.anisotropy[i], f.valid[i] != 0};
        }
    }
};

// Pixel access for DirectionField::sample: the tiles of a lazy field (one tile lookup when the four pixels
// share a tile, as they mostly do).
struct TiledPixels {
    const detail::LazyDirectionTiles& tiles;
    int width, height;
    static NeighbourPixel of(const DirectionPixel& px) { return {&px.direction, px.anisotropy, px.valid}; }
    void quad(int x0, int y0, PixelQuad& q) const {
        if (x0 >= 0 && y0 >= 0 && x0 + 1 < width && y0 + 1 < height) {
            const int tx = tiles.tileIndex(x0), ty = tiles.tileIndex(y0);
            if (tiles.tileIndex(x0 + 1) == tx && tiles.tileIndex(y0 + 1) == ty) {
                const DirectionTile& t = tiles.tile(tx, ty);
                const DirectionPixel* row0 = &t.at(x0, y0);
                const DirectionPixel* row1 = row0 + t.w;
                q = {of(row0[0]), of(row0[1]), of(row1[0]), of(row1[1])};
                return;
            }
        }
        for (int k = 0; k < 4; ++k) {
            const int x = x0 + (k & 1), y = y0 + (k >> 1);
            if (x >= 0 && y >= 0 && x < width && y < height)
                q[std::size_t(k)] = of(tiles.tileOf(x, y).at(x, y));
        }
    }
};

// DirectionField::sample on either storage (see its documentation).
template <class Pixels>
std::optional<DirectionSample> bilinearSample(const Pixels& pixels, int width, int height,
                                              const Eigen::Vector2d& pos, const Eigen::Vector2d& reference,
                                              double straightBelow) {
    if (!(pos.x() >= 0 && pos.y() >= 0 && pos.x() <= width && pos.y() <= height)) return std::nullopt;
    // The pixel containing pos decides coverage (so background stops are pixel-exact).
    const int cx = std::min(int(pos.x()), width - 1), cy = std::min(int(pos.y()), height - 1);
    if (cx < 0 || cy < 0) return std::nullopt;
    // Bilinear weights between the four nearest pixel centres (x0 + i, y0 + j). The containing pixel is one
    // of them: x0 ≤ cx ≤ x0 + 1 (pos − ½ rounds to within [pos − 1, pos]), likewise in y.
    const double gx = pos.x() - 0.5, gy = pos.y() - 0.5;
    const int x0 = int(std::floor(gx)), y0 = int(std::floor(gy));
    PixelQuad quad;
    pixels.quad(x0, y0, quad);
    const NeighbourPixel& containing = quad[std::size_t((cx - x0) + 2 * (cy - y0))];
    if (!containing.valid) return std::nullopt;
    const double fx = gx - x0, fy = gy - y0;
    // The unit reference is needed only where a low-anisotropy neighbour is bent towards it.
    std::optional<Eigen::Vector2d> unitReference;
    auto unitRef = [&]() -> const Eigen::Vector2d& {
        if (!unitReference) unitReference = reference.normalized();
        return *unitReference;
    };
    Eigen::Vector2d dir = Eigen::Vector2d::Zero();
    double aniso = 0, weight = 0;
    for (int k = 0; k < 4; ++k) {
        const NeighbourPixel& px = quad[std::size_t(k)];
        if (!px.valid) continue; // invalid or outside the image
        const double w = ((k & 1) ? fx : 1 - fx) * ((k & 2) ? fy : 1 - fy);
        if (w <= 0) continue;
        const double a = double(px.anisotropy);
        // Line field: flip to agree with the reference (a multiplication by ±1, exact, without a branch
        // that a line field's arbitrary signs would mispredict).
        Eigen::Vector2d d = (1.0 - 2.0 * double(px.direction->dot(reference) < 0)) * *px.direction;
        if (straightBelow > 0 && a < 2 * straightBelow) {
            const double f = std::clamp((a - straightBelow) / straightBelow, 0.0, 1.0);
            d = f * d + (1 - f) * unitRef();
        }
        // Well-defined directions dominate ill-defined ones; the floor keeps an all-isotropic
        // neighbourhood (a plane, anisotropy 0) a plain bilinear average.
        dir += (w * std::max(a, kMinDirectionWeight)) * d;
        aniso += w * a;
        weight += w;
    }
    if (weight <= 0) {
        // pos sits exactly on the containing pixel's far edge with zero weight everywhere else.
        if (straightBelow > 0 && double(containing.anisotropy) < straightBelow)
            return DirectionSample{unitRef(), double(containing.anisotropy)};
        const Eigen::Vector2d& d = *containing.direction;
        return DirectionSample{d.dot(reference) < 0 ? Eigen::Vector2d(-d) : d, double(containing.anisotropy)};
    }
    const double len = dir.norm();
    if (!(len > 1e-12)) return std::nullopt;
    return DirectionSample{dir / len, aniso / weight};
}

} // namespace

DirectionField::DirectionField(int w, int h) : width(w), height(h) {
    if (w < 0 || h < 0) throw InvalidInputError("A direction field cannot have a negative size.");
    const std::size_t n = std::size_t(w) * std::size_t(h);
    direction.assign(n, Eigen::Vector2d::Zero());
    anisotropy.assign(n, 0.0f);
    valid.assign(n, 0);
}

DirectionPixel DirectionField::pixel(int x, int y) const {
    if (lazy_) return lazy_->tileOf(x, y).at(x, y);
    const std::size_t i = index(x, y);
    return {direction[i], anisotropy[i], valid[i] != 0};
}

void DirectionField::setPixel(int x, int y, const Eigen::Vector2d& dir, double aniso) {
    if (lazy_) throw InvalidInputError("The pixels of a lazy direction field are computed, not set.");
    const std::size_t i = index(x, y);
    valid[i] = storePixel(direction[i], anisotropy[i], dir, aniso) ? 1 : 0;
}

std::size_t DirectionField::validCount() const {
    std::size_t n = 0;
    if (lazy_) {
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                n += pixel(x, y).valid;
        return n;
    }
    for (auto v : valid)
        n += v != 0;
    return n;
}

std::size_t DirectionField::computedPixels() const {
    return lazy_ ? lazy_->computedPixels() : std::size_t(width) * std::size_t(height);
}

std::optional<DirectionSample> DirectionField::sample(const Eigen::Vector2d& pos,
                                                      const Eigen::Vector2d& reference,
                                                      double straightBelow) const {
    if (lazy_)
        return bilinearSample(TiledPixels{*lazy_, width, height}, width, height, pos, reference,
                              straightBelow);
    return bilinearSample(StoredPixels{*this}, width, height, pos, reference, straightBelow);
}

namespace {

// Fills the requested stored fields (either pointer may be null) in one pass over the pixels: the face
// lookup, the ray/plane point and the barycentric coordinates are shared by both principal directions.
void fillDirectionFields(const Mesh& mesh, const CurvatureField& curvature, const FrameBuffers& buffers,
                         DirectionField* minField, DirectionField* maxField) {
    const FieldSource source(mesh, curvature, buffers);
    const int width = source.width(), height = source.height();
    if (minField) *minField = DirectionField(width, height);
    if (maxField) *maxField = DirectionField(width, height);
    // Rows in blocks, one per thread (parallel.h): every pixel is computed on its own.
    detail::parallelRows(height, detail::rowBlocks(height, 16), [&](int, int rowBegin, int rowEnd) {
        PixelFrame fr;
        Eigen::Vector2d screen;
        double aniso = 0;
        for (int y = rowBegin; y < rowEnd; ++y)
            for (int x = 0; x < width; ++x) {
                if (!source.frame(x, y, fr)) continue;
                for (DirectionField* field : {minField, maxField})
                    if (field && source.direction(fr, field == maxField, screen, aniso))
                        field->setPixel(x, y, screen, aniso);
            }
    });
}

} // namespace

DirectionField computeDirectionField(const Mesh& mesh, const CurvatureField& curvature,
                                     const FrameBuffers& buffers, const DirectionFieldOptions& options) {
    DirectionField field;
    if (options.direction == PrincipalDirection::Max)
        fillDirectionFields(mesh, curvature, buffers, nullptr, &field);
    else
        fillDirectionFields(mesh, curvature, buffers, &field, nullptr);
    return field;
}

DirectionFieldPair computeDirectionFields(const Mesh& mesh, const CurvatureField& curvature,
                                          const FrameBuffers& buffers) {
    DirectionFieldPair pair;
    fillDirectionFields(mesh, curvature, buffers, &pair.min, &pair.max);
    return pair;
}

DirectionField lazyDirectionField(const Mesh& mesh, const CurvatureField& curvature,
                                  const FrameBuffers& buffers, const LazyDirectionFieldOptions& options) {
    if (options.tileSize < 1)
        throw InvalidInputError("The tile size of a lazy direction field must be at least 1 pixel, not " +
                                std::to_string(options.tileSize) + ".");
    DirectionField field;
    field.lazy_ = std::make_shared<const detail::LazyDirectionTiles>(
        mesh, curvature, buffers, options.direction == PrincipalDirection::Max, options.tileSize);
    field.width = buffers.camera.width;
    field.height = buffers.camera.height;
    return field;
}

} // namespace fss
