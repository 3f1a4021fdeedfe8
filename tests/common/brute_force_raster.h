#pragma once
// Test support: a brute-force CPU rasterizer producing FrameBuffers (depth + face id) for small meshes,
// so that core tests need neither VTK nor GL. Pixel centres (i+½, j+½) covered by a projected triangle
// (barycentric test, top-left ties not resolved: shared edges go to the first face drawn) get the face's
// interpolated window depth if it is nearer (z-test). Window depth is affine in screen space for
// perspective projections, so linear interpolation of the vertices' depths is exact.
#include "fss/camera.h"
#include "fss/frame_buffers.h"
#include "fss/mesh.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace fss::test {

inline FrameBuffers bruteForceRaster(const Mesh& mesh, const Camera& camera) {
    FrameBuffers fb;
    fb.camera = camera;
    const std::size_t n = std::size_t(camera.width) * std::size_t(camera.height);
    fb.depth.assign(n, 1.0f);
    fb.faceId.assign(n, FrameBuffers::kNoFace);
    std::vector<double> depth(n, 1.0);
    for (FaceIndex f : mesh.faces()) {
        std::array<Eigen::Vector3d, 3> s;
        int k = 0;
        bool behind = false;
        for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
            const auto& p = mesh.point(v);
            const Eigen::Vector3d w(p.x(), p.y(), p.z());
            behind = behind || camera.viewDepth(w) <= camera.nearPlane;
            s[std::size_t(k++)] = camera.project(w);
        }
        if (behind) continue;
        const double area =
            (s[1].x() - s[0].x()) * (s[2].y() - s[0].y()) - (s[2].x() - s[0].x()) * (s[1].y() - s[0].y());
        if (area == 0) continue;
        const int x0 = std::max(0, int(std::floor(std::min({s[0].x(), s[1].x(), s[2].x()}) - 0.5)));
        const int x1 = std::min(camera.width - 1, int(std::ceil(std::max({s[0].x(), s[1].x(), s[2].x()}))));
        const int y0 = std::max(0, int(std::floor(std::min({s[0].y(), s[1].y(), s[2].y()}) - 0.5)));
        const int y1 = std::min(camera.height - 1, int(std::ceil(std::max({s[0].y(), s[1].y(), s[2].y()}))));
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                const double px = x + 0.5, py = y + 0.5;
                auto edge = [&](int a, int b) {
                    return ((s[std::size_t(b)].x() - s[std::size_t(a)].x()) * (py - s[std::size_t(a)].y()) -
                            (px - s[std::size_t(a)].x()) * (s[std::size_t(b)].y() - s[std::size_t(a)].y())) /
                           area;
                };
                const double w0 = edge(1, 2), w1 = edge(2, 0), w2 = edge(0, 1);
                if (w0 < 0 || w1 < 0 || w2 < 0) continue;
                const double z = w0 * s[0].z() + w1 * s[1].z() + w2 * s[2].z();
                const std::size_t i = fb.index(x, y);
                if (z < 0 || z >= depth[i]) continue;
                depth[i] = z;
                fb.depth[i] = float(z);
                fb.faceId[i] = std::uint32_t(f.idx());
            }
    }
    return fb;
}

} // namespace fss::test
