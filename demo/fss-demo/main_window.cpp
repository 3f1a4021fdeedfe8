#include "main_window.h"

#include <fss/error.h>
#include <fss/face_groups.h>
#include <fss/mesh_io.h>
#include <fss/metrics.h>
#include <fss/render/fem_io.h>

#include <QActionGroup>
#include <QApplication>
#include <QCloseEvent>
#include <QElapsedTimer>
#include <QFileDialog>
#include <QFileInfo>
#include <QImage>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QPushButton>
#include <QRegularExpression>
#include <QSettings>
#include <QStatusBar>
#include <QThread>
#include <QTimer>
#include <QUndoStack>
#include <QWindow>

#include <tuple>
#include <utility>

namespace fss::demo {

void MessageBoxPresenter::showError(QWidget* parent, const QString& title, const QString& message) {
    QMessageBox::critical(parent, title, message);
}

MainWindow::MainWindow(std::unique_ptr<MessagePresenter> presenter, QWidget* parent)
    : QMainWindow(parent), presenter_(std::move(presenter)) {
    if (!presenter_) presenter_ = std::make_unique<MessageBoxPresenter>();
    remesh_ = new widgets::RemeshWidget(this);
    setCentralWidget(remesh_);
    // At the right, without stretch: the status messages keep the rest of the bar.
    statistics_ = new QLabel(this);
    statistics_->setObjectName(QStringLiteral("statistics"));
    statusBar()->addPermanentWidget(statistics_, 0);
    connect(remesh_, &widgets::RemeshWidget::meshChanged, this, [this] {
        updateStatistics();
        emit meshChanged();
    });
    // Errors of the remeshing work (a scan that sees nothing, a stitch that fails) go to the status bar;
    // file errors are shown by openMesh / saveMesh through the presenter.
    connect(remesh_, &widgets::RemeshWidget::errorOccurred, this, [this](const QString& message) {
        if (sessionPending_) { // a session replay failed: as serious as a bad file
            sessionPending_ = false;
            reportError(tr("Open session"), message);
            return;
        }
        statusBar()->showMessage(message, 10000);
    });
    connect(remesh_, &widgets::RemeshWidget::sessionLoaded, this, [this](const QString& path) {
        sessionPending_ = false;
        remesh_->undoStack()->setClean(); // as in its file
        meshPath_ = remesh_->meshPath();
        meshName_ = QFileInfo(path).fileName();
        addRecentFile(path);
        updateStatistics();
        emit sessionLoaded(path);
    });
    // A cancelled replay ends without a signal of its own: forget it once its errors had their turn.
    connect(remesh_, &widgets::RemeshWidget::busyChanged, this, [this](bool busy) {
        if (!busy)
            QTimer::singleShot(0, this, [this] {
                if (!remesh_->isLoadingSession()) sessionPending_ = false;
            });
    });
    createMenus();
    setWindowTitle(QStringLiteral("FSS demo"));
    resize(1024, 768);
    updateStatistics();
}

MainWindow::~MainWindow() = default;

void MainWindow::createMenus() {
    QMenu* file = menuBar()->addMenu(tr("&File"));
    file->addAction(tr("&Open…"), QKeySequence(Qt::CTRL | Qt::Key_O), this, &MainWindow::openDialog)
        ->setObjectName(QStringLiteral("open"));
    // Explicit keys: QKeySequence::SaveAs has no binding on some platforms (xcb without a desktop).
    file->addAction(tr("&Save"), QKeySequence(Qt::CTRL | Qt::Key_S), this, &MainWindow::save)
        ->setObjectName(QStringLiteral("save"));
    file->addAction(tr("Save &As…"), QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_S), this,
                    &MainWindow::saveDialog)
        ->setObjectName(QStringLiteral("saveAs"));
    file->addSeparator();
    file->addAction(tr("Open Sess&ion…"), QKeySequence(tr("Ctrl+Shift+O")), this,
                    &MainWindow::openSessionDialog);
    file->addAction(tr("Save S&ession As…"), QKeySequence(tr("Ctrl+Shift+E")), this,
                    &MainWindow::saveSessionDialog);
    file->addSeparator();
    recentMenu_ = file->addMenu(tr("Open &Recent"));
    updateRecentMenu();
    file->addSeparator();
    file->addAction(tr("&Quit"), QKeySequence(Qt::CTRL | Qt::Key_Q), this, &QWidget::close)
        ->setObjectName(QStringLiteral("quit"));

