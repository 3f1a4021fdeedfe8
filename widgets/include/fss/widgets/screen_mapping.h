#pragma once
/// \file screen_mapping.h
/// Positions the user gives with the mouse are in Qt's device-independent pixels (DIP) of the view; the
/// scan pipeline wants pixels of the scan image (camera.h: top-left origin, y down), whose size is the
/// scan resolution and has nothing to do with the window size or the screen's device pixel ratio. A scan
/// camera is the view's camera with another image size (same aspect up to rounding), so the view's
/// rectangle maps onto the image's rectangle by one scale per axis.

#include <Eigen/Core>

#include <QPointF>
#include <QSize>
#include <QSizeF>

namespace fss::widgets {

/// Maps between view DIP and scan-image pixels (see the file comment).
struct ScreenMapping {
    QSizeF view; ///< the view's size in device-independent pixels (QWidget::size())
    QSize image; ///< the scan image's size in pixels (Camera::width × Camera::height)

    /// Whether both sizes are non-empty.
    bool isValid() const { return !view.isEmpty() && !image.isEmpty(); }
    /// A view position (DIP) → scan-image pixel position (sub-pixel; pixel (i, j) covers [i, i+1) × [j,
    /// j+1)).
    Eigen::Vector2d toImage(const QPointF& p) const {
        return {p.x() * image.width() / view.width(), p.y() * image.height() / view.height()};
    }
    /// A scan-image pixel position → view position (DIP); the inverse of toImage.
    QPointF toView(const Eigen::Vector2d& p) const {
        return {p.x() * view.width() / image.width(), p.y() * view.height() / image.height()};
    }
};

} // namespace fss::widgets
