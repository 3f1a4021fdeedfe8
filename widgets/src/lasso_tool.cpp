#include "fss/widgets/lasso_tool.h"

#include "fss/widgets/screen_mapping.h"
#include "fss/widgets/vtk_view.h"
#include "view_bridge.h"

#include <QKeyEvent>
#include <QMouseEvent>

#include <cmath>

namespace fss::widgets {

LassoTool::LassoTool(VtkView* view, QObject* parent) : Tool(view, parent) {}

LassoTool::~LassoTool() = default;

QString LassoTool::name() const {
    return tr("Lasso");
}

QString LassoTool::statusText() const {
    if (!isEnabled()) return tr("Please wait until the current work has finished.");
    if (drawing_) return tr("Drag around the region to scan and release the button to close the lasso.");
    if (hasLasso())
        return tr("Lasso set: press Scan to sample inside it, draw a new one, or press Esc to clear it.");
    return tr("Drag with the left button around the region to scan (other buttons navigate).");
}

std::optional<Lasso> LassoTool::scanLasso(QSize imageSize) const {
    if (!hasLasso()) return std::nullopt;
    const ScreenMapping mapping{QSizeF(view()->size()), imageSize};
    if (!mapping.isValid()) return std::nullopt;
    Lasso lasso;
    for (const QPointF& p : polygon_)
        lasso.points.push_back(mapping.toImage(p));
    return lasso;
}

void LassoTool::setPolygon(const QPolygonF& polygon) {
    drawing_ = false;
    polygon_ = polygon.size() >= 3 ? polygon : QPolygonF();
    show();
    emit lassoChanged();
    if (hasLasso()) emit lassoFinished();
    notifyStatus();
}

void LassoTool::clear() {
    const bool had = drawing_ || !polygon_.isEmpty();
    drawing_ = false;
    polygon_.clear();
    bridge::clearLayer(view(), bridge::Layer::Lasso);
    if (had) {
        emit lassoChanged();
        notifyStatus();
    }
}

void LassoTool::onActivated() {
    show();
}

void LassoTool::show() {
    if (polygon_.isEmpty()) {
        bridge::clearLayer(view(), bridge::Layer::Lasso);
        return;
    }
    bridge::Stroke stroke;
    stroke.points.assign(polygon_.begin(), polygon_.end());
    stroke.color = drawing_ ? QColor(255, 230, 80) : QColor(255, 200, 0);
    stroke.closed = !drawing_;
    stroke.width = 2.0;
    bridge::setLayer(view(), bridge::Layer::Lasso, {std::move(stroke)});
}

bool LassoTool::handleEvent(QEvent* event) {
    switch (event->type()) {
    case QEvent::MouseButtonPress:
    case QEvent::MouseButtonDblClick: {
        auto* e = static_cast<QMouseEvent*>(event);
        if (e->button() != Qt::LeftButton) return false;
        drawing_ = true;
        polygon_ = QPolygonF{e->position()};
        show();
        emit lassoChanged();
        notifyStatus();
        return true;
    }
    case QEvent::MouseMove: {
        auto* e = static_cast<QMouseEvent*>(event);
        if (!drawing_) return false;
        const QPointF d = e->position() - polygon_.back();
        if (std::hypot(d.x(), d.y()) >= kMinStep) {
            polygon_ << e->position();
            show();
            emit lassoChanged();
        }
        return true;
    }
    case QEvent::MouseButtonRelease: {
        auto* e = static_cast<QMouseEvent*>(event);
        if (e->button() != Qt::LeftButton || !drawing_) return false;
        drawing_ = false;
        if (polygon_.back() != e->position()) polygon_ << e->position();
        if (polygon_.size() < 3) polygon_.clear();
        show();
        emit lassoChanged();
        if (hasLasso()) emit lassoFinished();
        notifyStatus();
        return true;
    }
    case QEvent::KeyPress: {
        auto* e = static_cast<QKeyEvent*>(event);
        if (e->key() != Qt::Key_Escape || (!drawing_ && polygon_.isEmpty())) return false;
        clear();
        return true;
    }
    default:
        return false;
    }
}

} // namespace fss::widgets

#include "fss/widgets/moc_lasso_tool.cpp" // meta-object code compiled here: widgets/CMakeLists.txt says why
