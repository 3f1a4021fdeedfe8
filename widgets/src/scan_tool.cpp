#include "fss/widgets/scan_tool.h"

#include "fss/error.h"
#include "fss/widgets/lasso_tool.h"
#include "fss/widgets/scan_panel.h"
#include "fss/widgets/vtk_view.h"

#include <QKeyEvent>

namespace fss::widgets {

ScanTool::ScanTool(VtkView* view, const ScanPanel* panel, const LassoTool* lasso, QObject* parent)
    : Tool(view, parent), panel_(panel), lasso_(lasso) {}

ScanTool::~ScanTool() = default;

QString ScanTool::name() const {
    return tr("Scan");
}

QString ScanTool::statusText() const {
    if (!isEnabled()) return tr("Please wait until the current work has finished.");
    if (previewPending_)
        return tr("Scan preview shown: press Accept (Enter) to stitch it in or Reject (Esc).");
    const QSize size = panel_->scanSize(QSizeF(view()->size()));
    const QString where = lasso_ && lasso_->hasLasso() ? tr("inside the lasso") : tr("of the whole view");
    return tr("Navigate to a view, then press Scan (Enter) for a %1×%2 scan %3.")
        .arg(size.width())
        .arg(size.height())
        .arg(where);
}

ScanStep ScanTool::step(std::int32_t scanId) const {
    if (!view()->hasMesh()) throw InvalidInputError("There is no mesh to scan: open a mesh first.");
    ScanStep step;
    step.params = panel_->scanParams(view()->camera());
    step.params.scan.scanId = scanId;
    if (lasso_)
        step.params.lasso = lasso_->scanLasso(QSize(step.params.camera.width, step.params.camera.height));
    return step;
}

void ScanTool::setPreviewPending(bool pending) {
    if (previewPending_ == pending) return;
    previewPending_ = pending;
    notifyStatus();
}

void ScanTool::requestScan() {
    emit scanRequested();
}

bool ScanTool::handleEvent(QEvent* event) {
    if (event->type() != QEvent::KeyPress) return false;
    auto* e = static_cast<QKeyEvent*>(event);
    if (e->key() == Qt::Key_Return || e->key() == Qt::Key_Enter) {
        if (previewPending_)
            emit acceptRequested();
        else
            emit scanRequested();
        return true;
    }
    if (e->key() == Qt::Key_Escape && previewPending_) {
        emit rejectRequested();
        return true;
    }
    return false;
}

} // namespace fss::widgets

#include "fss/widgets/moc_scan_tool.cpp" // meta-object code compiled here: widgets/CMakeLists.txt says why