    QMenu* edit = menuBar()->addMenu(tr("&Edit"));
    edit->addAction(remesh_->undoAction());
    edit->addAction(remesh_->redoAction());
    edit->addSeparator();
    edit->addAction(remesh_->scanAction());
    edit->addAction(remesh_->acceptAction());
    edit->addAction(remesh_->rejectAction());

    // Standard views on the number keys as in FreeCAD (0 iso, 1 front, 2 top, 3 right, 4 rear, 5 bottom,
    // 6 left; front looks along +y at the −y side).
    QMenu* viewMenu = menuBar()->addMenu(tr("&View"));
    const std::tuple<StandardView, const char*, Qt::Key> views[] = {
        {StandardView::Iso, "&Iso", Qt::Key_0},
        {StandardView::NegY, "&Front (from −Y)", Qt::Key_1},
        {StandardView::PosZ, "&Top (from +Z)", Qt::Key_2},
        {StandardView::PosX, "&Right (from +X)", Qt::Key_3},
        {StandardView::PosY, "R&ear (from +Y)", Qt::Key_4},
        {StandardView::NegZ, "&Bottom (from −Z)", Qt::Key_5},
        {StandardView::NegX, "&Left (from −X)", Qt::Key_6}};
    for (const auto& [v, label, key] : views)
        viewMenu->addAction(tr(label), QKeySequence(key), this, [this, v = v] { view()->setStandardView(v); })
            ->setObjectName(QStringLiteral("view-") + QString::fromStdString(standardViewName(v)));
    viewMenu->addAction(tr("F&rame the mesh"), QKeySequence(Qt::Key_R), this, [this] { view()->frameMesh(); })
        ->setObjectName(QStringLiteral("frame"));
    viewMenu->addSeparator();
    QAction* edges =
        viewMenu->addAction(tr("Show &edges"), this, [this](bool on) { view()->setEdgesVisible(on); });
    edges->setObjectName(QStringLiteral("edges"));
    edges->setCheckable(true);
    edges->setChecked(view()->edgesVisible());
    edges->setToolTip(tr("Draw the triangle edges (dense meshes look dark with them)"));
    QAction* axes =
        viewMenu->addAction(tr("Axis &triad"), this, [this](bool on) { view()->setAxesVisible(on); });
    axes->setObjectName(QStringLiteral("axes"));
    axes->setCheckable(true);
    axes->setChecked(view()->axesVisible());
    QMenu* up = viewMenu->addMenu(tr("&Up axis"));
    auto* upGroup = new QActionGroup(this);
    for (const auto& [axis, label] :
         {std::pair{widgets::VtkView::UpAxis::Z, "&Z up"}, std::pair{widgets::VtkView::UpAxis::Y, "&Y up"}}) {
        QAction* a = up->addAction(tr(label), this, [this, axis = axis] {
            view()->setUpAxis(axis);
            view()->setStandardView(StandardView::Iso);
        });
        a->setObjectName(axis == widgets::VtkView::UpAxis::Z ? QStringLiteral("up-z")
                                                             : QStringLiteral("up-y"));
        a->setCheckable(true);
        a->setChecked(view()->upAxis() == axis);
        upGroup->addAction(a);
    }

    QMenu* colors = menuBar()->addMenu(tr("&Colour"));
    auto* group = new QActionGroup(this);
    const std::pair<widgets::ColorMap, const char*> maps[] = {{widgets::ColorMap::None, "&Plain"},
                                                              {widgets::ColorMap::MinAngle, "&Minimum angle"},
                                                              {widgets::ColorMap::Valence, "&Valence"},
                                                              {widgets::ColorMap::ScanId, "&Scan id"}};
    for (const auto& [m, label] : maps) {
        QAction* action = colors->addAction(tr(label), this, [this, m = m] { view()->setColorMap(m); });
        action->setCheckable(true);
        action->setChecked(m == view()->colorMap());
        group->addAction(action);
        colorActions_.emplace_back(m, action);
        action->setObjectName(QStringLiteral("colour-") + widgets::colorMapName(m));
    }
    colors->addSeparator();
    QAction* legend =
        colors->addAction(tr("&Legend"), this, [this](bool on) { view()->setLegendVisible(on); });
    legend->setObjectName(QStringLiteral("legend"));
    legend->setCheckable(true);
    legend->setChecked(view()->legendVisible());

