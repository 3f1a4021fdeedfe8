// The FEM hand-off's Nastran files (fss/render/fem_io.h, issue 22): the PID name comments of HyperMesh, ANSA,
// Femap and Patran, the shortest forms of 16-character reals read back by meshio, full-precision coordinates,
// and every format's limits checked by count, a refused mesh leaving no file.
#include "fem_io_helpers.h"

using namespace fem_io_test_helpers;

namespace {

// ---- Nastran names: the comment conventions of HyperMesh, ANSA, Femap and Patran -------------------------

TEST(NastranNames, ExactConventionSyntax) {
    Mesh mesh = twoGroupFandisk();
    fss::setGroupNames(mesh, {"Upper skin-2.a", "lower (inner)"});
    const fs::path file = scratch("names.bdf");
    fss::render::writeMeshFile(mesh, file);
    const std::string text = fss::test::slurp(file);
    // The exact lines, byte for byte.
    for (const char* line : {"$HMNAME COMP                   1\"Upper skin-2.a\"\n",
                             "$HMNAME PROP                   2\"lower (inner)\"\n",
                             "$ANSA_NAME_COMMENT;1;PSHELL;Upper skin-2.a;;NO;NO;NO;NO;\n",
                             "$ Femap Property 2 : lower (inner)\n",
                             "$ Elements and Element Properties for region : Upper skin-2.a\nPSHELL  1\n"})
        EXPECT_NE(text.find(line), std::string::npos) << line;
    expectNastranNameComments(text, {{1, "Upper skin-2.a"}, {2, "lower (inner)"}});
    // meshio still reads the file (the comments and PSHELL cards are skipped) with the PIDs.
    const nlohmann::json m = meshio(file);
    ASSERT_FALSE(m.is_null());
    const auto expected = facesPerGroup(mesh);
    EXPECT_EQ(m.at("groups").at("pid_1").get<std::size_t>(), expected.at("Upper skin-2.a"));
    EXPECT_EQ(m.at("groups").at("pid_2").get<std::size_t>(), expected.at("lower (inner)"));
    // Names the comment lines cannot hold: one sentence, no file.
    for (const char* bad : {"say \"hi\"", "a;b", "caf\xc3\xa9", "tab\there"}) {
        fss::setGroupNames(mesh, {bad, "lower"});
        const fs::path refused = scratch("bad_names.bdf");
        fs::remove(refused);
        try {
            fss::render::writeMeshFile(mesh, refused);
            ADD_FAILURE() << "written: " << bad;
        } catch (const fss::IoError& e) {
            EXPECT_NE(std::string(e.what()).find("Nastran BDF cannot hold the group name"), std::string::npos)
                << e.what();
        }
        EXPECT_FALSE(fs::exists(refused));
    }
}

// ---- Nastran reals: the shortest forms of a 16-character field ----------------------------------------

/// meshio's parser of Nastran reals (nastran._nastran._nastran_string_to_float), one value per line.
std::vector<double> meshioNastranReals(const std::vector<std::string>& texts) {
    const fs::path input = scratch("reals.txt"), script = scratch("meshio_reals.py");
    {
        std::ofstream f(input);
        for (const std::string& t : texts)
            f << t << "\n";
        std::ofstream(script)
            << "import sys\nfrom meshio.nastran._nastran import _nastran_string_to_float as p\n"
               "for line in open(sys.argv[1]):\n    print(repr(p(line.rstrip('\\n'))))\n";
    }
    const auto r =
        fss::test::runProcess(FSS_SYSTEM_PYTHON, {script.string(), input.string()}, tmpPath("fem_io"));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    std::vector<double> out;
    std::istringstream lines(r.out);
    for (std::string l; std::getline(lines, l);) {
        double v = std::numeric_limits<double>::quiet_NaN(); // std::stod refuses subnormals
        std::from_chars(l.data(), l.data() + l.size(), v);
        out.push_back(v);
    }
    return out;
}

/// The significant digits a 16-character field holds at least for \p v: 14 (13 if negative) in the fixed
/// form for 0.1 <= |v| < 1e14; else 13 (12) with a one-digit exponent, one fewer per further exponent digit.
int guaranteedDigits(double v) {
    const int sign = v < 0 ? 1 : 0;
    const double a = std::abs(v);
    if (a >= 0.1 && a < 1e14) return 14 - sign;
    const int e = int(std::floor(std::log10(a)));
    return 13 - sign - (int(std::to_string(std::abs(e)).size()) - 1);
}

TEST(NastranReal, EdgeCasesReadBackByMeshio) {
    std::vector<double> values = {0.0,
                                  -0.0,
                                  1.0,
                                  -1.0,
                                  0.5,
                                  0.1,
                                  -0.1,
                                  7.0,
                                  1e-300,
                                  -1e-300,
                                  1e300,
                                  -1e300,
                                  std::numeric_limits<double>::max(),
                                  -std::numeric_limits<double>::max(),
                                  std::numeric_limits<double>::min(),
                                  5e-324, // smallest normal, denormal
                                  9.9999999999999995,
                                  99999.999999999999,
                                  0.099999999999999999,
                                  9.99999999999999e-10,
                                  9.999999999999999e9,
                                  9.999999999999999e99,
                                  -9.9999999999999995e-100,
                                  999999999999999.9,
                                  1e15,
                                  123456789012345678.0,
                                  0.000123456789012345,
                                  -1.23456789012345e-5,
                                  3.14159265358979,
                                  -2.718281828459045,
                                  1.2345678901234567e-10,
                                  1.2345678901234567e100,
                                  -1.5e-100,
                                  12345678901.234567};
    // Random values over all magnitudes and both signs.
    std::mt19937_64 rng(22);
    std::uniform_real_distribution<double> mantissa(1, 10);
    std::uniform_int_distribution<int> exponent(-307, 307);
    for (int i = 0; i < 2000; ++i)
        values.push_back((i % 2 ? -1 : 1) * mantissa(rng) * std::pow(10.0, exponent(rng)));
    std::vector<std::string> texts;
    for (double v : values) {
        const std::string t = fss::render::nastranReal(v);
        EXPECT_LE(t.size(), 16u) << v << " -> " << t;
        EXPECT_NE(t.find('.'), std::string::npos) << v << " -> " << t; // a Nastran real has a point
        EXPECT_EQ(t.find_first_of("Ee "), std::string::npos) << v << " -> " << t;
        texts.push_back(t);
    }
    EXPECT_EQ(texts[0], "0.");
    EXPECT_EQ(texts[1], "0.");
    EXPECT_EQ(texts[2], "1.");
    EXPECT_EQ(texts[4], "0.5");
    EXPECT_EQ(texts[8], "1.-300");
    EXPECT_EQ(texts[10], "1.+300");
    EXPECT_EQ(texts[16], "10.");              // 9.9999999999999995 rounds up to the next power of ten
    EXPECT_EQ(texts[17], "100000.");          // 99999.999999999999 likewise
    EXPECT_EQ(texts[12], "1.7976931348+308"); // truncated: rounding up would overflow
    EXPECT_EQ(texts[27], "-1.23456789012-5"); // exponent: 12 digits (fixed would hold 10)
    EXPECT_EQ(texts[30], ".1234567890123-9"); // the point before the digits: a one-digit exponent
    EXPECT_EQ(texts[31], "12.3456789012+99"); // after two digits: a two-digit exponent
    EXPECT_EQ(texts[33], "12345678901.2346"); // fixed: 15 digits
    const std::vector<double> back = meshioNastranReals(texts);
    ASSERT_EQ(back.size(), values.size());
    double worstFixed = 0, worstExponent = 0;
    for (std::size_t i = 0; i < values.size(); ++i) {
        const double v = values[i];
        if (v == 0) {
            EXPECT_EQ(back[i], 0.0);
            continue;
        }
        if (std::abs(v) < std::numeric_limits<double>::min()) { // denormal: precision is absolute
            EXPECT_NEAR(back[i], v, 1e-323) << texts[i];
            continue;
        }
        const double rel = std::abs(back[i] - v) / std::abs(v);
        EXPECT_LE(rel, 5.0001 * std::pow(10.0, -guaranteedDigits(v))) << v << " -> " << texts[i];
        double& worst = std::abs(v) >= 0.1 && std::abs(v) < 1e14 ? worstFixed : worstExponent;
        worst = std::max(worst, rel);
    }
    std::printf(
        "[ measure  ] Nastran reals read back by meshio: worst relative error %.3g for 0.1 <= |v| < 1e14, "
        "%.3g elsewhere (%zu values)\n",
        worstFixed, worstExponent, values.size());
}

// ---- format limits ----------------------------------------------------------------------------------------

TEST(FemLimits, EachFormatsLimitIsCheckedByCount) {
    using fss::render::checkFormatLimits;
    using fss::render::formatLimits;
    struct Case {
        const char* file;
        double msh;
        bool binary;
        std::size_t nodes, elements, groups;
    };
    constexpr std::size_t none = std::numeric_limits<std::size_t>::max();
    for (const Case& c :
         {Case{"a.bdf", 4.1, false, 99'999'999, 99'999'999, 99'999'999},
          Case{"a.NAS", 4.1, false, 99'999'999, 99'999'999, 99'999'999},
          Case{"a.inp", 4.1, false, 999'999'999, 999'999'999, none},
          Case{"a.msh", 2.2, false, 2'147'483'647, 2'147'483'647, 2'147'483'647},
          Case{"a.unv", 4.1, false, 2'147'483'647, 2'147'483'647, 2'147'483'647},
          Case{"a.ply", 4.1, false, 2'147'483'647, none, none},
          Case{"a.stl", 4.1, true, none, 4'294'967'295, none}, Case{"a.msh", 4.1, false, none, none, none},
          Case{"a.stl", 4.1, false, none, none, none}, Case{"a.vtu", 4.1, false, none, none, none},
          Case{"a.vtp", 4.1, false, none, none, none}, Case{"a.obj", 4.1, false, none, none, none},
          Case{"a.off", 4.1, false, none, none, none}}) {
        SCOPED_TRACE(std::string(c.file) + " msh " + std::to_string(c.msh));
        fss::render::FemWriteOptions fem;
        fem.mshVersion = c.msh;
        fss::WriteOptions core;
        core.binary = c.binary;
        const auto l = formatLimits(c.file, fem, core);
        EXPECT_EQ(l.nodes, c.nodes);
        EXPECT_EQ(l.elements, c.elements);
        EXPECT_EQ(l.groups, c.groups);
        EXPECT_NO_THROW(checkFormatLimits(c.file, l.nodes, l.elements, l.groups, fem, core));
        const std::pair<std::size_t, const char*> over[] = {{0, "nodes"}, {1, "elements"}, {2, "groups"}};
        for (const auto& [which, what] : over) {
            std::size_t n[3] = {1, 1, 1};
            const std::size_t limit = which == 0 ? l.nodes : which == 1 ? l.elements : l.groups;
            if (limit == none) continue;
            n[which] = limit + 1;
            try {
                checkFormatLimits(c.file, n[0], n[1], n[2], fem, core);
                ADD_FAILURE() << what << " over the limit accepted";
            } catch (const fss::IoError& e) {
                const std::string m = e.what();
                EXPECT_NE(m.find(std::to_string(limit + 1) + " " + what + ", more than the " +
                                 std::to_string(limit) + " that a "),
                          std::string::npos)
                    << m;
                // One sentence naming the file: "Cannot write mesh file 'a.bdf': <problem>."
                EXPECT_EQ(m.rfind(std::string("Cannot write mesh file '") + c.file + "': ", 0), 0u) << m;
                EXPECT_EQ(m.find(". "), std::string::npos) << m;
                EXPECT_EQ(m.back(), '.') << m;
            }
        }
    }
}

// A limit lowered through FemWriteOptions (a student edition's, say) exercises the writers' refusal on a
// real mesh: one sentence, no file, no temporary file, an existing file unchanged.
TEST(FemLimits, RefusedMeshLeavesNoFile) {
    const Mesh mesh = twoGroupFandisk();
    const std::size_t nodes = mesh.number_of_vertices(), faces = mesh.number_of_faces();
    for (const char* ext : {"bdf", "inp", "msh", "unv", "vtu", "vtp", "ply", "stl", "obj", "off"}) {
        SCOPED_TRACE(ext);
        const fs::path file = scratch(std::string("limited.") + ext);
        for (int which = 0; which < 2; ++which) {
            fss::render::FemWriteOptions options;
            (which == 0 ? options.maxNodes : options.maxElements) = (which == 0 ? nodes : faces) - 1;
            fs::remove(file);
            try {
                fss::render::writeMeshFile(mesh, file, options);
                ADD_FAILURE() << "written over the limit";
            } catch (const fss::IoError& e) {
                EXPECT_NE(std::string(e.what()).find("asked for as the limit"), std::string::npos)
                    << e.what();
            }
            EXPECT_FALSE(fs::exists(file));
            std::ofstream(file) << "keep me\n";
            EXPECT_THROW(fss::render::writeMeshFile(mesh, file, options), fss::IoError);
            EXPECT_EQ(fss::test::slurp(file), "keep me\n");
        }
        // At the limit: written.
        fss::render::FemWriteOptions exact;
        exact.maxNodes = nodes;
        exact.maxElements = faces;
        fs::remove(file);
        EXPECT_NO_THROW(fss::render::writeMeshFile(mesh, file, exact));
        EXPECT_TRUE(fs::exists(file));
    }
    for (const auto& entry : fs::directory_iterator(tmpPath("fem_io")))
        EXPECT_EQ(entry.path().filename().string().find(".fss-tmp-"), std::string::npos) << entry.path();
}

// fandisk's coordinates have 4 decimals; rotated, scaled and moved they use all 17 digits of a double: the
// BDF's 16-character reals are read back by meshio and by gmsh within 1e-12 of the bounding box diagonal
// and of the largest coordinate.
TEST(NastranReal, FullPrecisionCoordinatesRoundTripAt1e12) {
    Mesh mesh = fss::readMesh(meshPath("fandisk.off"));
    const Eigen::Matrix3d rotation =
        (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix());
    const Eigen::Vector3d offset(1000.123456789, -2000.987654321, 3.14159265358979);
    for (auto v : mesh.vertices()) {
        const auto& p = mesh.point(v);
        const Eigen::Vector3d q = 123.456789 * rotation * Eigen::Vector3d(p.x(), p.y(), p.z()) + offset;
        mesh.point(v) = fss::Point3(q.x(), q.y(), q.z());
    }
    const fs::path file = scratch("full_precision.bdf");
    fss::render::writeMeshFile(mesh, file);
    const double diag = fss::boundingBox(mesh).diagonal().norm();
    double largest = 0;
    for (auto v : mesh.vertices())
        for (int k = 0; k < 3; ++k)
            largest = std::max(largest, std::abs(mesh.point(v)[k]));
    auto compare = [&](const char* reader, auto pointOf) {
        double worst = 0, worstPerValue = 0;
        std::size_t i = 0;
        for (auto v : mesh.vertices()) {
            const std::array<double, 3> q = pointOf(i++);
            for (int k = 0; k < 3; ++k) {
                const double x = mesh.point(v)[k], e = std::abs(q[std::size_t(k)] - x);
                worst = std::max(worst, e);
                if (x != 0) worstPerValue = std::max(worstPerValue, e / std::abs(x));
            }
        }
        EXPECT_LE(worst / diag, 1e-12) << reader;
        EXPECT_LE(worst / largest, 1e-12) << reader;
        std::printf(
            "[ measure  ] BDF coordinates read by %s: worst error %.3g of the bounding box diagonal, %.3g "
            "of the largest coordinate, %.3g of the value itself\n",
            reader, worst / diag, worst / largest, worstPerValue);
    };
    const nlohmann::json m = meshio(file);
    ASSERT_FALSE(m.is_null());
    const auto& points = m.at("points");
    ASSERT_EQ(points.size(), mesh.number_of_vertices());
    compare("meshio", [&](std::size_t i) {
        return std::array<double, 3>{points[i][0].get<double>(), points[i][1].get<double>(),
                                     points[i][2].get<double>()};
    });
    const GmshView g = readWithGmsh(file);
    ASSERT_EQ(g.points.size(), mesh.number_of_vertices());
    compare("gmsh", [&](std::size_t i) { return g.points.at(i + 1); });
}

} // namespace
