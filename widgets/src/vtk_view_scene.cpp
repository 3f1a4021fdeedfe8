// VtkView: the shown meshes (mesh, ghost, preview), their colour maps and legend, edges, axes and the
// overlay (vtk_view_impl.h holds what VtkView's files share).
#include "vtk_view_impl.h"

namespace fss::widgets {

namespace {

double cornerAngleDeg(const Point3& at, const Point3& a, const Point3& b) {
    const Vector3 u = a - at, v = b - at;
    const double lu = std::sqrt(u.squared_length()), lv = std::sqrt(v.squared_length());
    if (lu == 0 || lv == 0) return 0;
    return std::acos(std::clamp((u * v) / (lu * lv), -1.0, 1.0)) * 180.0 / M_PI;
}

// The live vertices and faces of \p mesh as VTK points and polygons (dense VTK ids, faces in the order of
// mesh.faces(), so VTK cell i is the i-th live face). Extends \p bounds by every point when given.
vtkSmartPointer<vtkPolyData> toPolyData(const Mesh& mesh, Eigen::AlignedBox3d* bounds = nullptr) {
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    points->Allocate(vtkIdType(mesh.number_of_vertices()));
    std::vector<vtkIdType> pointId(mesh.num_vertices(), -1); // num_vertices counts removed ones too
    for (VertexIndex v : mesh.vertices()) {
        const Point3& p = mesh.point(v);
        pointId[std::size_t(v)] = points->InsertNextPoint(p.x(), p.y(), p.z());
        if (bounds) bounds->extend(Eigen::Vector3d(p.x(), p.y(), p.z()));
    }
    vtkNew<vtkCellArray> polys;
    polys->AllocateEstimate(vtkIdType(mesh.number_of_faces()), 3);
    std::vector<vtkIdType> ids;
    for (FaceIndex f : mesh.faces()) {
        ids.clear();
        for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f)))
            ids.push_back(pointId[std::size_t(v)]);
        polys->InsertNextCell(vtkIdType(ids.size()), ids.data());
    }
    auto polyData = vtkSmartPointer<vtkPolyData>::New();
    polyData->SetPoints(points);
    polyData->SetPolys(polys);
    return polyData;
}

} // namespace

QColor scanIdColor(int scanId) {
    const render::Rgb c = render::scanIdColor(scanId);
    return QColor(c[0], c[1], c[2]);
}

std::optional<ColorMap> parseColorMap(std::string_view name) {
    if (name == "none") return ColorMap::None;
    if (name == "angle" || name == "min-angle") return ColorMap::MinAngle;
    if (name == "valence") return ColorMap::Valence;
    if (name == "scan-id") return ColorMap::ScanId;
    return std::nullopt;
}

QString colorMapName(ColorMap map) {
    switch (map) {
    case ColorMap::None:
        return QStringLiteral("none");
    case ColorMap::MinAngle:
        return QStringLiteral("angle");
    case ColorMap::Valence:
        return QStringLiteral("valence");
    case ColorMap::ScanId:
        return QStringLiteral("scan-id");
    }
    return {};
}

void VtkView::setMesh(const Mesh& mesh) {
    auto& d = *impl_;
    d.bounds.setEmpty();
    vtkSmartPointer<vtkPolyData> fresh = toPolyData(mesh, &d.bounds);

    // Per-face measures for the colour maps, in the order of mesh.faces() (= VTK cell order).
    d.faceMinAngle.clear();
    d.faceValenceDeviation.clear();
    d.faceScanId.clear();
    d.faceMinAngle.reserve(mesh.number_of_faces());
    d.faceValenceDeviation.reserve(mesh.number_of_faces());
    d.faceScanId.reserve(mesh.number_of_faces());
    std::vector<int> deviation(mesh.num_vertices(), -1); // |valence − 6| of interior vertices, else −1
    for (VertexIndex v : mesh.vertices())
        if (!mesh.is_border(v) && !mesh.is_isolated(v))
            deviation[std::size_t(v)] = std::abs(int(mesh.degree(v)) - 6);
    const auto scanIds = mesh.property_map<FaceIndex, std::int32_t>(props::faceScanId);
    std::vector<Point3> corners;
    for (FaceIndex f : mesh.faces()) {
        corners.clear();
        int worst = -1;
        for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f))) {
            corners.push_back(mesh.point(v));
            worst = std::max(worst, deviation[std::size_t(v)]);
        }
        double minAngle = 180;
        const std::size_t n = corners.size();
        for (std::size_t i = 0; i < n; ++i)
            minAngle = std::min(minAngle,
                                cornerAngleDeg(corners[i], corners[(i + n - 1) % n], corners[(i + 1) % n]));
        d.faceMinAngle.push_back(minAngle);
        d.faceValenceDeviation.push_back(worst);
        d.faceScanId.push_back(scanIds.second ? scanIds.first[f] : -1);
    }
    d.polyData->ShallowCopy(fresh);
    d.applyColorMap();
    d.polyData->Modified();
    d.actor->SetVisibility(d.polyData->GetNumberOfCells() > 0);
    setStandardView(d.initialView);
}

