#pragma once
/// \file scan_tool.h
/// ScanTool: the regular virtual range scan (DESIGN.md §1 "Scan"): a grid of one sample per pixel of a
/// scan image at the ScanPanel's resolution, taken from the view's current camera, limited to the
/// LassoTool's polygon when there is one. The tool builds the ScanStep and asks for the scan, the accept
/// and the reject; RemeshWidget carries them out on its Session and shows the preview.

#include "fss/session.h"
#include "fss/widgets/tool.h"

namespace fss::widgets {

class LassoTool;
class ScanPanel;

/// The scan tool (see the file comment). While active, the mouse navigates; Enter asks for a scan (or
/// accepts the pending preview), Esc rejects the preview.
class ScanTool : public Tool {
    Q_OBJECT
public:
    /// \param panel the settings (not null); \param lasso the lasso to honour (may be null)
    ScanTool(VtkView* view, const ScanPanel* panel, const LassoTool* lasso, QObject* parent = nullptr);
    ~ScanTool() override;

    QString name() const override;
    QString statusText() const override;

    /// The step a scan now would take: the view's camera at the panel's resolution, the panel's radii
    /// and thresholds, the lasso (converted to scan-image pixels) when one is set, and \p scanId.
    /// \throw InvalidInputError when the view has no mesh.
    ScanStep step(std::int32_t scanId = -1) const;

    /// Tells the tool whether a preview is pending (changes what Enter / Esc do and the status text).
    void setPreviewPending(bool pending);
    bool previewPending() const { return previewPending_; }

public slots:
    /// Emits scanRequested() (the Scan button).
    void requestScan();

signals:
    /// The user asks for a scan.
    void scanRequested();
    /// The user accepts the pending preview.
    void acceptRequested();
    /// The user rejects the pending preview.
    void rejectRequested();

protected:
    bool handleEvent(QEvent* event) override;

private:
    const ScanPanel* panel_;
    const LassoTool* lasso_;
    bool previewPending_ = false;
};

} // namespace fss::widgets
