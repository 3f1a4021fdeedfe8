// Mesh I/O: every kind of bad file, atomic writing and its failures, and a few hundred randomly corrupted
// files that must either load into a valid mesh or throw fss::IoError.

#include "mesh_io_helpers.h"

using namespace mesh_io_test_helpers;

// ----------------------------------------------------------------------------------------- bad files

TEST(MeshIoErrors, MissingUnreadableAndEmptyFiles) {
    expectIoError(fss::test::tmpPath("does_not_exist.off"), {"does not exist"});
    const fs::path folder = fss::test::tmpPath("a_folder.off");
    fs::create_directories(folder);
    expectIoError(folder, {"folder"});
    expectBadText("empty.off", "", {"empty"});
    expectBadText("blank.ply", " \n\t\r\n", {"only white space"});

    const fs::path locked = fss::test::tmpPath("locked.off");
    fs::copy_file(fss::test::meshPath("tetrahedron.off"), locked, fs::copy_options::overwrite_existing);
    fs::permissions(locked, fs::perms::none);
    if (!std::ifstream(locked)) { // root can read anything: only check where permissions apply
        expectIoError(locked, {"cannot be opened"});
    }
    fs::permissions(locked, fs::perms::owner_all);
}

TEST(MeshIoErrors, TruncatedFiles) {
    expectBadText("short_vertices.off", "OFF\n8 1 0\n0 0 0\n1 0 0\n0 1 0\n",
                  {"announces 8 vertices but the file ends after 3", "truncated"});
    expectBadText("short_faces.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                  {"announces 2 faces but the file ends after 1", "truncated"});
    expectBadText("short_face_line.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n",
                  {"line 6", "face 0 announces 3 corners but lists 2"});
    expectBadText("short_vertex.obj", "v 0 0 0\nv 1 0\n",
                  {"line 2", "expected 3 coordinates for vertex 1 but found 2"});
    expectBadText("short.ply",
                  "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                  "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                  "0 0 0\n1 0 0\n",
                  {"truncated"});
    expectBadText("no_end_header.ply", "ply\nformat ascii 1.0\nelement vertex 3\n", {"end_header"});
    expectBadText("short.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n",
                  {"truncated"});
    expectBadText("no_endsolid.stl",
                  "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 "
                  "0\nendloop\nendfacet\n",
                  {"endsolid", "truncated"});

    const Mesh octa = makeOctahedron();
    for (const FormatCase& fc : {FormatCase{".ply", true}, FormatCase{".stl", true}}) {
        const fs::path p = fss::test::tmpPath("cut_" + caseName(fc) + fc.ext);
        fss::writeMesh(octa, p, {.binary = true});
        const std::string bytes = readFile(p);
        writeFile(p, bytes.substr(0, bytes.size() - 7));
        expectIoError(p, {"truncated"});
    }
}

TEST(MeshIoErrors, HugeHeaderCountsFailFastWithoutAllocating) {
    expectBadText("huge.off", "OFF\n2000000000 2000000000 0\n0 0 0\n", {"2000000000 vertices", "truncated"});
    expectBadText("huge.ply",
                  "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000000\n"
                  "property double x\nproperty double y\nproperty double z\nelement face 1\n"
                  "property list uchar int vertex_indices\nend_header\n" +
                      std::string(100, '\0'),
                  {"4000000000000 vertex elements", "truncated"});
    std::string stl(84, ' ');
    const std::uint32_t n = 0xffffffffu;
    std::memcpy(stl.data() + 80, &n, 4); // little endian on our platforms
    expectBadText("huge.stl", stl, {"4294967295 triangles", "truncated"});
    expectBadText("huge_face.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n1000000000 0 1 2\n",
                  {"face 0 announces 1000000000 corners but lists 3"});
    // A binary PLY face list announcing more indices than the file holds.
    std::string ply =
        "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list int int vertex_indices\nend_header\n";
    const std::int32_t big = 2000000000;
    ply.append(reinterpret_cast<const char*>(&big), 4);
    ply += std::string(8, '\0');
    expectBadText("huge_list.ply", ply, {"truncated"});
}

TEST(MeshIoErrors, UnknownFormatAndGarbage) {
    expectBadText("mystery.xyz", "hello world\nthis is not a mesh\n", {"not recognised", "'.xyz'"});
    expectBadText("mystery", "12 34 56\n", {"not recognised", "no extension"});
    std::mt19937 rng(7);
    std::string junk(3000, '\0');
    for (char& c : junk)
        c = static_cast<char>(rng());
    expectBadText("junk.bin", junk, {"not recognised"});
    expectBadText("junk.off", junk, {"OFF header"});
    expectBadText("junk.obj", junk, {"line "});
    expectBadText("junk.ply", junk, {"'ply'"});
    expectBadText("junk.stl", junk, {"binary STL"});
    expectBadText("words.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nhello 1 2 3\nf 1 2 3\n",
                  {"line 4", "unknown OBJ statement 'hello'"});
    expectBadText("words.off", "OFF\n3 1 0\n0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n",
                  {"line 4", "expected a coordinate of vertex 1 but found 'zero'"});
    expectBadText("trailing.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n",
                  {"line 7", "unexpected data after the 1 face the header announces"});
    expectBadText("words.stl", "solid x\nfacet normal 0 0 1\nouter ring\n", {"line 3", "expected 'loop'"});
    expectBadText("binary.off", "OFF BINARY\n", {"binary OFF"});
    expectBadText("nofaces.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", {"contains no faces"});
    expectBadText("nofaces.obj", "v 0 0 0\nv 1 0 0\n", {"contains no faces"});
    expectBadText("noface.ply",
                  "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                  "property float z\nend_header\n0 0 0\n",
                  {"no 'face' element"});
}

TEST(MeshIoErrors, NanAndInfiniteCoordinates) {
    expectBadText("nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n",
                  {"line 4", "vertex 1", "NaN or infinite"});
    expectBadText("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 -inf 0\nf 1 2 3\n",
                  {"line 3", "vertex 2", "NaN or infinite"});
    expectBadText("overflow.obj", "v 0 0 0\nv 1e999 0 0\nv 0 1 0\nf 1 2 3\n", {"line 2", "NaN or infinite"});
    expectBadText("nan.stl",
                  "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex NaN 0 0\nvertex 0 1 0\n"
                  "endloop\nendfacet\nendsolid x\n",
                  {"line 5", "NaN or infinite"});
    std::string ply =
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    const float coords[9] = {0, 0, 0, 1, 0, std::numeric_limits<float>::quiet_NaN(), 0, 1, 0};
    ply.append(reinterpret_cast<const char*>(coords), sizeof coords);
    const std::uint8_t three = 3;
    const std::int32_t idx[3] = {0, 1, 2};
    ply.append(reinterpret_cast<const char*>(&three), 1);
    ply.append(reinterpret_cast<const char*>(idx), sizeof idx);
    expectBadText("nan.ply", ply, {"vertex 1 has a NaN or infinite coordinate"});

    const fs::path stl = fss::test::tmpPath("inf.stl");
    fss::writeMesh(makeOctahedron(), stl, {.binary = true});
    std::string bytes = readFile(stl);
    const float inf = std::numeric_limits<float>::infinity();
    std::memcpy(bytes.data() + 84 + 50 * 3 + 12 + 4, &inf, 4); // triangle 3, first corner, y
    writeFile(stl, bytes);
    expectIoError(stl, {"triangle 3 has a NaN or infinite coordinate"});
}

TEST(MeshIoErrors, FacesIndexingMissingVerticesOrWithTooFewCorners) {
    const std::string pts = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
    expectBadText("bad_index.off", "OFF\n4 2 0\n" + pts + "3 0 1 2\n3 0 1 9\n",
                  {"line 8", "face 1 uses vertex index 9", "only 4 vertices"});
    expectBadText("negative_index.off", "OFF\n4 1 0\n" + pts + "3 0 -1 2\n", {"face 0 uses vertex index -1"});
    expectBadText("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 7\n",
                  {"line 5", "face 1 uses vertex 7", "only 3 vertices"});
    expectBadText("zero_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", {"face 0 uses vertex index 0"});
    expectBadText("bad_relative.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",
                  {"relative vertex index -4"});
    const std::string plyHeader =
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
    expectBadText("bad_index.ply", plyHeader + pts + "3 0 1 2\n3 2 1 4\n",
                  {"line 15", "face 1 uses vertex index 4"});
    expectBadText("two_corners.off", "OFF\n4 1 0\n" + pts + "2 0 1\n",
                  {"face 0 has 2 corners", "at least 3"});
    expectBadText("two_corners.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n", {"face 0 has 2 corners"});
    expectBadText("two_corners.ply", plyHeader + pts + "3 0 1 2\n2 1 3\n", {"face 1 has 2 corners"});
    expectBadText("too_many_values.ply", plyHeader + pts + "3 0 1 2 7\n3 0 1 3\n",
                  {"more values than the header"});
}

TEST(MeshIoErrors, NothingLeftAfterRepair) {
    expectBadText("all_degenerate.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 0 1\n3 2 2 2\n",
                  {"nothing is left after repair", "all 2 polygons are degenerate"});
    // Distinct indices, identical points: degenerate only once duplicates are merged.
    expectBadText("same_points.stl",
                  "solid x\nfacet normal 0 0 1\nouter loop\nvertex 1 1 1\nvertex 1 1 1\nvertex 1 1 1\n"
                  "endloop\nendfacet\nendsolid x\n",
                  {"nothing is left after repair"});
}

// ----------------------------------------------------------------------------------------- writing

TEST(MeshIoWrite, ReplacesAtomicallyAndReportsFailures) {
    const Mesh octa = makeOctahedron();
    const fs::path folder = fss::test::tmpPath("write_folder");
    fs::remove_all(folder);
    fs::create_directories(folder);
    auto entries = [&] {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(folder))
            names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    };

    // Overwriting an existing file leaves no temporary behind.
    const fs::path target = folder / "mesh.off";
    writeFile(target, "old content");
    fss::writeMesh(octa, target);
    EXPECT_EQ(fss::readMesh(target).number_of_faces(), 8u);
    EXPECT_EQ(entries(), std::vector<std::string>{"mesh.off"});

    // Failures name the file, and leave what existed untouched.
    auto expectWriteError = [&](const fs::path& p, const std::string& part) {
        try {
            fss::writeMesh(octa, p);
            ADD_FAILURE() << "no exception for " << p;
        } catch (const IoError& e) {
            EXPECT_NE(std::string(e.what()).find(p.filename().string()), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
        }
    };
    const std::string before = readFile(target);
    expectWriteError(folder / "mesh.vtk", "'.vtk'");
    expectWriteError(folder / "missing" / "mesh.off", "temporary file");
    fs::create_directories(folder / "dir.ply");
    expectWriteError(folder / "dir.ply", "folder");
    EXPECT_EQ(readFile(target), before);
    EXPECT_EQ(entries(), (std::vector<std::string>{"dir.ply", "mesh.off"}));
}

TEST(MeshIoWrite, WritesPolygonFacesAsFansInStl) {
    Mesh quad;
    const auto a = quad.add_vertex(Point3(0, 0, 0)), b = quad.add_vertex(Point3(1, 0, 0)),
               c = quad.add_vertex(Point3(1, 1, 0)), d = quad.add_vertex(Point3(0, 1, 0));
    quad.add_face(a, b, c, d);
    for (bool binary : {false, true}) {
        const fs::path p = fss::test::tmpPath(binary ? "quad_bin.stl" : "quad_ascii.stl");
        fss::writeMesh(quad, p, {.binary = binary});
        const Mesh m = fss::readMesh(p);
        EXPECT_EQ(m.number_of_faces(), 2u);
        EXPECT_EQ(m.number_of_vertices(), 4u);
        EXPECT_NEAR(area(m), 1.0, 1e-15);
    }
}

// ----------------------------------------------------------------------------------------- robustness

TEST(MeshIoFuzz, CorruptedFilesLoadValidMeshesOrThrowIoError) {
    // A small mesh with face properties, in every format; then mutations of each file.
    Mesh mesh = makeOctahedron();
    auto q = mesh.add_property_map<FaceIndex, float>(fss::props::faceQuality, 0.5f).first;
    auto s = mesh.add_property_map<FaceIndex, std::int32_t>(fss::props::faceScanId, 3).first;
    (void)q;
    (void)s;
    std::vector<std::pair<std::string, std::string>> originals; // extension, bytes
    for (const FormatCase& fc : kAllFormats) {
        const fs::path p = fss::test::tmpPath("fuzz_source_" + caseName(fc) + fc.ext);
        fss::writeMesh(mesh, p, {.binary = fc.binary});
        originals.emplace_back(fc.ext, readFile(p));
    }

    std::mt19937 rng(20240611);
    auto uniform = [&](std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng); };
    const std::vector<std::string> interesting = {
        "0", "9", "-", "\n", " ", "nan", "1e308", "/", "#", std::string(1, '\0'), "\xff", "e", "4294967295"};
    std::size_t loaded = 0, rejected = 0;
    constexpr int kCasesPerFormat = 60;
    for (const auto& [ext, original] : originals) {
        for (int round = 0; round < kCasesPerFormat; ++round) {
            std::string bytes = original;
            const int mutations = 1 + int(uniform(3));
            for (int k = 0; k < mutations && !bytes.empty(); ++k) {
                const std::size_t at = uniform(bytes.size());
                switch (uniform(6)) {
                case 0:
                    bytes.resize(at);
                    break; // truncate
                case 1:
                    bytes[at] = static_cast<char>(uniform(256));
                    break; // flip a byte
                case 2:
                    bytes.insert(at, 1, static_cast<char>(uniform(256)));
                    break; // insert a byte
                case 3:
                    bytes.erase(at, 1 + uniform(16));
                    break; // delete a run
                case 4:
                    bytes.insert(at, interesting[uniform(interesting.size())]);
                    break; // plausible token
                case 5:
                    bytes.insert(at, bytes.substr(at, 1 + uniform(40)));
                    break; // repeat a run
                }
            }
            const fs::path p = fss::test::tmpPath("fuzz" + ext);
            writeFile(p, bytes);
            try {
                ReadReport report;
                const Mesh m = fss::readMesh(p, &report);
                ASSERT_TRUE(CGAL::is_valid_polygon_mesh(m)) << ext << " round " << round;
                ASSERT_TRUE(CGAL::is_triangle_mesh(m)) << ext << " round " << round;
                ASSERT_GT(m.number_of_faces(), 0u) << ext << " round " << round;
                ++loaded;
            } catch (const IoError& e) {
                ASSERT_NE(std::string(e.what()).find("fuzz" + ext), std::string::npos) << e.what();
                ++rejected;
            } catch (const std::exception& e) {
                FAIL() << ext << " round " << round << ": unexpected exception " << e.what();
            }
        }
    }
    EXPECT_EQ(loaded + rejected, originals.size() * kCasesPerFormat);
    EXPECT_GT(rejected, 0u);
    EXPECT_GT(loaded, 0u);
}
