#pragma once
/// \file colour_maps.h
/// The face colour maps of FSS's pictures, defined once: the head-less snapshots (snapshot.h,
/// `fss-remesh run --snapshot`) and the widgets' VtkView (ColorMap) colour faces with these, so a face
/// of the same quality has the same colour everywhere (before shading).

#include <array>
#include <cstdint>

namespace fss::render {

/// An 8-bit colour.
using Rgb = std::array<std::uint8_t, 3>;

/// The minimum-angle colour map: red (215, 25, 28) at 0°, yellow (250, 220, 40) at 30°, green
/// (26, 150, 65) at 60° (an equilateral triangle) and above, linear in between (rounded per channel).
Rgb minAngleColor(double minAngleDeg);

/// The valence colour map, by a face's worst vertex valence deviation |valence − 6| over its interior
/// corners: green 0 (regular), yellow 1, orange 2 (the minimum-angle map's colour at 15°), red 3 and more,
/// in the colours of minAngleColor; grey (153, 153, 153) for −1 (every corner on the boundary).
Rgb valenceColor(int deviation);

/// The scan-id colour map: neutral grey (153, 153, 153) for ids < 0 (input faces); otherwise the HSV
/// colour of hue frac(0.05 + 0.618034 · id), saturation 0.8, value 0.95 — the hue steps by the golden
/// ratio per id, so any two of the first dozen ids differ by at least ~20° of hue. Depends on the id only.
Rgb scanIdColor(int scanId);

} // namespace fss::render
