#pragma once
/// \file fishbone_tool.h
/// FishboneTool: the feature-sensitive grid (DESIGN.md §1 "Feature-sensitive (fishbone) grid";
/// fishbone.h, fishbone_scan.h). Click a seed on the mesh: the backbone (the streamline of the minimal or
/// maximal principal curvature direction through it) is shown; D switches the direction. Ribs are either
/// traced automatically from every backbone sample, or (key-rib mode, K) clicked key-rib positions on the
/// backbone — draggable along it — with blended ribs in between. The backbone or key-ribs may also be
/// drawn by hand (input modes). Every change asks for a new fishbone scan (paramsChanged()); RemeshWidget
/// runs it and hands the resulting grid back (setGrid()), which is shown over the view as the preview;
/// Enter accepts it.
///
/// Positions are kept in the view's device-independent pixels and converted to scan-image pixels by
/// params() (ScreenMapping; the scan resolution differs from the view size and the device pixel ratio).

#include "fss/fishbone.h"
#include "fss/fishbone_scan.h"
#include "fss/widgets/tool.h"

#include <QPointF>
#include <QPolygonF>
#include <QSize>

#include <optional>
#include <vector>

namespace fss::widgets {

/// The fishbone tool (see the file comment). It consumes left-button events and its keys (D, K, Esc,
/// Enter); the other buttons and the wheel still navigate.
class FishboneTool : public Tool {
    Q_OBJECT
public:
    /// How the ribs are made.
    enum class RibMode {
        Automatic, ///< a traced rib through every backbone sample
        KeyRibs,   ///< ribs at clicked (or drawn) key-rib positions, blended in between (≥ 2 needed)
    };
    /// What a left-button drag does.
    enum class InputMode {
        Pick,         ///< click: seed (first, or with Shift) and key-rib positions; drag a key-rib to move it
        DrawBackbone, ///< drag: draws the backbone by hand (replaces the seed)
        DrawRib,      ///< drag across the backbone: draws a key-rib by hand (key-rib mode)
    };

    /// A click within this distance (DIP) of a key-rib marker grabs it; a key-rib click farther than
    /// kSnapDistance from the shown backbone is refused.
    static constexpr double kGrabDistance = 8.0;
    static constexpr double kSnapDistance = 24.0;

    explicit FishboneTool(VtkView* view, QObject* parent = nullptr);
    ~FishboneTool() override;

    QString name() const override;
    QString statusText() const override;

    /// The principal direction the backbone follows (the ribs follow the other).
    PrincipalDirection direction() const { return direction_; }
    void setDirection(PrincipalDirection direction);
    /// Swaps min and max.
    void toggleDirection();
    RibMode ribMode() const { return ribMode_; }
    void setRibMode(RibMode mode);
    InputMode inputMode() const { return inputMode_; }
    void setInputMode(InputMode mode);

    /// The seed (DIP), if any.
    std::optional<QPointF> seed() const { return seed_; }
    /// Places the seed at \p p (DIP); clears key-ribs and a drawn backbone.
    void setSeed(const QPointF& p);
    /// Adds a key-rib at \p p (DIP), snapped to the nearest shown backbone sample; switches to key-rib mode.
    /// \return false (nothing changes) when there is no backbone yet or \p p is farther than kSnapDistance.
    bool addKeyRib(const QPointF& p);
    /// The key-rib positions (DIP, on the backbone).
    const std::vector<QPointF>& keyRibs() const { return keyRibs_; }
    /// The hand-drawn backbone (DIP), empty when none.
    const QPolygonF& drawnBackbone() const { return drawnBackbone_; }
    /// Sets a hand-drawn backbone (DIP, ≥ 2 points; fewer clear it); clears the seed.
    void setDrawnBackbone(const QPolygonF& points);
    /// The hand-drawn key-ribs (DIP).
    const std::vector<QPolygonF>& drawnRibs() const { return drawnRibs_; }
    /// Adds a hand-drawn key-rib (DIP, ≥ 2 points); switches to key-rib mode.
    void addDrawnRib(const QPolygonF& points);
    /// Forgets everything (seed, key-ribs, drawings, the shown grid).
    void clear();

    /// Whether the input suffices for a scan (a seed or a drawn backbone).
    bool hasInput() const { return seed_.has_value() || drawnBackbone_.size() >= 2; }
    /// True in key-rib mode with fewer than two key-ribs: the scan is only run to show the backbone
    /// (its automatic grid must not be accepted).
    bool backboneOnly() const;
    /// The parameters of the fishbone scan for a scan image of \p imageSize with sample spacing \p spacing
    /// (scan pixels); std::nullopt without input. In backboneOnly() state these are automatic-mode
    /// parameters (used to trace the backbone).
    std::optional<FishboneParams> params(QSize imageSize, double spacing) const;

    /// Shows \p grid (from the scan of params(); null clears): its backbone column and, unless
    /// backboneOnly(), its ribs, mapped from a scan image of \p imageSize to the view.
    void setGrid(const FishboneGrid* grid, QSize imageSize);
    /// Whether a grid preview (not just a backbone) is shown.
    bool hasGridPreview() const { return gridShown_ && !backboneOnly(); }
    /// The backbone as shown (DIP), empty when none.
    const QPolygonF& backbone() const { return backbone_; }
    /// Number of rib polylines shown.
    std::size_t ribCount() const { return ribs_.size(); }
    /// Shows \p message as the status until the next change (e.g. why the last scan failed).
    void setProblem(const QString& message);

signals:
    /// The input changed: a new fishbone scan should be run (or the preview dropped when !hasInput()).
    void paramsChanged();
    /// The user accepts the shown grid (Enter).
    void acceptRequested();

protected:
    bool handleEvent(QEvent* event) override;
    void onActivated() override;

private:
    void changed();
    void show();
    QPointF snapToBackbone(const QPointF& p, double* distance) const;

    PrincipalDirection direction_ = PrincipalDirection::Min;
    RibMode ribMode_ = RibMode::Automatic;
    InputMode inputMode_ = InputMode::Pick;
    std::optional<QPointF> seed_;
    std::vector<QPointF> keyRibs_;
    QPolygonF drawnBackbone_;
    std::vector<QPolygonF> drawnRibs_;
    QPolygonF stroke_; // a drawing in progress
    bool drawing_ = false;
    int dragIndex_ = -1; // key-rib being dragged
    QPolygonF backbone_; // shown (from the last grid)
    std::vector<QPolygonF> ribs_;
    bool gridShown_ = false;
    QString problem_;
};

} // namespace fss::widgets
