#pragma once
// The set-up of the stitching property test (stitch_property_test.cpp): a z-buffer rasterizer standing in
// for the GPU renderer, and the random scans (views, resolutions, lassos, morphology) it chains.
#include "fss/camera_projector.h"
#include "fss/scan_pipeline.h"

#include "stitch_helpers.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <sstream>
#include <string>

namespace stitch_property_setup {

using stitch_test_helpers::vec;

// A z-buffer rasterizer standing in for the GPU renderer (fss::render::Rasterizer): per pixel centre the
// nearest face covering it (closed edge functions in double), depth interpolated affinely on the screen
// (window depth is affine there) and stored as float like the GPU's. O(faces + covered pixels) per render,
// much cheaper than CpuMeshRenderer's ray casting, which keeps this test within its CPU budget. The scan
// snaps every sample onto the plane of the face under it, so the depth precision does not matter.
class ZBufferRenderer final : public fss::MeshRenderer {
public:
    void setMesh(const Mesh& mesh) override { mesh_ = &mesh; }
    fss::FrameBuffers render(const Camera& camera) override {
        Camera cam = camera;
        cam.fitClippingRange(fss::boundingBox(*mesh_));
        cam.validate();
        const fss::CameraProjector proj(cam);
        const int W = cam.width, H = cam.height;
        fss::FrameBuffers fb;
        fb.camera = cam;
        std::vector<double> depth(std::size_t(W) * std::size_t(H), 2.0);
        fb.faceId.assign(depth.size(), fss::FrameBuffers::kNoFace);
        for (FaceIndex f : mesh_->faces()) {
            Vec3 s[3];
            int k = 0;
            bool ok = true;
            for (auto v : CGAL::vertices_around_face(mesh_->halfedge(f), *mesh_)) {
                const Vec3 p = vec(mesh_->point(v));
                if (proj.viewDepth(p) <= cam.nearPlane) ok = false;
                s[k++] = proj.project(p);
            }
            if (!ok) continue;
            stitch_test_helpers::forEachCoveredPixel(s, W, H, [&](int x, int y, double z) {
                if (!(z >= 0 && z <= 1)) return;
                const std::size_t i = std::size_t(y) * std::size_t(W) + std::size_t(x);
                if (z < depth[i]) {
                    depth[i] = z;
                    fb.faceId[i] = std::uint32_t(f);
                }
            });
        }
        fb.depth.resize(depth.size());
        for (std::size_t i = 0; i < depth.size(); ++i)
            fb.depth[i] = depth[i] <= 1.0 ? float(depth[i]) : 1.0f;
        return fb;
    }

private:
    const Mesh* mesh_ = nullptr;
};

// ---- the scan setup: random views, resolutions, lassos, morphology
struct ScanSetup {
    Camera camera;
    std::optional<fss::Lasso> lasso;
    int erode = 0, dilate = 0;
    bool forceReplace = false;
    std::string text;
};

inline Vec3 randomDirection(std::mt19937& rng) {
    std::normal_distribution<double> N(0, 1);
    Vec3 d;
    do
        d = Vec3(N(rng), N(rng), N(rng));
    while (d.norm() < 1e-3);
    return d.normalized();
}

inline ScanSetup randomSetup(std::mt19937& rng, const Eigen::AlignedBox3d& box, int maxRes) {
    std::uniform_real_distribution<double> U(0, 1);
    ScanSetup s;
    // Resolution log-uniform in [32, maxRes].
    const int res =
        int(std::lround(std::exp(std::log(32.0) + U(rng) * (std::log(double(maxRes)) - std::log(32.0)))));
    const int W = std::clamp(int(res * (0.8 + 0.4 * U(rng))), 32, maxRes), H = res;
    Camera& c = s.camera;
    c.width = W;
    c.height = H;
    c.viewAngleDeg = 20 + 20 * U(rng);
    c.parallel = U(rng) < 0.15;
    const Vec3 centre = box.center(), half = 0.5 * box.sizes();
    const double radius = half.norm();
    const double zoom = std::exp(U(rng) * std::log(2.5)); // 1: whole object; 2.5: a part of it
    const Vec3 focal =
        centre + (1.0 - 1.0 / zoom) * half.cwiseProduct(Vec3(2 * U(rng) - 1, 2 * U(rng) - 1, 2 * U(rng) - 1));
    const Vec3 dir = randomDirection(rng);
    const double fit = radius / std::sin(0.5 * c.viewAngleDeg * std::numbers::pi / 180.0);
    c.focal = focal;
    c.eye = focal + dir * std::max(fit / zoom, 1.8 * radius); // outside the bounding sphere
    c.parallelScale = radius / zoom;
    // The pixel footprint at the focal point is at least diag / 100 (a high resolution widens the view
    // instead): the chained mesh then converges to about the density of a 100² scan of the whole object and
    // stays small enough for hundreds of scans with full checks after each.
    {
        const double minFootprint = 2 * radius / 100 * (1 + U(rng));
        const double fp = c.pixelFootprint(focal);
        if (fp < minFootprint) {
            c.eye = focal + (c.eye - focal) * (minFootprint / fp);
            c.parallelScale *= minFootprint / fp;
        }
    }
    do
        c.up = randomDirection(rng);
    while (c.up.cross(dir).norm() < 0.2);
    c.fitClippingRange(box);
    // Lasso: none, a star-shaped polygon, or random points (often self-intersecting), or a pentagram.
    const double kind = U(rng);
    std::ostringstream t;
    t << "res " << W << "x" << H << (c.parallel ? " parallel" : " perspective") << " zoom " << zoom;
    // Lassos of high-resolution scans select a detail (at most about as many samples as a 160² scan of the
    // whole view) to keep the patches of comparable size.
    const double detail = std::min(1.0, 160.0 / res);
    if (kind < 0.15 && res <= 160) {
        t << " no lasso";
    } else {
        fss::Lasso l;
        // Around a point of the object's image (its bounding sphere's projection).
        const Vec3 cp = c.project(centre);
        const double objectPixels = std::min(0.5 * std::min(W, H), radius / c.pixelFootprint(centre));
        const Eigen::Vector2d m(std::clamp(cp.x() + objectPixels * (1.2 * U(rng) - 0.6), 0.0, double(W)),
                                std::clamp(cp.y() + objectPixels * (1.2 * U(rng) - 0.6), 0.0, double(H)));
        const double r = std::max(3.0, std::min(std::min(W, H) * (0.15 + 0.45 * U(rng)) * detail,
                                                objectPixels * (0.3 + 0.7 * U(rng))));
        if (kind < 0.6) {
            const int n = 3 + int(U(rng) * 10);
            std::vector<double> angles(std::size_t(n), 0);
            for (auto& a : angles)
                a = 2 * std::numbers::pi * U(rng);
            std::sort(angles.begin(), angles.end());
            for (double a : angles) {
                const double rr = r * (0.3 + 0.7 * U(rng));
                l.points.push_back(m + rr * Eigen::Vector2d(std::cos(a), std::sin(a)));
            }
            t << " star lasso " << n;
        } else if (kind < 0.9) {
            const int n = 4 + int(U(rng) * 6);
            for (int i = 0; i < n; ++i)
                l.points.push_back(m + r * Eigen::Vector2d(2 * U(rng) - 1, 2 * U(rng) - 1));
            t << " random lasso " << n;
        } else {
            const double a0 = 2 * std::numbers::pi * U(rng);
            for (int i = 0; i < 5; ++i) {
                const double a = a0 + 4 * std::numbers::pi * i / 5.0;
                l.points.push_back(m + r * Eigen::Vector2d(std::cos(a), std::sin(a)));
            }
            t << " pentagram lasso";
        }
        s.lasso = std::move(l);
    }
    // Half of the scans force the replacement (QualityMaskOptions::forceReplace): with the footprint
    // floor above, the quality mask alone would soon reject almost every scan.
    s.forceReplace = U(rng) < 0.5;
    t << (s.forceReplace ? " force-replace" : "");
    s.erode = int(U(rng) * 4);
    s.dilate = int(U(rng) * 4);
    t << " erode " << s.erode << " dilate " << s.dilate;
    s.text = t.str();
    return s;
}

} // namespace stitch_property_setup
