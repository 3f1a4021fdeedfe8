// Masks: the lasso on hand-made grids with known answers (square, concave L, figure-eight, pentagram
// under the non-zero rule), erosion / dilation / cleanup on ASCII-art grids, and the sampling-quality
// mask against the patch of an earlier scan (kept against a grazing scan, replaced by a zoomed one).
#include "fss/error.h"
#include "fss/mask.h"
#include "fss/raycast.h"
#include "fss/scan.h"
#include "fss/shapes.h"
#include "fss/triangulate.h"
#include "test_math.h"

#include <CGAL/boost/graph/iterator.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

using fss::Camera;
using fss::Lasso;
using fss::Mesh;
using fss::SampleGrid;

namespace {

using fss::test::kPi;

// rows × cols samples on their pixel centres, all hit, admissible and valid.
SampleGrid flatGrid(int rows, int cols) {
    SampleGrid g(rows, cols);
    g.camera.width = cols;
    g.camera.height = rows;
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) {
            fss::Sample& s = g.at(r, c);
            s.screen = {c + 0.5, r + 0.5};
            s.hit = s.admissible = s.valid = true;
        }
    return g;
}

// ASCII art: '#' valid (and admissible), '.' admissible but not valid, 'x' not admissible.
SampleGrid fromArt(const std::vector<std::string>& art) {
    SampleGrid g = flatGrid(int(art.size()), int(art[0].size()));
    for (int r = 0; r < g.rows; ++r)
        for (int c = 0; c < g.cols; ++c) {
            fss::Sample& s = g.at(r, c);
            s.valid = art[r][c] == '#';
            s.admissible = art[r][c] != 'x';
        }
    return g;
}

std::vector<std::string> toArt(const SampleGrid& g) {
    std::vector<std::string> art(std::size_t(g.rows), std::string(std::size_t(g.cols), '.'));
    for (int r = 0; r < g.rows; ++r)
        for (int c = 0; c < g.cols; ++c) {
            const fss::Sample& s = g.at(r, c);
            art[r][c] = s.valid ? '#' : (s.admissible ? '.' : 'x');
        }
    return art;
}

// Plain double crossing-number test of a simple polygon (an independent check of the lasso).
bool insideSimplePolygon(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& p) {
    bool in = false;
    for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
        const auto& a = poly[i];
        const auto& b = poly[j];
        if ((a.y() > p.y()) != (b.y() > p.y()) &&
            p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
            in = !in;
    }
    return in;
}

double distanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const Eigen::Vector2d e = b - a;
    const double t = std::clamp((p - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
    return (a + t * e - p).norm();
}

} // namespace

// ---- Lasso -------------------------------------------------------------------------------------------

TEST(Lasso, SquareAndItsBoundary) {
    SampleGrid g = flatGrid(10, 10);
    EXPECT_EQ(fss::applyLasso(g, Lasso{{{2, 2}, {6, 2}, {6, 6}, {2, 6}}}), 100u - 16u);
    EXPECT_EQ(g.validCount(), 16u);
    EXPECT_EQ(g.admissibleCount(), 16u);
    for (int r = 0; r < 10; ++r)
        for (int c = 0; c < 10; ++c)
            EXPECT_EQ(g.at(r, c).valid, r >= 2 && r <= 5 && c >= 2 && c <= 5);
    // Pixel centres exactly on the boundary are inside (closed polygon, exact predicates).
    SampleGrid h = flatGrid(10, 10);
    h.at(0, 0).admissible = h.at(0, 0).valid = false; // already out: not counted again
    EXPECT_EQ(fss::applyLasso(h, Lasso{{{2.5, 2.5}, {5.5, 2.5}, {5.5, 5.5}, {2.5, 5.5}}}), 100u - 16u - 1u);
    EXPECT_EQ(h.validCount(), 16u);
    EXPECT_TRUE(fss::insideLasso(Lasso{{{0, 0}, {3, 0}, {0, 3}}}, {1.5, 1.5})); // on the hypotenuse
    EXPECT_FALSE(fss::insideLasso(Lasso{{{0, 0}, {3, 0}, {0, 3}}}, {1.5, 1.5 + 1e-15}));
}

