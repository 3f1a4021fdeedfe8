// Everything that talks to VTK for the FEM hand-off (fss/render/fem_io.h): VTU / VTP written by VTK's XML
// writers with the groups as integer cell data `group` and each group's name as a one-value integer field
// data array "group:<name>" holding its value (the convention meshio uses for names; a vtkStringArray would
// be the obvious choice, but meshio 5 refuses VTU files with String arrays, measured); VTU, VTP and legacy
// VTK files read by VTK's readers.
#include "fem_detail.h"

#include "fss/face_groups.h"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkDataSet.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkGenericCell.h>
#include <vtkIdList.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkSmartPointer.h>
#include <vtkType.h>
#include <vtkUnstructuredGrid.h>
#include <vtkUnstructuredGridReader.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <string_view>

namespace fs = std::filesystem;

namespace fss::render::detail {
namespace {

constexpr std::string_view kNamePrefix = "group:";

/// Collects VTK's error and warning texts instead of printing them (a bad file must give one sentence).
class QuietOutputWindow : public vtkOutputWindow {
public:
    static QuietOutputWindow* New();
    vtkTypeMacro(QuietOutputWindow, vtkOutputWindow);
    std::string firstError;
    void DisplayErrorText(const char* text) override {
        if (firstError.empty() && text) firstError = text;
    }
    void DisplayWarningText(const char*) override {}
    void DisplayGenericWarningText(const char*) override {}
    void DisplayText(const char*) override {}

protected:
    QuietOutputWindow() = default;
    ~QuietOutputWindow() override = default;
};
vtkStandardNewMacro(QuietOutputWindow);

/// VTK's process-wide output window replaced by a QuietOutputWindow for the lifetime of the object.
class ScopedQuietVtk {
public:
    ScopedQuietVtk() : previous_(vtkOutputWindow::GetInstance()) { vtkOutputWindow::SetInstance(quiet_); }
    ~ScopedQuietVtk() { vtkOutputWindow::SetInstance(previous_); }
    ScopedQuietVtk(const ScopedQuietVtk&) = delete;
    ScopedQuietVtk& operator=(const ScopedQuietVtk&) = delete;
    /// The last line of VTK's first error (the line that names the problem), or "".
    std::string error() const {
        std::string e = quiet_->firstError;
        while (!e.empty() && (e.back() == '\n' || e.back() == ' ' || e.back() == '.'))
            e.pop_back();
        const std::size_t nl = e.rfind('\n');
        return nl == std::string::npos ? e : e.substr(nl + 1);
    }

private:
    vtkSmartPointer<vtkOutputWindow> previous_;
    vtkNew<QuietOutputWindow> quiet_;
};

/// Points, the triangles' and edges' connectivity, cell data `group`, field data "group:<name>".
struct VtkParts {
    vtkNew<vtkPoints> points;
    vtkNew<vtkCellArray> triangles, lines;
    vtkNew<vtkIntArray> group;
    std::vector<vtkSmartPointer<vtkIntArray>> names;
};

void addName(VtkParts& v, const std::string& name, int value) {
    auto array = vtkSmartPointer<vtkIntArray>::New();
    array->SetName((std::string(kNamePrefix) + name).c_str());
    array->InsertNextValue(value);
    v.names.push_back(array);
}

void fill(const FemMesh& m, VtkParts& v) {
    v.points->SetDataTypeToDouble();
    v.points->SetNumberOfPoints(vtkIdType(m.nodes.size()));
    for (std::size_t i = 0; i < m.nodes.size(); ++i)
        v.points->SetPoint(vtkIdType(i), m.nodes[i].data());
    for (const auto& t : m.triangles) {
        const vtkIdType ids[3] = {vtkIdType(t[0]), vtkIdType(t[1]), vtkIdType(t[2])};
        v.triangles->InsertNextCell(3, ids);
    }
    for (const auto& e : m.edges) {
        const vtkIdType ids[2] = {vtkIdType(e[0]), vtkIdType(e[1])};
        v.lines->InsertNextCell(2, ids);
    }
    v.group->SetName("group");
    for (std::size_t g = 0; g < m.groupNames.size(); ++g)
        addName(v, m.groupNames[g], int(g));
    if (!m.edges.empty()) addName(v, m.edgeGroup, int(m.groupNames.size()));
}

template <class Writer>
void finishWrite(Writer* writer, const fs::path& path, const FemWriteOptions& options) {
    TempFile temp(path);
    writer->SetFileName(temp.path().string().c_str());
    if (options.vtkBinary) {
        writer->SetDataModeToBinary();
    } else {
        writer->SetDataModeToAscii();
    }
    if (writer->Write() != 1 || writer->GetErrorCode() != 0) failWrite(path, "VTK's XML writer failed");
    temp.commit();
}

/// The integer cell array `group`, or null when the data set has none. Anything else called `group` (not
/// integral, not one component) is a group syntax FSS does not know.
vtkDataArray* groupArray(vtkDataSet* data, const fs::path& path) {
    vtkAbstractArray* any = data->GetCellData()->GetAbstractArray("group");
    if (!any) return nullptr;
    auto* array = vtkDataArray::SafeDownCast(any);
    const int t = array ? array->GetDataType() : VTK_VOID;
    const bool integral = t == VTK_CHAR || t == VTK_SIGNED_CHAR || t == VTK_UNSIGNED_CHAR || t == VTK_SHORT ||
                          t == VTK_UNSIGNED_SHORT || t == VTK_INT || t == VTK_UNSIGNED_INT || t == VTK_LONG ||
                          t == VTK_UNSIGNED_LONG || t == VTK_LONG_LONG || t == VTK_UNSIGNED_LONG_LONG ||
                          t == VTK_ID_TYPE;
    if (!integral || array->GetNumberOfComponents() != 1)
        failRead(path, "its cell data 'group' is not one integer per cell, the only group syntax FSS reads");
    return array;
}

PolygonSoup toSoup(vtkDataSet* data, const fs::path& path) {
    PolygonSoup soup;
    const vtkIdType np = data->GetNumberOfPoints();
    soup.points.reserve(std::size_t(np));
    for (vtkIdType i = 0; i < np; ++i) {
        double p[3];
        data->GetPoint(i, p);
        soup.points.emplace_back(p[0], p[1], p[2]);
    }
    vtkDataArray* group = groupArray(data, path);
    std::map<long long, std::string> names;
    vtkFieldData* field = data->GetFieldData();
    for (int i = 0; field && i < field->GetNumberOfArrays(); ++i) {
        vtkDataArray* a = field->GetArray(i);
        const char* n = field->GetArrayName(i);
        if (!a || !n || a->GetNumberOfTuples() != 1 || a->GetNumberOfComponents() != 1) continue;
        const std::string_view name(n);
        if (name.substr(0, kNamePrefix.size()) == kNamePrefix && name.size() > kNamePrefix.size())
            names[static_cast<long long>(a->GetComponent(0, 0))] =
                std::string(name.substr(kNamePrefix.size()));
    }
    std::map<long long, std::int32_t> indexOfValue;
    vtkNew<vtkIdList> ids;
    const vtkIdType nc = data->GetNumberOfCells();
    for (vtkIdType c = 0; c < nc; ++c) {
        const int type = data->GetCellType(c);
        if (type == VTK_VERTEX || type == VTK_POLY_VERTEX || type == VTK_LINE || type == VTK_POLY_LINE)
            continue; // points and lines (e.g. feature edges) are not part of the surface
        if (type != VTK_TRIANGLE && type != VTK_QUAD && type != VTK_POLYGON && type != VTK_TRIANGLE_STRIP)
            failRead(path,
                     "its cell " + std::to_string(c) + " is of VTK cell type " + std::to_string(type) +
                         ", but FSS reads surfaces (vertices, lines, triangles, strips, quads, polygons)");
        data->GetCellPoints(c, ids);
        std::int32_t g = kNoGroup;
        if (group) {
            const double value = group->GetComponent(c, 0);
            if (value >= 0) {
                const auto key = static_cast<long long>(value);
                auto found = indexOfValue.find(key);
                if (found == indexOfValue.end()) {
                    const auto named = names.find(key);
                    found = indexOfValue.emplace(key, std::int32_t(soup.groupNames.size())).first;
                    soup.groupNames.push_back(named != names.end() && !named->second.empty()
                                                  ? named->second
                                                  : "group_" + std::to_string(key));
                }
                g = found->second;
            }
        }
        const vtkIdType n = ids->GetNumberOfIds();
        auto corner = [&](vtkIdType k) {
            const vtkIdType id = ids->GetId(k);
            if (id < 0 || id >= np)
                failRead(path, "its cell " + std::to_string(c) + " uses point " + std::to_string(id) +
                                   ", but there are only " + std::to_string(np) + " points");
            return std::size_t(id);
        };
        if (type == VTK_TRIANGLE_STRIP) {
            for (vtkIdType k = 0; k + 2 < n; ++k) {
                // Every other triangle of a strip is flipped to keep one orientation.
                std::vector<std::size_t> t{corner(k), corner(k + 1), corner(k + 2)};
                if (k % 2) std::swap(t[0], t[1]);
                soup.polygons.push_back(std::move(t));
                soup.groups.push_back(g);
            }
            continue;
        }
        std::vector<std::size_t> poly;
        for (vtkIdType k = 0; k < n; ++k)
            poly.push_back(corner(k));
        soup.polygons.push_back(std::move(poly));
        soup.groups.push_back(g);
    }
    if (soup.polygons.empty()) failRead(path, "it holds no surface cells (triangles, quads or polygons)");
    if (!group) soup.groups.clear();
    return soup;
}

template <class Reader> vtkSmartPointer<vtkDataSet> readWith(const fs::path& path) {
    vtkNew<Reader> reader;
    reader->SetFileName(path.string().c_str());
    reader->Update();
    vtkSmartPointer<vtkDataSet> out = reader->GetOutput();
    return out;
}

} // namespace

void writeVtk(const FemMesh& m, const fs::path& path, const FemWriteOptions& options) {
    VtkParts parts;
    fill(m, parts);
    const auto edgeGroup = std::int32_t(m.groupNames.size());
    if (lowerExtension(path) == ".vtu") {
        vtkNew<vtkUnstructuredGrid> grid;
        grid->SetPoints(parts.points);
        grid->Allocate(vtkIdType(m.triangles.size() + m.edges.size()));
        for (std::size_t t = 0; t < m.triangles.size(); ++t) {
            const vtkIdType ids[3] = {vtkIdType(m.triangles[t][0]), vtkIdType(m.triangles[t][1]),
                                      vtkIdType(m.triangles[t][2])};
            grid->InsertNextCell(VTK_TRIANGLE, 3, ids);
            parts.group->InsertNextValue(m.group[t]);
        }
        for (const auto& e : m.edges) {
            const vtkIdType ids[2] = {vtkIdType(e[0]), vtkIdType(e[1])};
            grid->InsertNextCell(VTK_LINE, 2, ids);
            parts.group->InsertNextValue(edgeGroup);
        }
        grid->GetCellData()->AddArray(parts.group);
        for (const auto& a : parts.names)
            grid->GetFieldData()->AddArray(a);
        vtkNew<vtkXMLUnstructuredGridWriter> writer;
        writer->SetInputData(grid);
        finishWrite(writer.Get(), path, options);
        return;
    }
    // Poly data orders cells as vertices, lines, polygons: the lines' group values come first.
    vtkNew<vtkPolyData> poly;
    poly->SetPoints(parts.points);
    poly->SetLines(parts.lines);
    poly->SetPolys(parts.triangles);
    for (std::size_t e = 0; e < m.edges.size(); ++e)
        parts.group->InsertNextValue(edgeGroup);
    for (std::int32_t g : m.group)
        parts.group->InsertNextValue(g);
    poly->GetCellData()->AddArray(parts.group);
    for (const auto& a : parts.names)
        poly->GetFieldData()->AddArray(a);
    vtkNew<vtkXMLPolyDataWriter> writer;
    writer->SetInputData(poly);
    finishWrite(writer.Get(), path, options);
}

PolygonSoup readVtk(const fs::path& path) {
    const std::string ext = lowerExtension(path);
    const ScopedQuietVtk quiet;
    vtkSmartPointer<vtkDataSet> data;
    if (ext == ".vtu") {
        vtkNew<vtkXMLUnstructuredGridReader> reader;
        if (!reader->CanReadFile(path.string().c_str()))
            failRead(path, "it is not a VTK XML unstructured grid");
        data = readWith<vtkXMLUnstructuredGridReader>(path);
    } else if (ext == ".vtp") {
        vtkNew<vtkXMLPolyDataReader> reader;
        if (!reader->CanReadFile(path.string().c_str())) failRead(path, "it is not a VTK XML poly data file");
        data = readWith<vtkXMLPolyDataReader>(path);
    } else {
        vtkNew<vtkUnstructuredGridReader> grid;
        grid->SetFileName(path.string().c_str());
        vtkNew<vtkPolyDataReader> polys;
        polys->SetFileName(path.string().c_str());
        if (grid->IsFileUnstructuredGrid())
            data = readWith<vtkUnstructuredGridReader>(path);
        else if (polys->IsFilePolyData())
            data = readWith<vtkPolyDataReader>(path);
        else
            failRead(path, "it is not a legacy VTK file of an unstructured grid or poly data");
    }
    if (!quiet.error().empty()) failRead(path, "VTK's reader reports: " + quiet.error());
    if (!data) failRead(path, "VTK's reader could not read it");
    return toSoup(data, path);
}

} // namespace fss::render::detail
