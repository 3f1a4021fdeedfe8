#include "fss/widgets/tool.h"

#include "fss/widgets/vtk_view.h"

#include <QEvent>

namespace fss::widgets {

Tool::Tool(VtkView* view, QObject* parent) : QObject(parent), view_(view) {}

Tool::~Tool() {
    if (active_ && view_) view_->removeEventFilter(this);
}

void Tool::activate() {
    if (!active_) {
        view_->installEventFilter(this);
        active_ = true;
        onActivated();
    }
    notifyStatus();
}

void Tool::deactivate() {
    if (!active_) return;
    view_->removeEventFilter(this);
    active_ = false;
    onDeactivated();
}

void Tool::setEnabled(bool enabled) {
    if (enabled_ == enabled) return;
    enabled_ = enabled;
    notifyStatus();
}

void Tool::notifyStatus() {
    emit statusChanged(statusText());
}

bool Tool::handleEvent(QEvent*) {
    return false;
}

bool Tool::eventFilter(QObject* watched, QEvent* event) {
    if (watched != view_ || !active_ || !enabled_) return false;
    return handleEvent(event);
}

NavigateTool::NavigateTool(VtkView* view, QObject* parent) : Tool(view, parent) {}

QString NavigateTool::name() const {
    return tr("Navigate");
}

QString NavigateTool::statusText() const {
    return tr("Drag with the left button to rotate, the middle button (or Shift) to pan, the wheel to zoom.");
}

} // namespace fss::widgets

#include "fss/widgets/moc_tool.cpp" // meta-object code compiled here: widgets/CMakeLists.txt says why
