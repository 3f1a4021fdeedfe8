#pragma once
/// \file main_window.h
/// The main window of fss-demo: a RemeshWidget (view, tools, panels, history) with File (open, save,
/// save as, sessions, recent files, quit), Edit (undo, redo), View (standard views with keys 0–6, frame
/// with R, edges, axis triad, up axis), Colour (maps, legend) and Help (navigation keys) menus and mesh
/// statistics at the right of the status bar. Errors go through a MessagePresenter so that tests can open
/// bad files without a modal box. Closing the window or opening another mesh with unsaved accepted scans
/// (or a stitch running) asks "Save changes?" (Save / Discard / Cancel).

#include <fss/camera.h>
#include <fss/mesh.h>
#include <fss/widgets/remesh_widget.h>
#include <fss/widgets/vtk_view.h>

#include <QMainWindow>
#include <QString>
#include <QStringList>

#include <functional>
#include <memory>
#include <utility>
#include <vector>

class QAction;
class QCloseEvent;
class QLabel;
class QMenu;

namespace fss::demo {

/// Shows an error to the user. The default (MessageBoxPresenter) opens a modal QMessageBox; tests and
/// the --screenshot mode install one that only records or prints.
class MessagePresenter {
public:
    virtual ~MessagePresenter() = default;
    /// Shows \p message (one sentence) with \p title over \p parent.
    virtual void showError(QWidget* parent, const QString& title, const QString& message) = 0;
};

/// A modal QMessageBox::critical.
class MessageBoxPresenter final : public MessagePresenter {
public:
    void showError(QWidget* parent, const QString& title, const QString& message) override;
};

/// The demo's main window around a RemeshWidget, which owns the mesh and its remeshing session.
class MainWindow : public QMainWindow {
    Q_OBJECT
public:
    /// \param presenter how errors are shown (a MessageBoxPresenter when null)
    explicit MainWindow(std::unique_ptr<MessagePresenter> presenter = nullptr, QWidget* parent = nullptr);
    ~MainWindow() override;

    /// Most recently opened or saved files kept in the recent-files menu.
    static constexpr int kMaxRecentFiles = 8;

    /// Reads \p path with fss::readMesh and shows it. On failure the previous mesh stays, the error (one
    /// sentence) is shown through the presenter and errorOccurred() is emitted. On success the file
    /// heads the recent files. \return success
    bool openMesh(const QString& path);
    /// Writes the current mesh to \p path (format by extension). On success the status bar says so, the
    /// work counts as saved and File › Save writes there again. On failure reports like openMesh.
    bool saveMesh(const QString& path);
    /// File › Save (Ctrl+S): writes the mesh to the file of the last Save As; without one, Save As.
    /// \return whether the mesh was written
    bool save();
    /// \p path with the suffix of the file dialog's name filter \p filter (e.g. "OFF (*.off)") appended
    /// when \p path has no suffix of a mesh format; unchanged otherwise.
    static QString withFilterSuffix(const QString& path, const QString& filter);
    /// Whether accepted scans are not saved yet (mesh or session) or a stitch is running.
    bool hasUnsavedChanges() const;
    /// Asks "Save changes?" with Save / Discard / Cancel when hasUnsavedChanges() (Save runs save()).
    /// \return true when the caller may go on (nothing unsaved, saved, or discarded)
    bool maybeSave();
    /// The text of Help › Navigation keys.
    static QString navigationHelp();
    /// Loads the session file \p path (RemeshWidget::loadSession): validates it and replays it with progress
    /// and Cancel; the result and its history replace the current session when the replay has finished
    /// (sessionLoaded()). A bad file or a failed replay is reported like openMesh's errors, and the previous
    /// mesh stays. On success the file heads the recent files. \return whether the replay started
    bool openSession(const QString& path);
    /// Saves the session (input mesh path and SHA-256, every accepted scan, undo and redo) to \p path
    /// (RemeshWidget::saveSession). On failure reports like openMesh. \return success
    bool saveSession(const QString& path);
    /// Shows \p mesh under the display name \p name (used in the title and status bar).
    void setMesh(Mesh mesh, const QString& name);

    /// The current mesh (empty before the first successful open): the input with the accepted scans.
    const Mesh& mesh() const;
    /// The file the current mesh came from (empty when none).
    QString meshPath() const { return meshPath_; }
    /// Colours the view by \p map and checks the matching Colour menu entry.
    void setColorMap(widgets::ColorMap map);

    /// The 3D view.
    widgets::VtkView* view() const;
    /// The remeshing widget (tools, panels, history).
    widgets::RemeshWidget* remeshWidget() const { return remesh_; }
    /// The recent files, most recent first (QSettings "recentFiles", at most kMaxRecentFiles).
    QStringList recentFiles() const;
    /// The statistics shown in the status bar.
    QString statisticsText() const;

    /// Shows the window, waits until it is exposed and rendered, and saves it as an image (PNG by the
    /// extension). \return an empty string on success, else one sentence saying why it failed.
    QString saveScreenshot(const QString& path);

protected:
    void closeEvent(QCloseEvent* event) override;

signals:
    /// An operation failed; \p message is the sentence shown to the user.
    void errorOccurred(const QString& message);
    /// A new mesh is shown.
    void meshChanged();
    /// openSession() has replayed \p path.
    void sessionLoaded(const QString& path);

private:
    void createMenus();
    void reportError(const QString& title, const QString& message);
    // Runs \p call (a RemeshWidget operation); when it returns false, reports the error the widget
    // emitted meanwhile under \p title. Returns what \p call returned.
    bool reportWidgetFailure(const QString& title, const std::function<bool()>& call);
    void updateStatistics();
    void openDialog();
    void saveDialog();
    void openSessionDialog();
    void saveSessionDialog();
    void addRecentFile(const QString& path);
    void updateRecentMenu();

    std::unique_ptr<MessagePresenter> presenter_;
    widgets::RemeshWidget* remesh_ = nullptr;
    QLabel* statistics_ = nullptr;
    QMenu* recentMenu_ = nullptr;
    std::vector<std::pair<widgets::ColorMap, QAction*>> colorActions_;
    QString meshPath_;
    QString meshName_;
    QString savePath_;            // the last Save As target: File › Save writes there
    bool sessionPending_ = false; // openSession started a replay whose errors go to the presenter
};

} // namespace fss::demo
