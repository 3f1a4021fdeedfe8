#include "fss/widgets/fishbone_tool.h"

#include "fss/widgets/screen_mapping.h"
#include "fss/widgets/vtk_view.h"
#include "view_bridge.h"

#include <QKeyEvent>
#include <QMouseEvent>

#include <cmath>
#include <limits>

namespace fss::widgets {

namespace {
double distance(const QPointF& a, const QPointF& b) {
    return std::hypot(a.x() - b.x(), a.y() - b.y());
}

QString directionName(PrincipalDirection d) {
    return d == PrincipalDirection::Min ? FishboneTool::tr("minimal") : FishboneTool::tr("maximal");
}

bridge::Stroke stroke(const QPolygonF& points, QColor color, qreal width, bool markers = false) {
    bridge::Stroke s;
    s.points.assign(points.begin(), points.end());
    s.color = color;
    s.width = width;
    s.markers = markers;
    return s;
}
} // namespace

FishboneTool::FishboneTool(VtkView* view, QObject* parent) : Tool(view, parent) {}

FishboneTool::~FishboneTool() = default;

QString FishboneTool::name() const {
    return tr("Fishbone");
}

QString FishboneTool::statusText() const {
    if (!isEnabled()) return tr("Please wait until the current work has finished.");
    if (!problem_.isEmpty()) return problem_;
    if (drawing_)
        return inputMode_ == InputMode::DrawBackbone ? tr("Release the button to finish the drawn backbone.")
                                                     : tr("Release the button to finish the drawn key-rib.");
    if (inputMode_ == InputMode::DrawBackbone)
        return tr("Drag along the feature to draw the backbone by hand.");
    if (inputMode_ == InputMode::DrawRib && !hasInput())
        return tr("Seed or draw a backbone first, then drag across it to draw key-ribs.");
    if (inputMode_ == InputMode::DrawRib) return tr("Drag across the backbone to draw a key-rib by hand.");
    if (!hasInput())
        return tr("Click a point on the mesh to seed the backbone along the %1 curvature direction (D "
                  "switches).")
            .arg(directionName(direction_));
    if (ribMode_ == RibMode::KeyRibs && backboneOnly())
        return tr("Click on the backbone to place key-rib %1 of at least 2 (Shift+click for a new seed).")
            .arg(keyRibs_.size() + drawnRibs_.size() + 1);
    if (!gridShown_) return tr("Computing the fishbone grid…");
    if (ribMode_ == RibMode::KeyRibs)
        return tr("Grid from %1 key-ribs previewed: drag a key-rib along the backbone, click to add one, "
                  "Enter "
                  "accepts.")
            .arg(keyRibs_.size() + drawnRibs_.size());
    return tr("Fishbone grid previewed: Enter accepts; click for a new seed, D switches direction, K places "
              "key-ribs instead.");
}

void FishboneTool::setDirection(PrincipalDirection direction) {
    if (direction_ == direction) return;
    direction_ = direction;
    // The backbone follows the other field now: key-ribs placed on the old one no longer apply.
    keyRibs_.clear();
    backbone_.clear();
    ribs_.clear();
    gridShown_ = false;
    changed();
}

void FishboneTool::toggleDirection() {
    setDirection(direction_ == PrincipalDirection::Min ? PrincipalDirection::Max : PrincipalDirection::Min);
}

void FishboneTool::setRibMode(RibMode mode) {
    if (ribMode_ == mode) return;
    ribMode_ = mode;
    gridShown_ = false;
    changed();
}

void FishboneTool::setInputMode(InputMode mode) {
    inputMode_ = mode;
    drawing_ = false;
    stroke_.clear();
    show();
    notifyStatus();
}

void FishboneTool::setSeed(const QPointF& p) {
    seed_ = p;
    keyRibs_.clear();
    drawnRibs_.clear();
    drawnBackbone_.clear();
    backbone_.clear();
    ribs_.clear();
    gridShown_ = false;
    changed();
}

bool FishboneTool::addKeyRib(const QPointF& p) {
    if (backbone_.size() < 2) {
        setProblem(tr("There is no backbone yet: click a seed first."));
        return false;
    }
    double d = 0;
    const QPointF snapped = snapToBackbone(p, &d);
    if (d > kSnapDistance) {
        setProblem(tr("That point is not on the backbone: click closer to the magenta line."));
        return false;
    }
    keyRibs_.push_back(snapped);
    ribMode_ = RibMode::KeyRibs;
    gridShown_ = false;
    changed();
    return true;
}

void FishboneTool::setDrawnBackbone(const QPolygonF& points) {
    drawnBackbone_ = points.size() >= 2 ? points : QPolygonF();
    seed_.reset();
    keyRibs_.clear();
    drawnRibs_.clear();
    backbone_.clear();
    ribs_.clear();
    gridShown_ = false;
    changed();
}

void FishboneTool::addDrawnRib(const QPolygonF& points) {
    if (points.size() < 2) return;
    drawnRibs_.push_back(points);
    ribMode_ = RibMode::KeyRibs;
    gridShown_ = false;
    changed();
}

void FishboneTool::clear() {
    seed_.reset();
    keyRibs_.clear();
    drawnBackbone_.clear();
    drawnRibs_.clear();
    stroke_.clear();
    drawing_ = false;
    dragIndex_ = -1;
    backbone_.clear();
    ribs_.clear();
    gridShown_ = false;
    changed();
}

bool FishboneTool::backboneOnly() const {
    return ribMode_ == RibMode::KeyRibs && keyRibs_.size() + drawnRibs_.size() < 2;
}

std::optional<FishboneParams> FishboneTool::params(QSize imageSize, double spacing) const {
    if (!hasInput()) return std::nullopt;
    const ScreenMapping mapping{QSizeF(view()->size()), imageSize};
    if (!mapping.isValid()) return std::nullopt;
    FishboneParams p;
    p.direction = direction_;
    p.spacing = spacing;
    if (drawnBackbone_.size() >= 2)
        for (const QPointF& q : drawnBackbone_)
            p.drawnBackbone.push_back(mapping.toImage(q));
    else
        p.seed = mapping.toImage(*seed_);
    if (ribMode_ == RibMode::KeyRibs && !backboneOnly()) {
        for (const QPointF& q : keyRibs_)
            p.keyRibs.push_back(mapping.toImage(q));
        for (const QPolygonF& rib : drawnRibs_) {
            Polyline2 line;
            for (const QPointF& q : rib)
                line.push_back(mapping.toImage(q));
            p.drawnKeyRibs.push_back(std::move(line));
        }
    }
    return p;
}

void FishboneTool::setGrid(const FishboneGrid* grid, QSize imageSize) {
    backbone_.clear();
    ribs_.clear();
    gridShown_ = false;
    const ScreenMapping mapping{QSizeF(view()->size()), imageSize};
    if (grid && mapping.isValid()) {
        for (int r = 0; r < grid->rows; ++r)
            if (grid->isPresent(r, grid->backboneColumn))
                backbone_ << mapping.toView(grid->at(r, grid->backboneColumn));
        if (!backboneOnly())
            for (int r = 0; r < grid->rows; ++r) {
                QPolygonF rib;
                for (int c = 0; c < grid->cols; ++c)
                    if (grid->isPresent(r, c)) rib << mapping.toView(grid->at(r, c));
                if (rib.size() >= 2) ribs_.push_back(std::move(rib));
            }
        gridShown_ = true;
    }
    problem_.clear();
    show();
    notifyStatus();
}

void FishboneTool::setProblem(const QString& message) {
    problem_ = message;
    notifyStatus();
}

void FishboneTool::onActivated() {
    show();
}

void FishboneTool::changed() {
    problem_.clear();
    show();
    notifyStatus();
    emit paramsChanged();
}

void FishboneTool::show() {
    std::vector<bridge::Stroke> strokes;
    for (const QPolygonF& rib : ribs_)
        strokes.push_back(stroke(rib, QColor(80, 220, 255), 1.0));
    if (!backbone_.isEmpty()) strokes.push_back(stroke(backbone_, QColor(255, 60, 200), 3.0));
    if (drawnBackbone_.size() >= 2) strokes.push_back(stroke(drawnBackbone_, QColor(255, 230, 80), 1.5));
    for (const QPolygonF& rib : drawnRibs_)
        strokes.push_back(stroke(rib, QColor(255, 230, 80), 1.5));
    if (!stroke_.isEmpty()) strokes.push_back(stroke(stroke_, QColor(255, 255, 120), 2.0));
    if (seed_) strokes.push_back(stroke(QPolygonF{*seed_}, QColor(255, 60, 200), 3.0, true));
    for (const QPointF& k : keyRibs_)
        strokes.push_back(stroke(QPolygonF{k}, QColor(255, 160, 0), 3.0, true));
    if (strokes.empty())
        bridge::clearLayer(view(), bridge::Layer::Fishbone);
    else
        bridge::setLayer(view(), bridge::Layer::Fishbone, std::move(strokes));
}

QPointF FishboneTool::snapToBackbone(const QPointF& p, double* dist) const {
    QPointF best = p;
    double bestD = std::numeric_limits<double>::infinity();
    for (const QPointF& q : backbone_)
        if (const double d = distance(p, q); d < bestD) {
            bestD = d;
            best = q;
        }
    if (dist) *dist = bestD;
    return best;
}

bool FishboneTool::handleEvent(QEvent* event) {
    switch (event->type()) {
    case QEvent::MouseButtonPress:
    case QEvent::MouseButtonDblClick: {
        auto* e = static_cast<QMouseEvent*>(event);
        if (e->button() != Qt::LeftButton) return false;
        const QPointF p = e->position();
        if (inputMode_ != InputMode::Pick) {
            drawing_ = true;
            stroke_ = QPolygonF{p};
            show();
            notifyStatus();
            return true;
        }
        if (!hasInput() || (e->modifiers() & Qt::ShiftModifier) || ribMode_ == RibMode::Automatic) {
            setSeed(p);
            return true;
        }
        for (std::size_t i = 0; i < keyRibs_.size(); ++i)
            if (distance(keyRibs_[i], p) <= kGrabDistance) {
                dragIndex_ = int(i);
                return true;
            }
        addKeyRib(p);
        return true;
    }
    case QEvent::MouseMove: {
        auto* e = static_cast<QMouseEvent*>(event);
        if (dragIndex_ >= 0) {
            double d = 0;
            const QPointF snapped = snapToBackbone(e->position(), &d);
            if (d <= kSnapDistance) keyRibs_[std::size_t(dragIndex_)] = snapped;
            show();
            return true;
        }
        if (drawing_) {
            if (distance(stroke_.back(), e->position()) >= 2.0) {
                stroke_ << e->position();
                show();
            }
            return true;
        }
        return false;
    }
    case QEvent::MouseButtonRelease: {
        auto* e = static_cast<QMouseEvent*>(event);
        if (e->button() != Qt::LeftButton) return false;
        if (dragIndex_ >= 0) {
            dragIndex_ = -1;
            gridShown_ = false;
            changed();
            return true;
        }
        if (drawing_) {
            drawing_ = false;
            if (stroke_.back() != e->position()) stroke_ << e->position();
            const QPolygonF drawn = stroke_;
            stroke_.clear();
            if (drawn.size() < 2) {
                show();
                notifyStatus();
            } else if (inputMode_ == InputMode::DrawBackbone) {
                setDrawnBackbone(drawn);
            } else {
                addDrawnRib(drawn);
            }
            return true;
        }
        return true;
    }
    case QEvent::KeyPress: {
        auto* e = static_cast<QKeyEvent*>(event);
        switch (e->key()) {
        case Qt::Key_D:
            toggleDirection();
            return true;
        case Qt::Key_K:
            setRibMode(ribMode_ == RibMode::KeyRibs ? RibMode::Automatic : RibMode::KeyRibs);
            return true;
        case Qt::Key_Escape:
            clear();
            return true;
        case Qt::Key_Return:
        case Qt::Key_Enter:
            if (hasGridPreview()) emit acceptRequested();
            return true;
        default:
            return false;
        }
    }
    default:
        return false;
    }
}

} // namespace fss::widgets

#include "fss/widgets/moc_fishbone_tool.cpp" // meta-object code compiled here: widgets/CMakeLists.txt says why