TEST(Lasso, ConcaveL) {
    SampleGrid g = flatGrid(10, 10);
    fss::applyLasso(g, Lasso{{{0, 0}, {6, 0}, {6, 3}, {3, 3}, {3, 6}, {0, 6}}});
    // Rows 0–2 × columns 0–5 and rows 3–5 × columns 0–2.
    EXPECT_EQ(g.validCount(), 18u + 9u);
    EXPECT_TRUE(g.at(1, 5).valid);
    EXPECT_TRUE(g.at(5, 1).valid);
    EXPECT_FALSE(g.at(4, 4).valid); // the notch
}

TEST(Lasso, FigureEightSelectsBothLoops) {
    // Bow tie (0,0)→(8,8)→(8,0)→(0,8): two triangles of opposite orientation meeting at (4,4).
    SampleGrid g = flatGrid(8, 8);
    fss::applyLasso(g, Lasso{{{0, 0}, {8, 8}, {8, 0}, {0, 8}}});
    // Left loop: c ≤ min(r, 7 − r) → 1+2+3+4+4+3+2+1 = 20 samples (centres on the diagonals count); the
    // right loop mirrors it.
    EXPECT_EQ(g.validCount(), 40u);
    for (int r = 0; r < 8; ++r)
        for (int c = 0; c < 8; ++c)
            EXPECT_EQ(g.at(r, c).valid, c <= std::min(r, 7 - r) || 7 - c <= std::min(r, 7 - r))
                << r << "," << c;
}

TEST(Lasso, PentagramUsesNonZeroRule) {
    // Five points on a circle joined in the order 0, 2, 4, 1, 3. Non-zero winding: the whole star,
    // centre pentagon included (winding number 2 there), i.e. exactly the simple 10-gon outline.
    const Eigen::Vector2d centre(20.3, 19.7);
    const double R = 17;
    std::vector<Eigen::Vector2d> outer, outline;
    for (int k = 0; k < 5; ++k)
        outer.push_back(centre + R * Eigen::Vector2d(std::cos(kPi / 2 + k * 2 * kPi / 5),
                                                     std::sin(kPi / 2 + k * 2 * kPi / 5)));
    const double rInner = R * std::cos(2 * kPi / 5) / std::cos(kPi / 5);
    for (int k = 0; k < 5; ++k) {
        outline.push_back(outer[k]);
        const double a = kPi / 2 + k * 2 * kPi / 5 + kPi / 5;
        outline.push_back(centre + rInner * Eigen::Vector2d(std::cos(a), std::sin(a)));
    }
    const Lasso star{{outer[0], outer[2], outer[4], outer[1], outer[3]}};
    SampleGrid g = flatGrid(40, 40);
    fss::applyLasso(g, star);
    std::size_t expected = 0, inCentre = 0;
    for (int r = 0; r < 40; ++r)
        for (int c = 0; c < 40; ++c) {
            const Eigen::Vector2d p(c + 0.5, r + 0.5);
            double clearance = std::numeric_limits<double>::infinity();
            for (std::size_t i = 0; i < outline.size(); ++i)
                clearance =
                    std::min(clearance, distanceToSegment(p, outline[i], outline[(i + 1) % outline.size()]));
            ASSERT_GT(clearance, 1e-6); // no pixel centre is ambiguous for the plain double reference
            const bool in = insideSimplePolygon(outline, p);
            expected += in;
            inCentre += (p - centre).norm() < 0.8 * rInner * std::cos(kPi / 5);
            EXPECT_EQ(g.at(r, c).valid, in) << r << "," << c;
        }
    EXPECT_EQ(g.validCount(), expected);
    EXPECT_GT(inCentre, 20u);
    EXPECT_TRUE(fss::insideLasso(star, centre)); // even-odd would say outside
}

