#pragma once
/// \file remesh_widget.h
/// RemeshWidget: the composite drop-in widget of FSS for a CAD / FEM preprocessor — a VtkView with the
/// tools (navigate, lasso, scan, fishbone), the ScanPanel, the QualityPanel and the history (a QUndoView
/// of undoStack()), a status line, and a progress bar with a Cancel button.
///
/// It owns a fss::Session (session.h): the mesh given to setMesh() / openMesh() is the session's
/// reference; every accepted scan changes the current mesh (mesh()), and every accept is one QUndoCommand
/// on undoStack() (undo / redo call Session::undo / redo). Scans are rendered on the GUI thread (they
/// need the view's GL context, or the CPU renderer); the long work — stitching (Session::accept) and the
/// curvature estimate of a first fishbone scan — runs on a worker thread with progress and Cancel, and the
/// tools are disabled meanwhile. The Session is touched by one thread at a time: while isBusy() the
/// widget does not call it from the GUI thread (undo / redo wait for the worker to finish).
///
/// **Trial stitch.** A stitch trims the parts of a patch it cannot glue in safely, and there the mesh keeps
/// its input faces. So that the preview shows what will replace the mesh, every new preview is stitched on
/// a copy of the current mesh on a second background thread (the trial: progress in the status bar,
/// Cancel stops it, the widget stays interactive and isBusy() stays false). When it has finished the
/// preview shades the faces the stitch keeps in VtkView::kPreview and those it trims in
/// VtkView::kPreviewTrimmed, and the status line says "N of M patch faces will be stitched". Accept then
/// reuses the trial's whole-mesh figures (valence 6, smallest angle before → after); the stitch itself is
/// run again by Session::accept (the session takes no precomputed result), which is deterministic: the
/// accepted mesh equals the trial's (trialMesh()).

#include "fss/mesh.h"
#include "fss/session.h"
#include "fss/stitch.h"

#include <QString>
#include <QWidget>

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

class QAction;
class QLabel;
class QProgressBar;
class QPushButton;
class QUndoStack;
class QUndoView;

namespace fss::widgets {

class FishboneTool;
class LassoTool;
class NavigateTool;
class QualityPanel;
class ScanPanel;
class ScanTool;
class Tool;
class VtkView;

/// The composite remeshing widget (see the file comment). Several may live in one process.
class RemeshWidget : public QWidget {
    Q_OBJECT
public:
    explicit RemeshWidget(QWidget* parent = nullptr);
    /// Cancels and waits for running work.
    ~RemeshWidget() override;
    RemeshWidget(const RemeshWidget&) = delete;
    RemeshWidget& operator=(const RemeshWidget&) = delete;

    /// Starts a new session on a copy of \p mesh (the reference): the history is cleared, the view shows
    /// the mesh from the initial view. Waits for running work first. An empty, non-triangle or invalid
    /// mesh is refused: errorOccurred() with one sentence, the previous mesh stays. \p meshPath names the
    /// file \p mesh was read from, if any (meshPath(); session files refer to it); without one the session
    /// starts from canonicalMesh(mesh) (same points and faces, the layout a file of it reads back as, so
    /// that a saved session replays exactly).
    /// \return whether the mesh was taken.
    bool setMesh(const Mesh& mesh, const QString& meshPath = {});
    /// Reads \p path (fss::readMesh: OFF, OBJ, PLY, STL) and calls setMesh(). On failure the previous
    /// mesh stays and errorOccurred() carries the reader's sentence. \return success
    bool openMesh(const QString& path);
    /// The current mesh (the reference with the accepted scans stitched in); empty before the first mesh.
    /// A copy owned by the GUI thread, safe to read at any time: while isBusy() it is the mesh before the
    /// running accept.
    const Mesh& mesh() const;
    /// The reference mesh of the session (empty before the first mesh).
    const Mesh& referenceMesh() const;
    /// Writes mesh() to \p path (fss::render::writeMeshFile; format by extension, FEM and VTK formats
    /// included), with the reference's face groups carried to it (fss::transferFaceGroups). On failure
    /// errorOccurred().
    /// \return success
    bool saveMesh(const QString& path);
    /// The file the reference mesh was read from (openMesh, loadSession; or the file saveSession wrote
    /// for a mesh given to setMesh); empty otherwise.
    QString meshPath() const;

    /// Saves the session as a session file (session_file.h): the reference mesh's path and SHA-256, the
    /// renderer kind, and the event log (every accepted scan, undo and redo). A pending preview is not
    /// part of it. When the reference has no file (it was given to setMesh), it is first written next to
    /// \p path as "<name>.input.ply" (binary: the replayed reference is bit-identical).
    /// Replaying the file (loadSession, `fss-remesh run`, fss::replaySession) with the same renderer kind
    /// reproduces mesh() exactly. Waits for running work first. On failure errorOccurred() (nothing is
    /// half-written). \return success
    bool saveSession(const QString& path);
    /// Loads a session file: validates it (errors name the offending field), reads its mesh, and replays
    /// its events on a new session — each scan on the GUI thread, each stitch and the curvature estimate
    /// on the worker thread, with progress over all events and Cancel. Only when every event has been
    /// replayed does the new session replace the current one (the undo stack then holds its steps, the
    /// undone ones redo-able); on a bad file, a failed event or Cancel, the current mesh and history stay
    /// and errorOccurred() says why (Cancel only sets the status line). The renderer is the recorded kind:
    /// "gpu" uses the view's GL context (the CPU renderer when the view has none; the status line then
    /// says the result may differ slightly from the recording), "cpu" the CPU renderer.
    /// \return whether the replay started (false: the file was refused, or work is running); the result
    ///         comes later by sessionLoaded() or errorOccurred().
    bool loadSession(const QString& path);
    /// Whether a session file is being replayed (loadSession).
    bool isLoadingSession() const;

