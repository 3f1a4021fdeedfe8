#pragma once
/// \file scan_panel.h
/// ScanPanel: the settings of the next scan — the target edge length in world units or the resolution
/// (whichever was set last is held as the view changes; the edge length the resolution gives is shown),
/// the sample lattice, its slant mask and its warp to the surface, erosion / dilation radii, the
/// triangulation and quality thresholds, force-replace, and the fishbone grid's spacing — and the scan camera
/// they make from the view's camera.

#include "fss/camera.h"
#include "fss/scan_pipeline.h"

#include <Eigen/Core>

#include <QWidget>

#include <optional>

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QSpinBox;

namespace fss::widgets {

/// The scan settings panel (see the file comment). Every value has a getter and a setter so that
/// applications and tests can drive it without the mouse; settingsChanged() follows every change.
class ScanPanel : public QWidget {
    Q_OBJECT
public:
    explicit ScanPanel(QWidget* parent = nullptr);
    ~ScanPanel() override;

    /// Scan resolution: the number of pixels (samples) along the longer side of the scan image; the
    /// shorter side follows the view's aspect. Clamped to [16, 4096]; default 256. Setting it (or typing
    /// it) holds the resolution: followsTargetEdgeLength() becomes false.
    int resolution() const;
    void setResolution(int pixels);

    /// The target edge length of a scan in world units: while followsTargetEdgeLength(), the resolution is
    /// the one whose pixel footprint at the measuring point (updateEdgeLength) is closest to it, clamped to
    /// [16, 4096], recomputed whenever the view changes. Setting it (or typing it) makes the resolution
    /// follow it. setInputEdgeLength() sets it to the input's mean edge length.
    double targetEdgeLength() const;
    void setTargetEdgeLength(double length);
    /// Whether the resolution follows targetEdgeLength() (true after setTargetEdgeLength or
    /// setInputEdgeLength, false after setResolution; the "Keep edge length" check box).
    bool followsTargetEdgeLength() const;
    void setFollowsTargetEdgeLength(bool follow);
    /// Shows the input mesh's mean edge length \p meanEdge (world units; ≤ 0: no mesh), makes it the target
    /// edge length (the field's decimals and step adapt to its scale) and lets the resolution follow it.
    void setInputEdgeLength(double meanEdge);
    /// The input's mean edge length shown (0 when none).
    double inputEdgeLength() const { return inputEdge_; }
    /// Morphological erosion radius in grid samples, [0, 8]; default 1.
    int erodeRadius() const;
    void setErodeRadius(int radius);
    /// Dilation radius after the erosion, [0, 8]; default 1 (never re-admits rejected samples).
    int dilateRadius() const;
    void setDilateRadius(int radius);
    /// Triangles with an edge longer than this many pixel footprints span a depth step and are dropped
    /// (TriangulateOptions::maxEdgeFootprints), [1, 20]; default 3.
    double maxEdgeFootprints() const;
    void setMaxEdgeFootprints(double footprints);
    /// Grazing limit in degrees (TriangulateOptions::maxSamplingAngleDeg), [10, 90]; default 80.
    double maxSamplingAngleDeg() const;
    void setMaxSamplingAngleDeg(double degrees);
    /// Quality margin (QualityMaskOptions::margin), [0, 0.9]; default 0.1.
    double qualityMargin() const;
    void setQualityMargin(double margin);
    /// The sample lattice of regular scans (ScanOptions::lattice); default the core's (Lattice::Adaptive).
    /// Lattice::Square is the paper's pixel lattice.
    Lattice lattice() const;
    void setLattice(Lattice lattice);
    /// Lattice-angle mask in degrees (ScanOptions::minLatticeAngleDeg, 0 = off), [0, 59]; default the
    /// core's (35).
    double minLatticeAngleDeg() const;
    void setMinLatticeAngleDeg(double degrees);
    /// The adaptive lattice warped to the surface (ScanOptions::warpToSurface); default the core's (on). The
    /// switch is enabled only while lattice() is Lattice::Adaptive; its state goes into scanParams() (and so
    /// into the session) whatever the lattice, where the other lattices ignore it.
    bool warpToSurface() const;
    void setWarpToSurface(bool warp);
    /// Keep every sample regardless of the current mesh's quality (QualityMaskOptions::forceReplace).
    bool forceReplace() const;
    void setForceReplace(bool force);
    /// Fishbone grid spacing h in scan-image pixels (FishboneParams::spacing), [0.5, 32]; default 2.
    double fishboneSpacing() const;
    void setFishboneSpacing(double pixels);
    /// Fishbones traced on the full scan image (FishboneParams::samplingFactor = 1: finer direction fields,
    /// better feature alignment, up to h² times the render cost) instead of the sampling image of about one
    /// pixel per sample (samplingFactor = 0, automatic). Default false.
    bool fishboneFineField() const;
    void setFishboneFineField(bool fine);
    /// The FishboneParams::samplingFactor these settings ask for: 1 with the fine field, else 0.
    int fishboneSamplingFactor() const { return fishboneFineField() ? 1 : 0; }

