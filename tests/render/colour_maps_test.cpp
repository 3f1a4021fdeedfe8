// The colour maps shared by snapshots and widgets (colour_maps.h): the minimum-angle map's anchors, the
// valence map in the same colours, and the scan-id map (grey input faces, saturated scans by hue).
#include "fss/render/colour_maps.h"
#include "fss/render/snapshot.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace {

using fss::render::Rgb;

// Hue in degrees [0, 360) and saturation in [0, 1] of an 8-bit colour.
double hueOf(const Rgb& c) {
    const double r = c[0] / 255.0, g = c[1] / 255.0, b = c[2] / 255.0;
    const double mx = std::max({r, g, b}), mn = std::min({r, g, b}), d = mx - mn;
    if (d == 0) return 0;
    double h = mx == r ? std::fmod((g - b) / d, 6.0) : mx == g ? (b - r) / d + 2 : (r - g) / d + 4;
    h *= 60;
    return h < 0 ? h + 360 : h;
}
double saturationOf(const Rgb& c) {
    const int mx = std::max({c[0], c[1], c[2]}), mn = std::min({c[0], c[1], c[2]});
    return mx == 0 ? 0 : double(mx - mn) / mx;
}

TEST(ColourMaps, MinAngleMapKeepsTheSnapshotColours) {
    EXPECT_EQ(fss::render::minAngleColor(0), (Rgb{215, 25, 28}));
    EXPECT_EQ(fss::render::minAngleColor(30), (Rgb{250, 220, 40}));
    EXPECT_EQ(fss::render::minAngleColor(60), (Rgb{26, 150, 65}));
    EXPECT_EQ(fss::render::minAngleColor(15), (Rgb{233, 123, 34}));
}

TEST(ColourMaps, ValenceMapUsesTheSameColours) {
    EXPECT_EQ(fss::render::valenceColor(0), fss::render::minAngleColor(60)); // regular: green
    EXPECT_EQ(fss::render::valenceColor(1), fss::render::minAngleColor(30)); // yellow
    EXPECT_EQ(fss::render::valenceColor(2), fss::render::minAngleColor(15)); // orange
    EXPECT_EQ(fss::render::valenceColor(3), fss::render::minAngleColor(0));  // red
    EXPECT_EQ(fss::render::valenceColor(7), fss::render::minAngleColor(0));
    EXPECT_EQ(fss::render::valenceColor(-1), (Rgb{153, 153, 153})); // only boundary corners: grey
}

TEST(ColourMaps, ScanIdsGreyForInputAndApartByHue) {
    EXPECT_EQ(fss::render::scanIdColor(-1), (Rgb{153, 153, 153}));
    EXPECT_EQ(fss::render::scanIdColor(-7), (Rgb{153, 153, 153}));
    // Scan 0: hue 0.05 · 360 = 18°, saturation 0.8, value 0.95.
    EXPECT_EQ(fss::render::scanIdColor(0), (Rgb{242, 107, 48}));
    for (int a = 0; a < 12; ++a) {
        const Rgb ca = fss::render::scanIdColor(a);
        EXPECT_NEAR(saturationOf(ca), 0.8, 0.01) << a;
        EXPECT_EQ(std::max({ca[0], ca[1], ca[2]}), 242) << a; // value 0.95
        EXPECT_EQ(ca, fss::render::scanIdColor(a));           // depends on the id only
        for (int b = a + 1; b < 12; ++b) {
            const double d = std::abs(hueOf(ca) - hueOf(fss::render::scanIdColor(b)));
            EXPECT_GE(std::min(d, 360 - d), 20.0) << a << ' ' << b;
        }
    }
}

} // namespace