    /// The undo stack: one command per accepted scan. Prefer undoAction() / redoAction(), which are
    /// disabled while work runs; calling undo()/redo() on the stack meanwhile waits for the work to end.
    QUndoStack* undoStack() const;
    /// Undo / redo actions of undoStack() (with the standard shortcuts), disabled while isBusy().
    QAction* undoAction() const;
    QAction* redoAction() const;
    /// The Scan, Accept and Reject actions of the tool bar.
    QAction* scanAction() const;
    QAction* acceptAction() const;
    QAction* rejectAction() const;

    /// The parts (owned by the widget).
    VtkView* view() const;
    ScanPanel* scanPanel() const;
    QualityPanel* qualityPanel() const;
    QUndoView* historyView() const;
    NavigateTool* navigateTool() const;
    LassoTool* lassoTool() const;
    ScanTool* scanTool() const;
    FishboneTool* fishboneTool() const;

    /// The tool receiving the mouse (one of the four above); Navigate initially.
    Tool* activeTool() const;
    /// Activates \p tool (one of the widget's tools) and deactivates the previous one.
    void setActiveTool(Tool* tool);

    /// The session (null before the first mesh). Do not call it while isBusy().
    const Session* session() const;
    /// Whether a scan preview is pending (Accept / Reject apply to it).
    bool hasPreview() const;
    /// Whether work runs on the worker thread (stitching, curvature).
    bool isBusy() const;
    /// The sentence in the status line: what the active tool expects next, or what is running.
    QString statusText() const;
    /// Whether the trial stitch of the pending preview is running (see the file comment).
    bool isTrialRunning() const;
    /// The trial stitch of the pending preview, once it has finished without error: the mesh Accept will
    /// make, its stitch report, and per face index of the preview's patch 1 (stitched) or 0 (trimmed).
    /// Null while it runs, after it failed or was cancelled, and without a preview.
    const Mesh* trialMesh() const;
    const StitchReport* trialReport() const;
    const std::vector<std::uint8_t>* trialStitchedFaces() const;
    /// Whether the view shows the reference mesh as a ghost (when the view supports it).
    bool ghostVisible() const { return ghost_; }

    /// The History name of accepted step \p number (from 1) made by \p step: its view (a standard view
    /// such as "from +X" when the camera looks along one, else "custom view"), its resolution and its
    /// grid kind, e.g. "1. Scan from +Z, 256×192 px, regular grid". After an accept the History entry
    /// adds acceptSummary().
    static QString stepName(int number, const ScanStep& step);
    /// What an accept did, shown in the status line and the History entry: faces replaced (StitchReport),
    /// the whole mesh's share of valence-6 interior vertices and its smallest angle before → after, and
    /// the stitch report's seam figures.
    static QString acceptSummary(const StitchReport& report, double valence6Before, double valence6After,
                                 double minAngleBefore, double minAngleAfter);

public slots:
    /// A regular scan (ScanTool::step: the view's camera at the panel's resolution, the lasso if any) on
    /// the GUI thread; the result becomes the preview. On failure errorOccurred() with the reason (the
    /// previous preview stays). \return success
    bool scan();
    /// Stitches the preview in on the worker thread (progress, Cancel); when it has finished, pushes the
    /// undo command and emits scanAccepted() and meshChanged(). Does nothing while busy or without a
    /// preview (errorOccurred() says so). Failures leave the mesh unchanged and emit errorOccurred().
    void accept();
    /// Drops the preview.
    void reject();
    /// Asks running work (or, when none runs, the trial stitch) to stop, honoured at its next progress
    /// report: a stitch stops between patch
    /// components and trim rounds (Session::accept then leaves the mesh unchanged and the preview stays),
    /// the curvature estimate between vertex blocks, a session replay (loadSession) at once.
    void cancel();
    /// Shows or hides the reference as a translucent ghost.
    void setGhostVisible(bool visible);

signals:
    /// mesh() changed: a new mesh, an accepted scan, undo or redo.
    void meshChanged();
    /// A scan was stitched in; \p report says what the stitch did.
    void scanAccepted(const fss::StitchReport& report);
    /// Something failed; \p message is one sentence for the user.
    void errorOccurred(const QString& message);
    /// statusText() changed.
    void statusChanged(const QString& text);
    /// isBusy() changed.
    void busyChanged(bool busy);
    /// A preview appeared or went away.
    void previewChanged();
    /// loadSession() replayed \p path: mesh() is its result and undoStack() its history.
    void sessionLoaded(const QString& path);
    /// The trial stitch of the preview ended (finished: trialMesh() is set; failed or cancelled: null, and
    /// the status line says so).
    void trialFinished();

private:
    struct Impl;
    std::unique_ptr<Impl> d_;
    bool ghost_ = false;

    friend class AcceptCommand;
    struct Replay;
    void undoStep();
    void redoStep();
    void installSession(std::unique_ptr<Session> session, const QString& meshPath, bool cpuRenderer,
                        const CurvatureOptions& curvature);
    void startWork(std::function<void(const Progress&)> work, std::function<void()> done);
    void replayNext();
    void finishReplay();
    void failReplay(const QString& message);
    void afterMeshChange();
    void showPreview();
    void updateTrial();
    void startTrial();
    void finishTrial();
    void stopTrial();
    QString trialText() const;
    void runFishbone();
    void createToolBar();
    void reportError(const QString& message);
    // Shows \p text in the status line until the next action.
    void setNote(const QString& text);
    bool eventFilter(QObject* watched, QEvent* event) override;
    void setBusy(bool busy, const QString& what = {});
    void updateStatus();
    void waitForWork();
};

} // namespace fss::widgets