    /// The scan image size for a view image of \p viewSize (any unit): the longer side is resolution(),
    /// the other keeps the aspect (at least 1).
    QSize scanSize(QSizeF viewSize) const;
    /// The view's camera (as VtkView::camera()) with the scan image size of scanSize().
    Camera scanCamera(const Camera& viewCamera) const;
    /// The scan parameters for \p viewCamera: scanCamera(), the lattice, radii, thresholds and force-replace;
    /// no lasso (the caller adds it) and scan id −1.
    ScanParams scanParams(const Camera& viewCamera) const;

    /// Updates the edge-length line for \p viewCamera, measured at world point \p at (e.g. the centre of
    /// the mesh): one regular-grid edge is the scan camera's pixel footprint there. std::nullopt clears it.
    void updateEdgeLength(const std::optional<Camera>& viewCamera, const Eigen::Vector3d& at = {0, 0, 0});
    /// The edge length currently shown (world units; 0 when none).
    double edgeLength() const { return edgeLength_; }
    /// The text of the edge-length line.
    QString edgeLengthText() const;

signals:
    /// Some setting changed (by the user or a setter).
    void settingsChanged();
    /// Enter was pressed in the resolution or target edge length field: take a scan.
    void scanRequested();

protected:
    bool eventFilter(QObject* watched, QEvent* event) override;

private:
    void refreshEdgeLength();
    // While following the target: sets the resolution whose footprint is closest to it.
    void applyTarget();
    // The pixel footprint at the measuring point of a scan of resolution \p pixels (0 when unknown).
    double footprintAt(int pixels) const;

    QSpinBox* resolution_ = nullptr;
    QSpinBox* erode_ = nullptr;
    QSpinBox* dilate_ = nullptr;
    QDoubleSpinBox* maxEdge_ = nullptr;
    QDoubleSpinBox* maxAngle_ = nullptr;
    QDoubleSpinBox* margin_ = nullptr;
    QCheckBox* force_ = nullptr;
    QComboBox* lattice_ = nullptr;
    QDoubleSpinBox* minLatticeAngle_ = nullptr;
    QCheckBox* warp_ = nullptr;
    QDoubleSpinBox* spacing_ = nullptr;
    QCheckBox* fineField_ = nullptr;
    QLabel* edgeLabel_ = nullptr;
    QDoubleSpinBox* target_ = nullptr;
    QCheckBox* follow_ = nullptr;
    QLabel* inputLabel_ = nullptr;
    double inputEdge_ = 0;
    bool applying_ = false; // applyTarget is setting the resolution
    std::optional<Camera> viewCamera_;
    Eigen::Vector3d at_{0, 0, 0};
    double edgeLength_ = 0;
};

} // namespace fss::widgets
