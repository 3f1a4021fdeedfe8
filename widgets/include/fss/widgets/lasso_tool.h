#pragma once
/// \file lasso_tool.h
/// LassoTool: press the left button, drag around the region to scan, release to close the polygon; Esc
/// cancels the lasso being drawn or clears the finished one. The polygon is kept in the view's
/// device-independent pixels and converted to the scan image's pixels by scanLasso().

#include "fss/mask.h"
#include "fss/widgets/tool.h"

#include <QPolygonF>
#include <QSize>
#include <QSizeF>

#include <optional>

namespace fss::widgets {

/// The lasso tool (see the file comment). It consumes left-button events and Esc; the other buttons
/// and the wheel still navigate. The polygon is shown over the view while it exists.
class LassoTool : public Tool {
    Q_OBJECT
public:
    /// A new point is recorded when the mouse has moved this far (DIP) from the last one.
    static constexpr double kMinStep = 2.0;

    explicit LassoTool(VtkView* view, QObject* parent = nullptr);
    ~LassoTool() override;

    QString name() const override;
    QString statusText() const override;

    /// The finished polygon in view DIP (empty while none or while drawing).
    QPolygonF polygon() const { return drawing_ ? QPolygonF() : polygon_; }
    /// Whether a finished lasso exists.
    bool hasLasso() const { return !drawing_ && polygon_.size() >= 3; }
    /// Whether a lasso is being drawn (button held).
    bool isDrawing() const { return drawing_; }
    /// The finished lasso in pixels of a scan image of \p imageSize taken from the view's camera
    /// (ScreenMapping with the view's current DIP size); std::nullopt when there is none.
    std::optional<Lasso> scanLasso(QSize imageSize) const;
    /// Sets a finished lasso programmatically (DIP); fewer than 3 points clear it.
    void setPolygon(const QPolygonF& polygon);
    /// Forgets the lasso (drawn or finished); emits lassoChanged() when there was one.
    void clear();

signals:
    /// The lasso was finished (button released with at least 3 points).
    void lassoFinished();
    /// The lasso changed in any way (started, extended, finished, cleared).
    void lassoChanged();

protected:
    bool handleEvent(QEvent* event) override;
    void onActivated() override;

private:
    void show();

    QPolygonF polygon_;
    bool drawing_ = false;
};

} // namespace fss::widgets