// applyLasso decides a row of one y and non-decreasing x at once (binary searches with the exact
// predicate per edge) and other rows sample by sample; both must give insideLasso's answer for every
// sample. Random lassos with corners on the quarter-pixel lattice put corners on sample centres, level
// edges on sample rows and edges through many centres (the boundary cases); self-intersecting ones test
// the winding. Grids: regular, with repeated x, mirrored rows (x decreasing) and a row with a NaN.
TEST(Lasso, RowsAtOnceMatchThePointTest) {
    std::uint64_t state = 12345;
    auto next = [&] { // xorshift64*, deterministic on every platform
        state ^= state >> 12, state ^= state << 25, state ^= state >> 27;
        return (state * 2685821657736338717ULL) >> 11;
    };
    const int rows = 23, cols = 31;
    std::size_t boundaryHits = 0, insideTotal = 0, outsideTotal = 0;
    for (int trial = 0; trial < 300; ++trial) {
        Lasso lasso;
        const int m = 3 + int(next() % 12);
        for (int k = 0; k < m; ++k)
            lasso.points.emplace_back(double(next() % (4 * cols + 9)) / 4.0 - 1.0,
                                      double(next() % (4 * rows + 9)) / 4.0 - 1.0);
        try {
            fss::validateLasso(lasso);
        } catch (const fss::InvalidInputError&) {
            continue;
        }
        for (int layout = 0; layout < 4; ++layout) {
            SampleGrid g = flatGrid(rows, cols);
            for (int r = 0; r < rows; ++r)
                for (int c = 0; c < cols; ++c) {
                    fss::Sample& s = g.at(r, c);
                    if (layout == 1) s.screen.x() = double(c / 2) + 0.5;                  // pairs of equal x
                    if (layout == 2 && r % 2 == 1) s.screen.x() = double(cols - c) - 0.5; // mirrored
                    if (layout == 3 && r == 5 && c == 7)
                        s.screen.x() = std::numeric_limits<double>::quiet_NaN();
                    s.admissible = s.valid = (next() % 7 != 0);
                }
            const SampleGrid before = g;
            std::size_t expectedDropped = 0;
            const std::size_t dropped = fss::applyLasso(g, lasso);
            for (int r = 0; r < rows; ++r)
                for (int c = 0; c < cols; ++c) {
                    const fss::Sample& s = before.at(r, c);
                    const bool in = fss::insideLasso(lasso, s.screen);
                    const bool keep = s.admissible && in;
                    expectedDropped += s.admissible && !in;
                    ASSERT_EQ(g.at(r, c).admissible, keep)
                        << "trial " << trial << " layout " << layout << " at " << r << "," << c;
                    ASSERT_EQ(g.at(r, c).valid, s.valid && keep);
                    if (in) {
                        ++insideTotal;
                        // On an edge: the plain point test of its segment (exact for these lattice points).
                        for (int k = 0; k < m; ++k) {
                            const Eigen::Vector2d a = lasso.points[std::size_t(k)];
                            const Eigen::Vector2d b = lasso.points[std::size_t((k + 1) % m)];
                            const Eigen::Vector2d ab = b - a, ap = s.screen - a;
                            if (ab.x() * ap.y() - ab.y() * ap.x() == 0 && ap.dot(ab) >= 0 &&
                                ap.dot(ab) <= ab.squaredNorm()) {
                                ++boundaryHits;
                                break;
                            }
                        }
                    } else {
                        ++outsideTotal;
                    }
                }
            EXPECT_EQ(dropped, expectedDropped);
        }
    }
    // The random lassos did exercise both sides and the boundary rule.
    EXPECT_GT(insideTotal, 10000u);
    EXPECT_GT(outsideTotal, 10000u);
    EXPECT_GT(boundaryHits, 200u);
}