    QMenu* help = menuBar()->addMenu(tr("&Help"));
    help->addAction(tr("&Navigation keys"), QKeySequence::HelpContents, this,
                    [this] { QMessageBox::information(this, tr("Navigation keys"), navigationHelp()); })
        ->setObjectName(QStringLiteral("navigationHelp"));
    help->addAction(tr("&About FSS demo"), this, [this] {
        QMessageBox::about(this, tr("About FSS demo"),
                           tr("FSS %1: feature-sensitive remeshing by virtual range scanning.")
                               .arg(QApplication::applicationVersion()));
    });
}

QString MainWindow::navigationHelp() {
    return tr("<b>Mouse</b> (in the view): left drag rotates, middle drag or Shift + left drag pans, right "
              "drag or the wheel zooms.<br>"
              "<b>Keys</b>: R frames the mesh; 0 iso view, 1 front (−Y), 2 top (+Z), 3 right (+X), 4 rear "
              "(+Y), 5 bottom (−Z), 6 left (−X).<br>"
              "<b>Scanning</b>: Enter takes a scan (Scan tool, or in the Resolution / Target edge fields), "
              "Enter again accepts it, Esc rejects it or clears the lasso. Fishbone: D switches the "
              "curvature direction, K key-ribs.<br>"
              "<b>Edit</b>: Ctrl+Z undo, Ctrl+Shift+Z or Ctrl+Y redo; Ctrl+S save, Ctrl+Shift+S save as.");
}

widgets::VtkView* MainWindow::view() const {
    return remesh_->view();
}

const Mesh& MainWindow::mesh() const {
    return remesh_->mesh();
}

void MainWindow::setColorMap(widgets::ColorMap map) {
    view()->setColorMap(map);
    for (auto& [m, action] : colorActions_)
        action->setChecked(m == map);
}

bool MainWindow::openMesh(const QString& path) {
    Mesh mesh;
    try {
        mesh = render::readMeshFile(path.toStdString());
    } catch (const std::exception& e) {
        reportError(tr("Open mesh"), QString::fromStdString(e.what()));
        return false;
    }
    const QString previousPath = meshPath_, previousName = meshName_;
    meshPath_ = path;
    meshName_ = QFileInfo(path).fileName();
    if (!remesh_->setMesh(mesh, path)) {
        meshPath_ = previousPath;
        meshName_ = previousName;
        reportError(tr("Open mesh"),
                    tr("%1 cannot be remeshed: %2").arg(QFileInfo(path).fileName(), remesh_->statusText()));
        return false;
    }
    addRecentFile(path);
    return true;
}

bool MainWindow::saveMesh(const QString& path) {
    try {
        Mesh out = mesh();
        if (hasFaceGroups(remesh_->referenceMesh())) transferFaceGroups(remesh_->referenceMesh(), out);
        render::writeMeshFile(out, path.toStdString());
    } catch (const std::exception& e) {
        reportError(tr("Save mesh"), QString::fromStdString(e.what()));
        return false;
    }
    meshPath_ = path;
    meshName_ = QFileInfo(path).fileName();
    savePath_ = path;
    if (!remesh_->isBusy()) remesh_->undoStack()->setClean();
    addRecentFile(path);
    updateStatistics();
    statusBar()->showMessage(tr("Saved %1 (%2 faces).").arg(meshName_).arg(mesh().number_of_faces()), 8000);
    return true;
}

bool MainWindow::save() {
    if (savePath_.isEmpty()) {
        saveDialog();
        return !savePath_.isEmpty() && !hasUnsavedChanges();
    }
    return saveMesh(savePath_);
}

