// Head-less quality pictures (snapshot.h): ID buffer → flat-shaded face colours → PNG (VTK).
#include "fss/render/snapshot.h"

#include "fss/error.h"
#include "fss/scan_pipeline.h"

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <numbers>
#include <system_error>
#include <unistd.h>

namespace fss::render {
namespace {

Eigen::Vector3d toEigen(const Point3& p) {
    return {p.x(), p.y(), p.z()};
}

double cornerAngleDeg(const Eigen::Vector3d& at, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const Eigen::Vector3d u = a - at, v = b - at;
    const double lu = u.norm(), lv = v.norm();
    if (lu == 0 || lv == 0) return 0;
    return std::acos(std::clamp(u.dot(v) / (lu * lv), -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

} // namespace

std::size_t Image::countDifferentFrom(const Rgb& colour) const {
    std::size_t n = 0;
    for (std::size_t i = 0; i + 2 < rgb.size(); i += 3)
        n += rgb[i] != colour[0] || rgb[i + 1] != colour[1] || rgb[i + 2] != colour[2];
    return n;
}

std::vector<Rgb> minAngleFaceColors(const Mesh& mesh) {
    std::vector<Rgb> colors(mesh.num_faces(), Rgb{128, 128, 128});
    for (FaceIndex f : mesh.faces()) {
        std::array<Eigen::Vector3d, 3> p;
        int k = 0;
        for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
            if (k == 3) break;
            p[std::size_t(k++)] = toEigen(mesh.point(v));
        }
        if (k < 3) continue;
        const double a = std::min({cornerAngleDeg(p[0], p[1], p[2]), cornerAngleDeg(p[1], p[2], p[0]),
                                   cornerAngleDeg(p[2], p[0], p[1])});
        colors[f.idx()] = minAngleColor(a);
    }
    return colors;
}

Image shadeFaces(const Mesh& mesh, const FrameBuffers& buffers, const std::vector<Rgb>& faceColors,
                 const SnapshotOptions& options) {
    const int w = buffers.width(), h = buffers.height();
    if (w <= 0 || h <= 0 || buffers.faceId.size() != std::size_t(w) * std::size_t(h))
        throw InvalidInputError("The snapshot's face-id buffer does not match its camera's image size.");
    const double ambient = std::clamp(options.ambient, 0.0, 1.0);
    const double outline = std::clamp(options.outline, 0.0, 1.0);
    Image image;
    image.width = w;
    image.height = h;
    image.rgb.resize(std::size_t(w) * std::size_t(h) * 3);
    // Unit normals of the faces seen, computed once per face.
    std::vector<Eigen::Vector3d> normal(faceColors.size(), Eigen::Vector3d::Zero());
    std::vector<std::uint8_t> haveNormal(faceColors.size(), 0);
    const Camera& camera = buffers.camera;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
            std::uint8_t* out = &image.rgb[3 * i];
            const std::uint32_t id = buffers.faceId[i];
            if (id == FrameBuffers::kNoFace) {
                std::copy(options.background.begin(), options.background.end(), out);
                continue;
            }
            if (id >= faceColors.size() || id >= mesh.num_faces())
                throw InvalidInputError("The snapshot's face-id buffer names face " + std::to_string(id) +
                                        ", which the mesh does not have.");
            if (!haveNormal[id]) {
                const FaceIndex f(id);
                std::array<Eigen::Vector3d, 3> p;
                int k = 0;
                for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
                    if (k == 3) break;
                    p[std::size_t(k++)] = toEigen(mesh.point(v));
                }
                const Eigen::Vector3d n = (p[1] - p[0]).cross(p[2] - p[0]);
                normal[id] = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
                haveNormal[id] = 1;
            }
            const double cosine = std::abs(normal[id].dot(camera.ray(x + 0.5, y + 0.5).direction));
            double factor = ambient + (1 - ambient) * cosine;
            const bool border = (x + 1 < w && buffers.faceId[i + 1] != id &&
                                 buffers.faceId[i + 1] != FrameBuffers::kNoFace) ||
                                (y + 1 < h && buffers.faceId[i + std::size_t(w)] != id &&
                                 buffers.faceId[i + std::size_t(w)] != FrameBuffers::kNoFace);
            if (border) factor *= outline;
            const Rgb& c = faceColors[id];
            for (int k = 0; k < 3; ++k)
                out[k] = std::uint8_t(std::lround(std::clamp(c[std::size_t(k)] * factor, 0.0, 255.0)));
            if (out[0] == options.background[0] && out[1] == options.background[1] &&
                out[2] == options.background[2])
                out[0] = std::uint8_t(out[0] == 0 ? 1 : out[0] - 1);
        }
    return image;
}

Snapshot renderSnapshot(const Mesh& mesh, const Camera& camera, const SnapshotOptions& options) {
    if (mesh.number_of_faces() == 0) throw InvalidInputError("The mesh to picture has no faces.");
    camera.validate();
    Snapshot snapshot;
    const std::unique_ptr<MeshRenderer> renderer = makeRenderer(options.renderer);
    renderer->setMesh(mesh);
    const FrameBuffers buffers = renderer->render(camera);
    snapshot.renderer = rendererDescription(*renderer);
    snapshot.covered = buffers.coveredCount();
    if (snapshot.covered == 0) throw InvalidInputError("The snapshot camera sees no part of the mesh.");
    snapshot.image = shadeFaces(mesh, buffers, minAngleFaceColors(mesh), options);
    if (options.legend)
        snapshot.image = appendRight(snapshot.image, renderMinAngleLegend(legendWidth(camera.height),
                                                                          camera.height, options.background));
    return snapshot;
}

void writePng(const Image& image, const std::filesystem::path& path) {
    if (image.width <= 0 || image.height <= 0)
        throw InvalidInputError("The image to write to " + path.string() + " is empty.");
    if (image.rgb.size() != std::size_t(image.width) * std::size_t(image.height) * 3)
        throw InvalidInputError("The image to write to " + path.string() + " has " +
                                std::to_string(image.rgb.size()) + " bytes, not 3 per pixel.");
    const std::filesystem::path tmp = path.string() + ".tmp" + std::to_string(::getpid()) + ".png";
    {
        // VTK reports a failed open only through its error log: find out here, with a clear sentence.
        std::ofstream probe(tmp, std::ios::binary | std::ios::trunc);
        if (!probe)
            throw IoError("The picture " + path.string() +
                          " cannot be written (cannot create a file there).");
    }
    vtkNew<vtkImageData> data;
    data->SetDimensions(image.width, image.height, 1);
    data->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
    auto* dst = static_cast<std::uint8_t*>(data->GetScalarPointer());
    const std::size_t row = std::size_t(image.width) * 3;
    for (int y = 0; y < image.height; ++y) // VTK images start at the bottom row
        std::copy_n(&image.rgb[std::size_t(image.height - 1 - y) * row], row, dst + std::size_t(y) * row);
    vtkNew<vtkPNGWriter> writer;
    writer->SetFileName(tmp.c_str());
    writer->SetInputData(data);
    writer->Write();
    std::error_code ec;
    if (writer->GetErrorCode() != 0 || std::filesystem::file_size(tmp, ec) == 0) {
        std::filesystem::remove(tmp, ec);
        throw IoError("The picture " + path.string() + " could not be written (PNG encoder error).");
    }
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        std::filesystem::remove(tmp, ec);
        throw IoError("The picture " + path.string() + " cannot be written (" + ec.message() + ").");
    }
}

