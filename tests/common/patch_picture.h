#pragma once
// Pictures of patches for tests that write one (docs/): a flat-shaded z-buffered software rendering of a
// mesh with its edges darkened, and an RGB PNG writer with "stored" deflate blocks (no zlib needed).
#include "fss/camera.h"
#include "fss/mesh.h"

#include <CGAL/boost/graph/iterator.h>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

namespace fss::test {

inline std::uint32_t crc32(const std::uint8_t* data, std::size_t n, std::uint32_t crc = 0) {
    crc = ~crc;
    for (std::size_t i = 0; i < n; ++i) {
        crc ^= data[i];
        for (int k = 0; k < 8; ++k)
            crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

inline void put32(std::vector<std::uint8_t>& out, std::uint32_t x) {
    for (int s = 24; s >= 0; s -= 8)
        out.push_back(std::uint8_t(x >> s));
}

inline void chunk(std::vector<std::uint8_t>& out, const char* type, const std::vector<std::uint8_t>& data) {
    put32(out, std::uint32_t(data.size()));
    std::vector<std::uint8_t> body(type, type + 4);
    body.insert(body.end(), data.begin(), data.end());
    out.insert(out.end(), body.begin(), body.end());
    put32(out, crc32(body.data(), body.size()));
}

// An RGB PNG with "stored" (uncompressed) deflate blocks: no zlib needed.
inline void writePng(const std::string& path, int w, int h, const std::vector<std::uint8_t>& rgb) {
    std::vector<std::uint8_t> raw;
    for (int y = 0; y < h; ++y) {
        raw.push_back(0);
        raw.insert(raw.end(), rgb.begin() + std::ptrdiff_t(y) * w * 3,
                   rgb.begin() + std::ptrdiff_t(y + 1) * w * 3);
    }
    std::vector<std::uint8_t> z{0x78, 0x01};
    for (std::size_t pos = 0; pos < raw.size();) {
        const std::size_t n = std::min<std::size_t>(65535, raw.size() - pos);
        z.push_back(pos + n == raw.size() ? 1 : 0);
        z.push_back(std::uint8_t(n & 0xff));
        z.push_back(std::uint8_t(n >> 8));
        z.push_back(std::uint8_t(~n & 0xff));
        z.push_back(std::uint8_t((~n >> 8) & 0xff));
        z.insert(z.end(), raw.begin() + std::ptrdiff_t(pos), raw.begin() + std::ptrdiff_t(pos + n));
        pos += n;
    }
    std::uint32_t a = 1, b = 0;
    for (std::uint8_t c : raw) {
        a = (a + c) % 65521;
        b = (b + a) % 65521;
    }
    put32(z, (b << 16) | a);
    std::vector<std::uint8_t> out{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    std::vector<std::uint8_t> ihdr;
    put32(ihdr, std::uint32_t(w));
    put32(ihdr, std::uint32_t(h));
    ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0});
    chunk(out, "IHDR", ihdr);
    chunk(out, "IDAT", z);
    chunk(out, "IEND", {});
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(out.data()), std::streamsize(out.size()));
}

// Flat-shaded z-buffered rendering of \p mesh with \p camera into the rgb image at x offset \p x0, with
// the mesh edges darkened (so the grid's alignment with the crease is visible).
inline void renderShaded(const fss::Mesh& mesh, const fss::Camera& camera, std::vector<std::uint8_t>& rgb,
                         std::vector<double>& zbuf, int imageWidth, int x0,
                         const std::function<Eigen::Vector3d(fss::FaceIndex)>& tintOf) {
    const Eigen::Vector3d light = Eigen::Vector3d(1.0, 0.25, 0.6).normalized();
    const Eigen::Matrix4d vp = camera.viewProjectionMatrix();
    auto project = [&](const Eigen::Vector3d& p) {
        const Eigen::Vector4d c = vp * Eigen::Vector4d(p.x(), p.y(), p.z(), 1);
        return Eigen::Vector3d((c.x() / c.w() + 1) * 0.5 * camera.width,
                               (1 - c.y() / c.w()) * 0.5 * camera.height, c.z() / c.w());
    };
    for (auto f : mesh.faces()) {
        std::array<Eigen::Vector3d, 3> p, s;
        int k = 0;
        for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
            p[std::size_t(k)] = Eigen::Vector3d(mesh.point(v).x(), mesh.point(v).y(), mesh.point(v).z());
            s[std::size_t(k)] = project(p[std::size_t(k)]);
            ++k;
        }
        const Eigen::Vector3d n = (p[1] - p[0]).cross(p[2] - p[0]).normalized();
        const double shade = 0.15 + 0.85 * std::max(0.0, n.dot(light));
        const Eigen::Vector3d tint = tintOf(f);
        const int xmin = std::max(0, int(std::floor(std::min({s[0].x(), s[1].x(), s[2].x()}))));
        const int xmax = std::min(camera.width - 1, int(std::ceil(std::max({s[0].x(), s[1].x(), s[2].x()}))));
        const int ymin = std::max(0, int(std::floor(std::min({s[0].y(), s[1].y(), s[2].y()}))));
        const int ymax =
            std::min(camera.height - 1, int(std::ceil(std::max({s[0].y(), s[1].y(), s[2].y()}))));
        const double area =
            (s[1].x() - s[0].x()) * (s[2].y() - s[0].y()) - (s[2].x() - s[0].x()) * (s[1].y() - s[0].y());
        if (std::abs(area) < 1e-12) continue;
        for (int y = ymin; y <= ymax; ++y)
            for (int x = xmin; x <= xmax; ++x) {
                const double px = x + 0.5, py = y + 0.5;
                std::array<double, 3> w;
                for (int i = 0; i < 3; ++i) {
                    const Eigen::Vector3d& a = s[std::size_t((i + 1) % 3)];
                    const Eigen::Vector3d& b = s[std::size_t((i + 2) % 3)];
                    w[std::size_t(i)] =
                        ((b.x() - a.x()) * (py - a.y()) - (px - a.x()) * (b.y() - a.y())) / area;
                }
                if (w[0] < 0 || w[1] < 0 || w[2] < 0) continue;
                const double z = w[0] * s[0].z() + w[1] * s[1].z() + w[2] * s[2].z();
                const std::size_t idx = std::size_t(y) * std::size_t(imageWidth) + std::size_t(x0 + x);
                if (z >= zbuf[idx]) continue;
                zbuf[idx] = z;
                const bool edge =
                    std::min({w[0], w[1], w[2]}) * std::abs(area) /
                        std::max({(s[0] - s[1]).head<2>().norm(), (s[1] - s[2]).head<2>().norm(),
                                  (s[2] - s[0]).head<2>().norm()}) <
                    0.5;
                for (int c = 0; c < 3; ++c)
                    rgb[idx * 3 + std::size_t(c)] =
                        std::uint8_t(std::clamp(255.0 * shade * tint[c] * (edge ? 0.75 : 1.0), 0.0, 255.0));
            }
    }
}

// As above, every face in \p tint.
inline void renderShaded(const fss::Mesh& mesh, const fss::Camera& camera, std::vector<std::uint8_t>& rgb,
                         std::vector<double>& zbuf, int imageWidth, int x0, const Eigen::Vector3d& tint) {
    renderShaded(mesh, camera, rgb, zbuf, imageWidth, x0, [&](fss::FaceIndex) { return tint; });
}

} // namespace fss::test
