#pragma once
/// \file tool.h
/// Tools: what the mouse and the keyboard do in a VtkView. A tool is installed as an event filter on the
/// view while it is active: it takes the events it needs (the left button, for the lasso and the
/// fishbone) and lets the view's navigation have the others. Each tool says in one sentence what it
/// expects from the user next (statusText(), statusChanged()).

#include <QObject>
#include <QString>

namespace fss::widgets {

class VtkView;

/// Base class of the tools. Tools do not own the view; the view must outlive them or be destroyed
/// first (the filter is removed with it).
class Tool : public QObject {
    Q_OBJECT
public:
    /// A tool acting on \p view (not null), inactive until activate().
    explicit Tool(VtkView* view, QObject* parent = nullptr);
    ~Tool() override;

    /// The tool's name for buttons and menus ("Navigate", "Lasso", …).
    virtual QString name() const = 0;
    /// One sentence telling the user what the tool expects next.
    virtual QString statusText() const = 0;

    /// Installs the tool on the view (its event filter); emits statusChanged().
    void activate();
    /// Removes the tool's event filter; the tool keeps its state (a lasso stays until cleared).
    void deactivate();
    bool isActive() const { return active_; }

    /// A disabled tool ignores input (events pass through to the view's navigation); RemeshWidget
    /// disables the tools while work runs on a worker thread.
    void setEnabled(bool enabled);
    bool isEnabled() const { return enabled_; }

    VtkView* view() const { return view_; }

signals:
    /// statusText() changed (or the tool was activated).
    void statusChanged(const QString& text);

protected:
    /// Emits statusChanged(statusText()).
    void notifyStatus();
    /// Called after activate() / deactivate().
    virtual void onActivated() {}
    virtual void onDeactivated() {}
    /// Handles one event of the view while active and enabled; return true to consume it. The default
    /// consumes nothing.
    virtual bool handleEvent(QEvent* event);

private:
    bool eventFilter(QObject* watched, QEvent* event) override;

    VtkView* view_;
    bool active_ = false;
    bool enabled_ = true;
};

/// Navigation only: every event goes to the view's trackball camera.
class NavigateTool : public Tool {
    Q_OBJECT
public:
    explicit NavigateTool(VtkView* view, QObject* parent = nullptr);
    QString name() const override;
    QString statusText() const override;
};

} // namespace fss::widgets