TEST(Lasso, DegenerateLassosAreRejected) {
    SampleGrid g = flatGrid(4, 4);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (const Lasso& bad :
         {Lasso{}, Lasso{{{1, 1}, {2, 2}}}, Lasso{{{1, 1}, {1, 1}, {1, 1}, {3, 2}}},
          Lasso{{{0, 0}, {1, 1}, {2, 2}, {3, 3}, {1, 1}}}, Lasso{{{0, 0}, {4, 0}, {nan, 4}}},
          Lasso{{{0, 0}, {4, 0}, {4, std::numeric_limits<double>::infinity()}}}}) {
        EXPECT_THROW(fss::applyLasso(g, bad), fss::InvalidInputError);
    }
    EXPECT_EQ(g.validCount(), 16u); // untouched
    try {
        fss::validateLasso(Lasso{{{0, 0}, {1, 1}, {2, 2}}});
        FAIL();
    } catch (const fss::InvalidInputError& e) {
        EXPECT_EQ(std::string(e.what()), "The lasso's points all lie on one line, so it encloses no area.");
    }
}

// ---- Morphology --------------------------------------------------------------------------------------

// The ASCII art reads best one row per line.
// clang-format off
TEST(Morphology, IsolatedSampleIsRemoved) {
    SampleGrid g = fromArt({".....",
                            ".....",
                            "..#..",
                            ".....",
                            "....."});
    const fss::MorphologyReport rep = fss::applyMorphology(g);
    EXPECT_EQ(g.validCount(), 0u);
    EXPECT_EQ(rep.eroded, 1u);
    EXPECT_EQ(rep.restored, 0u);
    EXPECT_EQ(rep.untriangulatable, 0u);
}

TEST(Morphology, BlockErodesToItsInteriorAndDilatesBack) {
    SampleGrid g = fromArt({".......",
                            ".#####.",
                            ".#####.",
                            ".#####.",
                            ".#####.",
                            ".#####.",
                            "......."});
    EXPECT_EQ(fss::erode(g, 1), 16u);
    EXPECT_EQ(toArt(g), (std::vector<std::string>{".......",
                                                  ".......",
                                                  "..###..",
                                                  "..###..",
                                                  "..###..",
                                                  ".......",
                                                  "......."}));
    EXPECT_EQ(fss::dilate(g, 1), 16u);
    EXPECT_EQ(g.validCount(), 25u);
    // Radius 2: the 5×5 block erodes to its centre; the grid border counts as invalid.
    const std::vector<std::string> full{"#####",
                                        "#####",
                                        "#####",
                                        "#####",
                                        "#####"};
    SampleGrid h = fromArt(full);
    EXPECT_EQ(fss::erode(h, 2), 24u);
    EXPECT_TRUE(h.at(2, 2).valid);
    EXPECT_EQ(fss::dilate(h, 2), 24u);
    SampleGrid k = fromArt(full);
    fss::erode(k, 1);
    EXPECT_EQ(k.validCount(), 9u);
    EXPECT_EQ(fss::erode(k, 3), 9u); // a 7×7 square does not fit
    EXPECT_THROW(fss::erode(k, -1), fss::InvalidInputError);
    EXPECT_THROW(fss::dilate(k, -1), fss::InvalidInputError);
    EXPECT_THROW(fss::applyMorphology(k, {.radius = -2}), fss::InvalidInputError);
}

TEST(Morphology, OneSampleBridgeIsBroken) {
    SampleGrid g = fromArt({"...........",
                            ".####.####.",
                            ".#########.",
                            ".####.####.",
                            ".####.####.",
                            "..........."});
    fss::applyMorphology(g);
    EXPECT_EQ(toArt(g), (std::vector<std::string>{"...........",
                                                  ".####.####.",
                                                  ".####.####.",
                                                  ".####.####.",
                                                  ".####.####.",
                                                  "..........."}));
}

TEST(Morphology, SpikeIsRemoved) {
    SampleGrid g = fromArt({"..........",
                            ".####.....",
                            ".####.....",
                            ".#######..",
                            ".####.....",
                            "..........",
                            "#........."});
    const fss::MorphologyReport rep = fss::applyMorphology(g);
    EXPECT_EQ(toArt(g), (std::vector<std::string>{"..........",
                                                  ".####.....",
                                                  ".####.....",
                                                  ".####.....",
                                                  ".####.....",
                                                  "..........",
                                                  ".........."}));
    EXPECT_EQ(rep.eroded, 12u + 3u + 1u); // the block's rim, the spike, the isolated sample
    EXPECT_EQ(rep.restored, 12u);
}

