#pragma once
// Pixel statistics of rendered images: how much of an image is covered by the mesh, and by which colours.
// Used instead of stored reference images (those break with every driver and font change).
#include <fss/widgets/vtk_view.h>

#include <QColor>
#include <QImage>
#include <QRect>

#include <cmath>
#include <cstdlib>
#include <functional>

namespace fss::test {

/// Fraction of the pixels of \p image (inside \p rect, the whole image when null) for which \p pred holds.
inline double pixelFraction(const QImage& image, const std::function<bool(QRgb)>& pred, QRect rect = {}) {
    if (rect.isNull()) rect = image.rect();
    rect &= image.rect();
    if (rect.isEmpty()) return 0;
    const QImage rgb = image.convertToFormat(QImage::Format_RGB32);
    long long hits = 0;
    for (int y = rect.top(); y <= rect.bottom(); ++y) {
        const auto* line = reinterpret_cast<const QRgb*>(rgb.constScanLine(y));
        for (int x = rect.left(); x <= rect.right(); ++x)
            hits += pred(line[x]) ? 1 : 0;
    }
    return double(hits) / double(rect.width()) / double(rect.height());
}

/// Not the view's background colour (any channel off by more than 12 of 255).
inline bool notBackground(QRgb p) {
    const double* bg = widgets::VtkView::kBackground;
    return std::abs(qRed(p) - int(std::lround(bg[0] * 255))) > 12 ||
           std::abs(qGreen(p) - int(std::lround(bg[1] * 255))) > 12 ||
           std::abs(qBlue(p) - int(std::lround(bg[2] * 255))) > 12;
}

/// The shaded plain surface colour (VtkView::kSurface is a warm tan: red well above blue, lit enough).
inline bool surfaceColored(QRgb p) {
    return qRed(p) > qBlue(p) + 25 && qGreen(p) > qBlue(p);
}

/// Green or yellow-green of the quality colour maps (good faces), shaded: green clearly above red and blue.
/// Neither the surface tan, nor yellow, nor the background qualifies.
inline bool qualityGreen(QRgb p) {
    return qGreen(p) > qBlue(p) + 30 && qGreen(p) > qRed(p) + 20;
}

} // namespace fss::test
