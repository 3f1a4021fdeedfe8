// The FEM hand-off (fss/render/fem_io.h, fss/face_groups.h, issue 22), checked against the field's own
// readers: every written file is read back by gmsh's API (MSH, UNV, BDF) or VTK's readers (VTU, VTP, legacy
// VTK) and by Debian's meshio (/usr/bin/python3) as an independent reader: node and element counts,
// coordinates, group names and sizes. The triangle quality measures of fss::computeMetrics are compared with
// vtkMeshQuality's on CGAL's meshes, and groups carried through a remeshing session keep their areas.
// The Nastran names and reals and the formats' limits: fem_nastran_test.cpp.
#include "fem_io_helpers.h"

using namespace fem_io_test_helpers;

namespace {

class FemRoundTrip : public ::testing::TestWithParam<std::string> {};

// Each format: written by FSS, read by the library's own reader and by meshio; counts, coordinates, group
// names and sizes equal.
TEST_P(FemRoundTrip, LibraryReadersAndMeshioSeeTheSameMesh) {
    const std::string ext = GetParam();
    const bool msh22 = ext == "msh22";
    const fs::path file = scratch("fandisk_groups." + (msh22 ? std::string("msh") : ext));
    const Mesh mesh = twoGroupFandisk();
    fss::render::FemWriteOptions options;
    options.featureEdges = true;
    options.featureAngleDeg = 45;
    if (msh22) options.mshVersion = 2.2;
    fss::render::writeMeshFile(mesh, file, options);
    const std::size_t edges = fss::sharpFeatureEdges(mesh, 45).size();
    ASSERT_GT(edges, 100u); // fandisk's creases
    const auto expected = facesPerGroup(mesh);
    const std::size_t faces = mesh.number_of_faces(), nodes = mesh.number_of_vertices();

    // The library's own reader.
    if (ext == "msh" || msh22 || ext == "unv" || ext == "bdf") {
        const GmshView g = readWithGmsh(file);
        EXPECT_EQ(g.nodes, nodes);
        EXPECT_EQ(g.triangles, faces);
        EXPECT_EQ(g.lines, edges);
        // gmsh's own parser of the coordinates (for BDF: of the Nastran reals without 'E').
        const double diag = fss::boundingBox(mesh).diagonal().norm();
        double worst = 0;
        std::size_t tag = 0;
        for (auto v : mesh.vertices()) {
            const auto& q = g.points.at(++tag);
            for (int k = 0; k < 3; ++k)
                worst = std::max(worst, std::abs(q[std::size_t(k)] - mesh.point(v)[k]));
        }
        EXPECT_LE(worst / diag, 1e-12) << ext;
        if (ext != "bdf") { // BDF holds PIDs, not names
            EXPECT_EQ(g.groups.at("upper"), expected.at("upper"));
            EXPECT_EQ(g.groups.at("lower"), expected.at("lower"));
            EXPECT_EQ(g.groups.at("feature_edges"), edges);
        } else { // gmsh makes each PID an elementary entity
            EXPECT_EQ(g.entities.at({2, 1}), expected.at("upper"));
            EXPECT_EQ(g.entities.at({2, 2}), expected.at("lower"));
            EXPECT_EQ(g.entities.at({1, 3}), edges);
        }
    }
    if (ext == "msh" || msh22 || ext == "vtu" || ext == "vtp") {
        // FSS's own reader (gmsh / VTK underneath) gives back the mesh with its groups.
        fss::ReadReport report;
        const Mesh back = fss::render::readMeshFile(file, &report);
        EXPECT_EQ(back.number_of_vertices(), nodes);
        EXPECT_EQ(back.number_of_faces(), faces);
        EXPECT_EQ(report.groups, 2u);
        EXPECT_EQ(facesPerGroup(back), expected);
        EXPECT_TRUE(report.repairs.empty());
    }
    if (ext == "vtu" || ext == "vtp") {
        vtkSmartPointer<vtkDataSet> data;
        if (ext == "vtu") {
            vtkNew<vtkXMLUnstructuredGridReader> r;
            r->SetFileName(file.c_str());
            r->Update();
            data = r->GetOutput();
        } else {
            vtkNew<vtkXMLPolyDataReader> r;
            r->SetFileName(file.c_str());
            r->Update();
            data = r->GetOutput();
        }
        ASSERT_NE(data.Get(), nullptr);
        EXPECT_EQ(std::size_t(data->GetNumberOfPoints()), nodes);
        EXPECT_EQ(std::size_t(data->GetNumberOfCells()), faces + edges);
        for (const auto& [name, value] : {std::pair<const char*, double>{"group:upper", 0},
                                          {"group:lower", 1},
                                          {"group:feature_edges", 2}}) {
            vtkDataArray* a = data->GetFieldData()->GetArray(name);
            ASSERT_NE(a, nullptr) << name;
            EXPECT_EQ(a->GetComponent(0, 0), value) << name;
        }
        std::size_t i = 0;
        double worst = 0;
        for (auto v : mesh.vertices()) {
            double p[3];
            data->GetPoint(vtkIdType(i++), p);
            for (int k = 0; k < 3; ++k)
                worst = std::max(worst, std::abs(p[k] - mesh.point(v)[k]));
        }
        EXPECT_EQ(worst, 0.0); // doubles, binary
    }

    // meshio (gmsh cannot read INP; meshio 5.0 reads neither UNV nor VTP).
    if (ext == "unv" || ext == "vtp") return;
    const nlohmann::json m = meshio(file);
    ASSERT_FALSE(m.is_null());
    expectSamePoints(mesh, m.at("points"), ext == "bdf" ? 1e-12 : 1e-15);
    EXPECT_EQ(m.at("cells").at("triangle").get<std::size_t>(), faces);
    EXPECT_EQ(m.at("cells").at("line").get<std::size_t>(), edges);
    const auto& groups = m.at("groups");
    if (ext == "bdf") {
        EXPECT_EQ(groups.at("pid_1").get<std::size_t>(), expected.at("upper"));
        EXPECT_EQ(groups.at("pid_2").get<std::size_t>(), expected.at("lower"));
        EXPECT_EQ(groups.at("pid_3").get<std::size_t>(), edges);
        expectNastranNameComments(fss::test::slurp(file), {{1, "upper"}, {2, "lower"}, {3, "feature_edges"}});
    } else if (ext == "vtu") {
        EXPECT_EQ(m.at("names").at("group:upper").get<int>(), 0);
        EXPECT_EQ(m.at("names").at("group:lower").get<int>(), 1);
        EXPECT_EQ(groups.at("value_0").get<std::size_t>(), expected.at("upper"));
        EXPECT_EQ(groups.at("value_1").get<std::size_t>(), expected.at("lower"));
        EXPECT_EQ(groups.at("value_2").get<std::size_t>(), edges);
    } else {
        EXPECT_EQ(groups.at("upper").get<std::size_t>(), expected.at("upper"));
        EXPECT_EQ(groups.at("lower").get<std::size_t>(), expected.at("lower"));
        EXPECT_EQ(groups.at("feature_edges").get<std::size_t>(), edges);
    }
}

INSTANTIATE_TEST_SUITE_P(Formats, FemRoundTrip,
                         ::testing::Values("msh", "msh22", "inp", "bdf", "unv", "vtu", "vtp"));

// The core formats keep the groups too: OBJ `g`, PLY `group` with named comments, multi-solid ascii STL.
TEST(FaceGroups, CoreFormatsRoundTrip) {
    const Mesh mesh = twoGroupFandisk();
    for (const char* ext : {"obj", "ply", "stl"}) {
        const fs::path file = scratch(std::string("core_groups.") + ext);
        fss::writeMesh(mesh, file);
        fss::ReadReport report;
        const Mesh back = fss::readMesh(file, &report);
        EXPECT_EQ(report.groups, 2u) << ext;
        // Names come in the order the file first uses them (fandisk's first face is in "lower").
        std::vector<std::string> names = fss::groupNames(back);
        std::sort(names.begin(), names.end());
        EXPECT_EQ(names, (std::vector<std::string>{"lower", "upper"})) << ext;
        EXPECT_EQ(facesPerGroup(back), facesPerGroup(mesh)) << ext;
    }
}

// A legacy VTK file with an integer cell array `group` (no names: "group_<value>").
TEST(FaceGroups, LegacyVtkWithGroupCellData) {
    const fs::path file = scratch("two_triangles.vtk");
    std::ofstream(file) << "# vtk DataFile Version 3.0\nfss\nASCII\nDATASET POLYDATA\nPOINTS 4 double\n"
                           "0 0 0\n1 0 0\n0 1 0\n1 1 0\nPOLYGONS 2 8\n3 0 1 2\n3 1 3 2\nCELL_DATA 2\n"
                           "SCALARS group int 1\nLOOKUP_TABLE default\n7\n9\n";
    fss::ReadReport report;
    const Mesh m = fss::render::readMeshFile(file, &report);
    EXPECT_EQ(m.number_of_faces(), 2u);
    EXPECT_EQ(report.format, "vtk");
    EXPECT_EQ(fss::groupNames(m), (std::vector<std::string>{"group_7", "group_9"}));
}

// ---- bad input: one sentence, nothing half-written -----------------------------------------------------

TEST(FemBadInput, GroupNamesTheFormatCannotHold) {
    Mesh mesh = twoGroupFandisk();
    fss::setGroupNames(mesh, {"upper face", "lower"});
    const fs::path inp = scratch("bad_name.inp");
    fs::remove(inp);
    try {
        fss::render::writeMeshFile(mesh, inp);
        FAIL() << "an Abaqus name with a space was written";
    } catch (const fss::IoError& e) {
        EXPECT_NE(std::string(e.what()).find("'upper face'"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(inp));
    // An existing file stays as it was.
    const fs::path obj = scratch("bad_name.obj");
    std::ofstream(obj) << "keep me\n";
    EXPECT_THROW(fss::writeMesh(mesh, obj), fss::IoError);
    EXPECT_EQ(fss::test::slurp(obj), "keep me\n");
    fss::setGroupNames(mesh, {"say \"hi\"", "lower"});
    EXPECT_THROW(fss::render::writeMeshFile(mesh, scratch("bad_name.msh")), fss::IoError);
    EXPECT_FALSE(fs::exists(scratch("bad_name.msh")));
    for (const auto& entry : fs::directory_iterator(tmpPath("fem_io")))
        EXPECT_EQ(entry.path().filename().string().find(".fss-tmp-"), std::string::npos) << entry.path();
}

TEST(FemBadInput, UnknownGroupSyntax) {
    const fs::path obj = scratch("two_groups_per_face.obj");
    std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\ng left right\nf 1 2 3\n";
    try {
        fss::readMesh(obj);
        FAIL();
    } catch (const fss::IoError& e) {
        EXPECT_NE(std::string(e.what()).find("one group per face"), std::string::npos) << e.what();
    }
    const fs::path ply = scratch("float_group.ply");
    std::ofstream(ply) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                          "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                          "property float group\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 0.5\n";
    EXPECT_THROW(fss::readMesh(ply), fss::IoError);
    const fs::path vtk = scratch("float_group.vtk");
    std::ofstream(vtk) << "# vtk DataFile Version 3.0\nfss\nASCII\nDATASET POLYDATA\nPOINTS 3 double\n"
                          "0 0 0\n1 0 0\n0 1 0\nPOLYGONS 1 4\n3 0 1 2\nCELL_DATA 1\n"
                          "SCALARS group float 1\nLOOKUP_TABLE default\n0.5\n";
    try {
        fss::render::readMeshFile(vtk);
        FAIL();
    } catch (const fss::IoError& e) {
        EXPECT_NE(std::string(e.what()).find("'group'"), std::string::npos) << e.what();
    }
}

// ---- quality measures against vtkMeshQuality ------------------------------------------------------------

struct Extremes {
    double min = 1e300, max = -1e300, mean = 0;
};

Extremes vtkQuality(const Mesh& mesh, int measure) {
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    std::map<std::size_t, vtkIdType> id;
    for (auto v : mesh.vertices()) {
        const auto& p = mesh.point(v);
        id[std::size_t(v)] = points->InsertNextPoint(p.x(), p.y(), p.z());
    }
    vtkNew<vtkCellArray> cells;
    for (FaceIndex f : mesh.faces()) {
        std::vector<vtkIdType> ids;
        for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
            ids.push_back(id[std::size_t(v)]);
        cells->InsertNextCell(3, ids.data());
    }
    vtkNew<vtkPolyData> poly;
    poly->SetPoints(points);
    poly->SetPolys(cells);
    vtkNew<vtkMeshQuality> quality;
    quality->SetInputData(poly);
    quality->SetTriangleQualityMeasure(measure);
    quality->Update();
    vtkDataArray* q = quality->GetOutput()->GetCellData()->GetArray("Quality");
    Extremes e;
    for (vtkIdType i = 0; i < q->GetNumberOfTuples(); ++i) {
        const double x = q->GetTuple1(i);
        e.min = std::min(e.min, x);
        e.max = std::max(e.max, x);
        e.mean += x / double(q->GetNumberOfTuples());
    }
    return e;
}

// Aspect ratio, scaled Jacobian, radius ratio (VTK's is the inverse of gamma) and the angles of
// computeMetrics equal vtkMeshQuality's (Verdict) on CGAL's meshes.
TEST(FemQuality, MetricsAgreeWithVtkMeshQuality) {
    for (const char* name : {"fandisk.off", "rotor_small.off", "couplingdown.off", "elephant.off"}) {
        SCOPED_TRACE(name);
        const Mesh mesh = fss::readMesh(meshPath(name));
        fss::MetricsOptions options;
        options.selfIntersections = false;
        const fss::Metrics m = fss::computeMetrics(mesh, options);
        const Extremes aspect = vtkQuality(mesh, VTK_QUALITY_ASPECT_RATIO);
        EXPECT_NEAR(m.aspectRatioMax, aspect.max, 1e-9 * aspect.max);
        EXPECT_NEAR(m.aspectRatioMean, aspect.mean, 1e-9 * aspect.mean);
        const Extremes jacobian = vtkQuality(mesh, VTK_QUALITY_SCALED_JACOBIAN);
        EXPECT_NEAR(m.scaledJacobianMin, jacobian.min, 1e-9);
        EXPECT_NEAR(m.scaledJacobianMean, jacobian.mean, 1e-9);
        const Extremes radius = vtkQuality(mesh, VTK_QUALITY_RADIUS_RATIO);
        EXPECT_NEAR(m.radiusRatioMin, 1 / radius.max, 1e-9);
        const Extremes minAngle = vtkQuality(mesh, VTK_QUALITY_MIN_ANGLE);
        EXPECT_NEAR(m.minAngleDeg, minAngle.min, 1e-7);
        EXPECT_NEAR(m.meanMinAngleDeg, minAngle.mean, 1e-7);
        const Extremes maxAngle = vtkQuality(mesh, VTK_QUALITY_MAX_ANGLE);
        EXPECT_NEAR(m.maxAngleDeg, maxAngle.max, 1e-7);
    }
}

// ---- groups through a remeshing session ------------------------------------------------------------------

// Two scans of the two-group fandisk accepted in a Session (CPU renderer), then the groups carried to the
// result: every face carries a group and each group's area is within 1 % of the input's.
TEST(FaceGroups, SessionResultKeepsGroupAreas) {
    const Mesh input = twoGroupFandisk();
    fss::Session session(input);
    for (auto view : {fss::StandardView::PosZ, fss::StandardView::Iso, fss::StandardView::NegY}) {
        fss::ScanStep step;
        step.params.camera = fss::Camera::standardView(view, fss::boundingBox(input), 200, 200);
        session.scan(step);
        session.accept();
    }
    Mesh result = session.current();
    EXPECT_GT(result.number_of_faces(), 0u);
    fss::transferFaceGroups(session.reference(), result);
    const auto before = fss::groupStats(input), after = fss::groupStats(result);
    ASSERT_EQ(after.size(), 2u); // no entry for faces without a group
    for (std::size_t g = 0; g < 2; ++g) {
        EXPECT_EQ(after[g].name, before[g].name);
        EXPECT_NEAR(after[g].area, before[g].area, 0.01 * before[g].area) << before[g].name;
        std::printf("[ measure  ] session: group %s area %.6g -> %.6g (%.3f %%)\n", before[g].name.c_str(),
                    before[g].area, after[g].area, 100 * (after[g].area / before[g].area - 1));
    }
    // The groups reach the file.
    const fs::path file = scratch("session_groups.msh");
    fss::render::writeMeshFile(result, file);
    EXPECT_EQ(facesPerGroup(fss::render::readMeshFile(file)), facesPerGroup(result));
}

} // namespace