QString MainWindow::withFilterSuffix(const QString& path, const QString& filter) {
    static const QStringList known = {"off", "obj", "ply", "stl", "msh", "inp",
                                      "bdf", "nas", "unv", "vtu", "vtp"};
    if (known.contains(QFileInfo(path).suffix().toLower())) return path;
    const QRegularExpressionMatch m = QRegularExpression(QStringLiteral("\\*\\.(\\w+)")).match(filter);
    return m.hasMatch() ? path + QLatin1Char('.') + m.captured(1) : path;
}

bool MainWindow::hasUnsavedChanges() const {
    return remesh_->isBusy() || !remesh_->undoStack()->isClean();
}

bool MainWindow::maybeSave() {
    if (!hasUnsavedChanges()) return true;
    const int steps = remesh_->undoStack()->index();
    QString text = remesh_->isBusy() ? tr("A scan is being stitched in") : QString();
    if (!remesh_->undoStack()->isClean())
        text += (text.isEmpty() ? QString() : tr(", and ")) +
                (steps == 1 ? tr("1 accepted scan of %1 is not saved")
                            : tr("%1 accepted scans of %2 are not saved").arg(steps))
                    .arg(meshName_.isEmpty() ? tr("the mesh") : meshName_);
    QMessageBox box(QMessageBox::Warning, tr("Save changes?"), text + QLatin1Char('.'),
                    QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel, this);
    box.setObjectName(QStringLiteral("saveChanges"));
    box.setInformativeText(tr("Save the remeshed mesh before going on?"));
    box.setDefaultButton(QMessageBox::Save);
    switch (box.exec()) {
    case QMessageBox::Save:
        if (remesh_->isBusy()) return false; // the stitch must finish before its result can be saved
        return save();
    case QMessageBox::Discard:
        if (remesh_->isBusy()) remesh_->cancel(); // the widget waits for the worker when it goes
        return true;
    default:
        return false;
    }
}

void MainWindow::closeEvent(QCloseEvent* event) {
    if (maybeSave())
        event->accept();
    else
        event->ignore();
}

void MainWindow::setMesh(Mesh mesh, const QString& name) {
    const QString previous = meshName_;
    meshName_ = name;
    if (!remesh_->setMesh(mesh)) meshName_ = previous; // the widget reported why; the previous mesh stays
}

QStringList MainWindow::recentFiles() const {
    return QSettings().value(QStringLiteral("recentFiles")).toStringList();
}

void MainWindow::addRecentFile(const QString& path) {
    const QString absolute = QFileInfo(path).absoluteFilePath();
    QStringList files = recentFiles();
    files.removeAll(absolute);
    files.prepend(absolute);
    while (files.size() > kMaxRecentFiles)
        files.removeLast();
    QSettings().setValue(QStringLiteral("recentFiles"), files);
    updateRecentMenu();
}

void MainWindow::updateRecentMenu() {
    recentMenu_->clear();
    const QStringList files = recentFiles();
    for (int i = 0; i < files.size(); ++i) {
        const QString path = files[i];
        recentMenu_
            ->addAction(QStringLiteral("&%1 %2").arg(i + 1).arg(QFileInfo(path).fileName()), this,
                        [this, path] {
                            if (!maybeSave()) return;
                            if (path.endsWith(QLatin1String(".json"), Qt::CaseInsensitive))
                                openSession(path);
                            else
                                openMesh(path);
                        })
            ->setToolTip(path);
    }
    recentMenu_->setEnabled(!files.isEmpty());
}

QString MainWindow::statisticsText() const {
    return statistics_->text();
}

void MainWindow::reportError(const QString& title, const QString& message) {
    statusBar()->showMessage(message, 10000);
    presenter_->showError(this, title, message);
    emit errorOccurred(message);
}

void MainWindow::updateStatistics() {
    setWindowTitle(meshName_.isEmpty() ? QStringLiteral("FSS demo")
                                       : meshName_ + QStringLiteral(" — FSS demo"));
    if (mesh().is_empty()) {
        statistics_->setText(tr("No mesh"));
        return;
    }
    MetricsOptions options;
    options.selfIntersections = false;
    const Metrics m = computeMetrics(mesh(), options);
    statistics_->setText(
        tr("%1: %2 vertices, %3 faces, valence 6: %4 % of %5 interior vertices, min angle %6°")
            .arg(meshName_)
            .arg(m.vertices)
            .arg(m.faces)
            .arg(100.0 * m.fracValence6Interior, 0, 'f', 1)
            .arg(m.interiorVertices)
            .arg(m.minAngleDeg, 0, 'f', 1));
}