void VtkView::clearMesh() {
    setMesh(Mesh{});
}

bool VtkView::hasMesh() const {
    return impl_->polyData->GetNumberOfCells() > 0;
}

void VtkView::setColorMap(ColorMap map) {
    impl_->colorMap = map;
    impl_->applyColorMap();
    impl_->polyData->Modified();
    update();
}

ColorMap VtkView::colorMap() const {
    return impl_->colorMap;
}

void VtkView::setLegendVisible(bool visible) {
    impl_->legendEnabled = visible;
    impl_->updateLegend();
    update();
}

bool VtkView::legendVisible() const {
    return impl_->legendEnabled;
}

bool VtkView::legendShown() const {
    return impl_->legend->GetVisibility() != 0;
}

void VtkView::setEdgesVisible(bool visible) {
    impl_->actor->GetProperty()->SetEdgeVisibility(visible);
    update();
}

bool VtkView::edgesVisible() const {
    return impl_->actor->GetProperty()->GetEdgeVisibility() != 0;
}

void VtkView::setAxesVisible(bool visible) {
    impl_->axesWidget->SetEnabled(visible);
    if (visible) impl_->axesWidget->InteractiveOff();
    update();
}

bool VtkView::axesVisible() const {
    return impl_->axesWidget->GetEnabled() != 0;
}

void VtkView::setOverlay(std::vector<OverlayPath> paths) {
    impl_->overlay = std::move(paths);
    update();
}

void VtkView::clearOverlay() {
    setOverlay({});
}

const std::vector<OverlayPath>& VtkView::overlay() const {
    return impl_->overlay;
}

void VtkView::setGhostMesh(const Mesh& reference) {
    auto& d = *impl_;
    if (reference.number_of_faces() == 0) {
        clearGhostMesh();
        return;
    }
    d.ghostMapper->SetInputData(toPolyData(reference));
    d.ghostActor->SetVisibility(d.ghostVisible);
    update();
}

void VtkView::clearGhostMesh() {
    auto& d = *impl_;
    d.ghostMapper->SetInputData(nullptr);
    d.ghostActor->VisibilityOff();
    update();
}

void VtkView::setGhostVisible(bool visible) {
    auto& d = *impl_;
    d.ghostVisible = visible;
    d.ghostActor->SetVisibility(visible && d.ghostMapper->GetInput() != nullptr);
    update();
}

bool VtkView::ghostVisible() const {
    return impl_->ghostActor->GetVisibility() != 0;
}

void VtkView::setPreviewMesh(const Mesh& patch) {
    setPreviewMesh(patch, {});
}

void VtkView::setPreviewMesh(const Mesh& patch, const std::vector<std::uint8_t>& stitched) {
    auto& d = *impl_;
    if (patch.number_of_faces() == 0) {
        clearPreviewMesh();
        return;
    }
    if (!stitched.empty() && stitched.size() != patch.num_faces())
        throw InvalidInputError("The preview's stitched-face flags do not match its faces.");
    vtkSmartPointer<vtkPolyData> data = toPolyData(patch);
    if (!stitched.empty()) {
        // Direct cell colours: VTK cell i is the i-th live face (toPolyData).
        vtkNew<vtkUnsignedCharArray> colours;
        colours->SetNumberOfComponents(3);
        colours->SetNumberOfTuples(vtkIdType(patch.number_of_faces()));
        vtkIdType cell = 0;
        for (FaceIndex f : patch.faces()) {
            const double* c = stitched[std::size_t(f)] ? kPreview : kPreviewTrimmed;
            for (int k = 0; k < 3; ++k)
                colours->SetValue(3 * cell + k, static_cast<unsigned char>(std::lround(255 * c[k])));
            ++cell;
        }
        data->GetCellData()->SetScalars(colours);
    }
    d.previewMapper->SetScalarVisibility(stitched.empty() ? 0 : 1);
    d.previewMapper->SetInputData(data);
    d.previewActor->VisibilityOn();
    update();
}

void VtkView::clearPreviewMesh() {
    auto& d = *impl_;
    d.previewMapper->SetInputData(nullptr);
    d.previewActor->VisibilityOff();
    update();
}

bool VtkView::hasPreviewMesh() const {
    return impl_->previewActor->GetVisibility() != 0;
}

} // namespace fss::widgets
