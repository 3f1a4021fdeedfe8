// The face colour maps of snapshots and widgets (colour_maps.h).
#include "fss/render/colour_maps.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace fss::render {
namespace {

constexpr Rgb kRed{215, 25, 28}, kYellow{250, 220, 40}, kGreen{26, 150, 65}, kGrey{153, 153, 153};

Rgb mix(const Rgb& a, const Rgb& b, double t) {
    Rgb c;
    for (int i = 0; i < 3; ++i)
        c[std::size_t(i)] =
            std::uint8_t(std::lround(a[std::size_t(i)] + t * (b[std::size_t(i)] - a[std::size_t(i)])));
    return c;
}

std::uint8_t byte(double unit) {
    return std::uint8_t(std::lround(std::clamp(unit, 0.0, 1.0) * 255));
}

} // namespace

Rgb minAngleColor(double minAngleDeg) {
    const double t = std::clamp(minAngleDeg / 60.0, 0.0, 1.0);
    return t < 0.5 ? mix(kRed, kYellow, t * 2) : mix(kYellow, kGreen, (t - 0.5) * 2);
}

Rgb valenceColor(int deviation) {
    switch (deviation) {
    case -1:
        return kGrey;
    case 0:
        return kGreen;
    case 1:
        return kYellow;
    case 2:
        return minAngleColor(15); // orange, halfway from red to yellow
    default:
        return kRed;
    }
}

Rgb scanIdColor(int scanId) {
    if (scanId < 0) return kGrey;
    // HSV → RGB with saturation 0.8 and value 0.95.
    const double hue = std::fmod(0.05 + 0.6180339887498949 * double(scanId), 1.0);
    constexpr double s = 0.80, v = 0.95;
    const double h6 = hue * 6;
    const int sector = std::min(int(std::floor(h6)), 5);
    const double f = h6 - sector;
    const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
    switch (sector) {
    case 0:
        return {byte(v), byte(t), byte(p)};
    case 1:
        return {byte(q), byte(v), byte(p)};
    case 2:
        return {byte(p), byte(v), byte(t)};
    case 3:
        return {byte(p), byte(q), byte(v)};
    case 4:
        return {byte(t), byte(p), byte(v)};
    default:
        return {byte(v), byte(p), byte(q)};
    }
}

} // namespace fss::render