void MainWindow::openDialog() {
    if (!maybeSave()) return;
    const QString path =
        QFileDialog::getOpenFileName(this, tr("Open mesh"), QFileInfo(meshPath_).path(),
                                     tr("Meshes (*.off *.obj *.ply *.stl *.msh *.vtu *.vtp *.vtk);;OFF "
                                        "(*.off);;OBJ (*.obj);;PLY (*.ply);;STL (*.stl);;gmsh MSH "
                                        "(*.msh);;VTK (*.vtu *.vtp *.vtk);;All files (*)"));
    if (!path.isEmpty()) openMesh(path);
}

void MainWindow::saveDialog() {
    QString filter;
    const QString path = QFileDialog::getSaveFileName(
        this, tr("Save mesh"), savePath_.isEmpty() ? QFileInfo(meshPath_).path() : savePath_,
        tr("PLY, keeps scan ids and quality (*.ply);;OFF (*.off);;OBJ (*.obj);;STL (*.stl);;gmsh MSH 4.1, "
           "groups as physical surfaces (*.msh);;Abaqus INP (*.inp);;Nastran BDF (*.bdf *.nas);;I-deas UNV "
           "(*.unv);;VTK unstructured grid (*.vtu);;VTK poly data (*.vtp)"),
        &filter);
    if (!path.isEmpty()) saveMesh(withFilterSuffix(path, filter));
}

bool MainWindow::reportWidgetFailure(const QString& title, const std::function<bool()>& call) {
    QString error;
    const auto capture = connect(remesh_, &widgets::RemeshWidget::errorOccurred, this,
                                 [&error](const QString& message) { error = message; });
    const bool ok = call();
    disconnect(capture);
    if (!ok) reportError(title, error);
    return ok;
}

bool MainWindow::openSession(const QString& path) {
    if (!reportWidgetFailure(tr("Open session"), [&] { return remesh_->loadSession(path); })) return false;
    sessionPending_ = true;
    return true;
}

bool MainWindow::saveSession(const QString& path) {
    if (!reportWidgetFailure(tr("Save session"), [&] { return remesh_->saveSession(path); })) return false;
    remesh_->undoStack()->setClean();
    addRecentFile(path);
    statusBar()->showMessage(tr("Session saved to %1.").arg(QFileInfo(path).fileName()), 5000);
    return true;
}

void MainWindow::openSessionDialog() {
    if (!maybeSave()) return;
    const QString path = QFileDialog::getOpenFileName(this, tr("Open session"), QFileInfo(meshPath_).path(),
                                                      tr("FSS sessions (*.json);;All files (*)"));
    if (!path.isEmpty()) openSession(path);
}

void MainWindow::saveSessionDialog() {
    const QString path = QFileDialog::getSaveFileName(this, tr("Save session"),
                                                      QFileInfo(meshPath_).path() + QStringLiteral("/") +
                                                          QFileInfo(meshPath_).completeBaseName() +
                                                          QStringLiteral(".session.json"),
                                                      tr("FSS sessions (*.json)"));
    if (!path.isEmpty()) saveSession(path);
}

QString MainWindow::saveScreenshot(const QString& path) {
    show();
    raise();
    QElapsedTimer timer;
    timer.start();
    // The view needs an exposed window for its GL context; give the window system up to 10 s.
    while (!(windowHandle() && windowHandle()->isExposed()) && timer.elapsed() < 10000) {
        QApplication::processEvents(QEventLoop::AllEvents, 50);
        QThread::msleep(10);
    }
    if (!windowHandle() || !windowHandle()->isExposed())
        return tr("The window could not be shown, so no screenshot was taken (is a display available?).");
    QApplication::processEvents();
    const QImage image = grab().toImage();
    if (image.isNull()) return tr("The window could not be rendered into an image.");
    if (!image.save(path)) return tr("The screenshot could not be written to %1.").arg(path);
    return {};
}

} // namespace fss::demo

#include "moc_main_window.cpp" // meta-object code compiled here, as in widgets/ (one parse less)