Image readPng(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        throw IoError("The picture " + path.string() + " does not exist.");
    vtkNew<vtkPNGReader> reader;
    if (reader->CanReadFile(path.c_str()) == 0)
        throw IoError("The file " + path.string() + " is not a PNG picture.");
    reader->SetFileName(path.c_str());
    reader->Update();
    vtkImageData* data = reader->GetOutput();
    int dims[3] = {0, 0, 0};
    data->GetDimensions(dims);
    const int components = data->GetNumberOfScalarComponents();
    if (reader->GetErrorCode() != 0 || dims[0] <= 0 || dims[1] <= 0 ||
        data->GetScalarType() != VTK_UNSIGNED_CHAR || components < 1 || components > 4)
        throw IoError("The picture " + path.string() + " is not a readable 8-bit PNG.");
    Image image;
    image.width = dims[0];
    image.height = dims[1];
    image.rgb.resize(std::size_t(dims[0]) * std::size_t(dims[1]) * 3);
    const auto* src = static_cast<const std::uint8_t*>(data->GetScalarPointer());
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            const std::uint8_t* s =
                src + (std::size_t(image.height - 1 - y) * std::size_t(image.width) + std::size_t(x)) *
                          std::size_t(components);
            std::uint8_t* d = &image.rgb[3 * (std::size_t(y) * std::size_t(image.width) + std::size_t(x))];
            if (components <= 2)
                d[0] = d[1] = d[2] = s[0];
            else
                std::copy_n(s, 3, d);
        }
    return image;
}

} // namespace fss::render