TEST(Morphology, DilationNeverReadmits) {
    // A 7×7 block with a non-admissible hole in the middle: the opening restores the hole's neighbours
    // but not the hole.
    const std::vector<std::string> art{".........",
                                       ".#######.",
                                       ".#######.",
                                       ".#######.",
                                       ".###x###.",
                                       ".#######.",
                                       ".#######.",
                                       ".#######.",
                                       "........."};
    SampleGrid g = fromArt(art);
    fss::applyMorphology(g);
    EXPECT_EQ(toArt(g), art);
    // Directly: the admissible neighbour becomes valid, the non-admissible one does not.
    SampleGrid h = fromArt({"x#."});
    EXPECT_EQ(fss::dilate(h, 1), 1u);
    EXPECT_EQ(toArt(h), (std::vector<std::string>{"x##"}));
}

TEST(Morphology, UntriangulatableSamplesAreRemoved) {
    SampleGrid g = fromArt({".......",
                            ".##....",
                            ".##.#..",
                            "....#..",
                            ".#...##",
                            ".....##"});
    EXPECT_EQ(fss::removeUntriangulatableSamples(g), 3u);
    EXPECT_EQ(toArt(g), (std::vector<std::string>{".......",
                                                  ".##....",
                                                  ".##....",
                                                  ".......",
                                                  ".....##",
                                                  ".....##"}));
    SampleGrid line = fromArt({"#####"});
    EXPECT_EQ(fss::removeUntriangulatableSamples(line), 5u);
}
// clang-format on

// ---- Sampling-quality mask ---------------------------------------------------------------------------

namespace {

// The plane [0,4]² (z = 0) and parallel cameras looking at its centre.
Mesh plane() {
    return fss::shapes::grid(80, 80, 0.05);
}

Camera planeCamera(double tiltDeg, double scale) {
    Camera c;
    c.parallel = true;
    c.focal = {2, 2, 0};
    c.eye = c.focal + 3.0 * Eigen::Vector3d(0, -std::sin(tiltDeg * kPi / 180), std::cos(tiltDeg * kPi / 180));
    c.up = {0, 1, 0};
    c.parallelScale = scale;
    c.width = c.height = 64;
    c.fitClippingRange(Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, -0.01), Eigen::Vector3d(4, 4, 0.01)));
    return c;
}

SampleGrid scanPlane(const Mesh& reference, const Camera& cam, std::int32_t id) {
    return fss::sampleRegularGrid(fss::rasterizeOnCpu(reference, cam), reference, {.scanId = id});
}

// The samples that the current mesh does not cover (their pixel shows no current face).
std::vector<bool> uncovered(const SampleGrid& g, const fss::FrameBuffers& current) {
    std::vector<bool> out(g.samples.size());
    for (int r = 0; r < g.rows; ++r)
        for (int c = 0; c < g.cols; ++c)
            out[g.index(r, c)] = !current.covered(c, r);
    return out;
}

} // namespace

