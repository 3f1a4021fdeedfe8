// fss::autoRemesh on CGAL's elephant (CPU renderer), a small curved mesh whose views' regions are only a few
// pixels wide at the target edge length (the input's vertex count): with the stitch's wide trims
// (StitchOptions::peelTrim off) the patches are cut apart at folds of the mesh under their boundary and about
// 0.63 of the area is remeshed; peeling (autoRemesh's default) keeps them.
#include "fss/auto_remesh.h"
#include "fss/metrics.h"
#include "fss/mesh_io.h"

#include "test_data.h"

#include <gtest/gtest.h>

#include <cmath>

namespace {

// Coverage recomputed from the result's face property, independently of the report.
double scannedAreaFraction(const fss::Mesh& m) {
    const auto ids = m.property_map<fss::FaceIndex, std::int32_t>(fss::props::faceScanId);
    if (!ids.second) return 0;
    double scanned = 0, total = 0;
    for (fss::FaceIndex f : m.faces()) {
        const auto h = m.halfedge(f);
        const double a = std::sqrt(
            CGAL::squared_area(m.point(m.source(h)), m.point(m.target(h)), m.point(m.target(m.next(h)))));
        total += a;
        if (ids.first[f] >= 0) scanned += a;
    }
    return scanned / total;
}

} // namespace

// Measured (CPU renderer): coverage 0.634 with peelTrim off, 0.764 with it on (3923 vertices for 2775 input
// vertices, valence 6 0.617, smallest angle 10.0°).
TEST(AutoRemeshPeel, ElephantKeepsMoreOfItsPatchesWhenTheStitchPeels) {
    const fss::Mesh elephant = fss::readMesh(fss::test::meshPath("elephant.off"));
    fss::AutoOptions o;
    ASSERT_TRUE(o.stitch.peelTrim);
    const fss::AutoResult peeled = fss::autoRemesh(elephant, o);
    o.stitch.peelTrim = false;
    const fss::AutoResult wide = fss::autoRemesh(elephant, o);

    const double coveragePeeled = scannedAreaFraction(peeled.mesh);
    const double coverageWide = scannedAreaFraction(wide.mesh);
    EXPECT_NEAR(coveragePeeled, peeled.coverage, 1e-9);
    EXPECT_GE(coveragePeeled, 0.72);
    EXPECT_LT(coverageWide, 0.68);
    EXPECT_GE(coveragePeeled, coverageWide + 0.08);
    std::size_t trimmedPeeled = 0, trimmedWide = 0, patchPeeled = 0, patchWide = 0;
    for (const fss::AutoStep& s : peeled.steps) trimmedPeeled += s.patchFacesTrimmed, patchPeeled += s.patchFaces;
    for (const fss::AutoStep& s : wide.steps) trimmedWide += s.patchFacesTrimmed, patchWide += s.patchFaces;
    // The stitches keep a larger share of what the scans deliver.
    EXPECT_LT(double(trimmedPeeled) / double(patchPeeled), double(trimmedWide) / double(patchWide) - 0.05);

    fss::MetricsOptions mo;
    mo.reference = &elephant;
    const fss::Metrics m = fss::computeMetrics(peeled.mesh, mo);
    EXPECT_TRUE(m.closed);
    EXPECT_EQ(m.nonManifoldVertices, 0u);
    EXPECT_EQ(m.degenerateFaces, 0u);
    EXPECT_EQ(m.selfIntersections, std::optional<std::size_t>(0));
    EXPECT_GE(m.minAngleDeg, 10.0 - 1e-9);
    EXPECT_NEAR(double(m.vertices), double(elephant.number_of_vertices()),
                0.5 * double(elephant.number_of_vertices()));
    ASSERT_TRUE(m.hausdorffToRef);
    EXPECT_LT(*m.hausdorffToRef, peeled.edgeLength);
}
