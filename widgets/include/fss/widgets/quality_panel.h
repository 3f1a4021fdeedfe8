#pragma once
/// \file quality_panel.h
/// QualityPanel: two histograms of the current mesh drawn with QPainter — the valence of the interior
/// vertices (regular = 6) and each triangle's smallest angle (equilateral = 60°).

#include "fss/mesh.h"

#include <QWidget>

#include <cstddef>
#include <map>
#include <vector>

namespace fss::widgets {

/// The mesh quality histograms (see the file comment). Call setMesh() whenever the mesh changes
/// (RemeshWidget does after every accept, undo and redo); the counts are computed in O(mesh) and kept,
/// the mesh itself is not referenced.
class QualityPanel : public QWidget {
    Q_OBJECT
public:
    /// Width of one minimum-angle bin in degrees; the bins are [0, 5), [5, 10), …, [55, 60] (a triangle's
    /// smallest angle is at most 60°).
    static constexpr double kAngleBinDeg = 5.0;
    /// Number of minimum-angle bins.
    static constexpr int kAngleBins = 12;

    explicit QualityPanel(QWidget* parent = nullptr);
    ~QualityPanel() override;

    /// Recomputes both histograms from \p mesh (removed elements ignored) and repaints.
    /// \pre every face is a triangle.
    void setMesh(const Mesh& mesh);
    /// Forgets the histograms (empty panel).
    void clear();

    /// Valence → number of interior vertices with it. Interior: a vertex with incident faces and no
    /// incident boundary edge (metrics.h's definition); its valence is its number of incident edges.
    const std::map<int, std::size_t>& valenceHistogram() const { return valence_; }
    /// kAngleBins counts of triangles by smallest corner angle (bin i: [5i, 5i+5) degrees; 60 in the last).
    const std::vector<std::size_t>& minAngleHistogram() const { return minAngle_; }
    /// Number of faces counted (the sum of minAngleHistogram()).
    std::size_t faceCount() const { return faces_; }
    /// How many times the histograms were recomputed (setMesh calls).
    std::size_t updateCount() const { return updates_; }

    QSize sizeHint() const override;
    QSize minimumSizeHint() const override;

signals:
    /// The histograms were recomputed.
    void updated();

protected:
    void paintEvent(QPaintEvent* event) override;

private:
    std::map<int, std::size_t> valence_;
    std::vector<std::size_t> minAngle_;
    std::size_t faces_ = 0;
    std::size_t updates_ = 0;
};

} // namespace fss::widgets