TEST(QualityMask, EarlierFrontalScanIsKeptAgainstGrazingAndReplacedByZoomed) {
    const Mesh reference = plane();
    // Earlier frontal scan: footprint 1/64, q = 1/64 on every face.
    const Camera frontal = planeCamera(0, 0.5);
    SampleGrid first = scanPlane(reference, frontal, 1);
    fss::applyMorphology(first);
    const fss::Patch earlier = fss::triangulateGrid(first);
    ASSERT_EQ(earlier.mesh.number_of_faces(), 2u * 63u * 63u);
    const Mesh& current = earlier.mesh;

    {
        // Later grazing scan (60°): same footprint, q = 2/64, worse: every sample over the patch goes,
        // every sample off the patch stays.
        const Camera grazing = planeCamera(60, 0.5);
        SampleGrid g = scanPlane(reference, grazing, 2);
        const fss::FrameBuffers buffers = fss::rasterizeOnCpu(current, grazing);
        const std::vector<bool> off = uncovered(g, buffers);
        const std::size_t offCount = std::size_t(std::count(off.begin(), off.end(), true));
        ASSERT_GT(offCount, 500u);
        ASSERT_LT(offCount, 64u * 64u - 500u);
        EXPECT_EQ(fss::applyQualityMask(g, current, buffers), 64u * 64u - offCount);
        for (std::size_t i = 0; i < g.samples.size(); ++i)
            EXPECT_EQ(g.samples[i].admissible, off[i]);
        // Forced replacement keeps everything.
        SampleGrid forced = scanPlane(reference, grazing, 2);
        EXPECT_EQ(fss::applyQualityMask(forced, current, buffers, {.forceReplace = true}), 0u);
        EXPECT_EQ(forced.admissibleCount(), 64u * 64u);
    }
    {
        // Later zoomed frontal scan (2×): q = 0.5/64 < 0.9 · 1/64, better everywhere: nothing goes.
        const Camera zoomed = planeCamera(0, 0.25);
        SampleGrid g = scanPlane(reference, zoomed, 3);
        const fss::FrameBuffers buffers = fss::rasterizeOnCpu(current, zoomed);
        ASSERT_EQ(buffers.coveredCount(), 64u * 64u);
        EXPECT_EQ(fss::applyQualityMask(g, current, buffers), 0u);
        EXPECT_EQ(g.admissibleCount(), 64u * 64u);
    }
    {
        // The same view again: equal quality is not better by the 10 % margin, so nothing covered by the
        // patch is replaced (no churn); with margin 0 it is still not strictly better.
        SampleGrid g = scanPlane(reference, frontal, 4);
        const fss::FrameBuffers buffers = fss::rasterizeOnCpu(current, frontal);
        const std::vector<bool> off = uncovered(g, buffers);
        fss::applyQualityMask(g, current, buffers, {.margin = 0.0});
        for (std::size_t i = 0; i < g.samples.size(); ++i)
            EXPECT_EQ(g.samples[i].admissible, off[i]);
    }
}

TEST(QualityMask, InputFacesAlwaysLoseAndFacesAreFoundLocally) {
    // The current mesh is the plane with a quality of 1/64 on the faces left of x = 2 and none (input)
    // on the right: a grazing scan (q = 2/64) loses exactly on the left half.
    Mesh current = plane();
    {
        SampleGrid g = scanPlane(current, planeCamera(60, 0.5), 1);
        const fss::FrameBuffers buffers = fss::rasterizeOnCpu(current, g.camera);
        EXPECT_EQ(fss::applyQualityMask(g, current, buffers), 0u); // no quality property: all input faces
    }
    auto quality =
        current.add_property_map<fss::FaceIndex, float>(fss::props::faceQuality, fss::kInputFaceQuality)
            .first;
    for (auto f : current.faces()) {
        double x = 0;
        for (auto v : CGAL::vertices_around_face(current.halfedge(f), current))
            x += current.point(v).x() / 3;
        if (x < 2) quality[f] = 1.0f / 64;
    }
    SampleGrid g = scanPlane(current, planeCamera(60, 0.5), 2);
    const fss::FrameBuffers buffers = fss::rasterizeOnCpu(current, g.camera);
    std::size_t left = 0;
    for (const fss::Sample& s : g.samples)
        left += s.point.x() < 2;
    ASSERT_GT(left, 1000u);
    EXPECT_EQ(fss::applyQualityMask(g, current, buffers), left);
    for (const fss::Sample& s : g.samples)
        EXPECT_EQ(s.admissible, s.point.x() > 2);

    EXPECT_THROW(fss::applyQualityMask(g, current, buffers, {.margin = 1.0}), fss::InvalidInputError);
    EXPECT_THROW(fss::applyQualityMask(g, current, buffers, {.searchRings = -1}), fss::InvalidInputError);
    fss::FrameBuffers small = buffers;
    small.camera.width = 32;
    EXPECT_THROW(fss::applyQualityMask(g, current, small), fss::InvalidInputError);
}
