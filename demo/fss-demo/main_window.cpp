#include "main_window.h"

#include <fss/error.h>
#include <fss/face_groups.h>
#include <fss/mesh_io.h>
#include <fss/metrics.h>
#include <fss/render/fem_io.h>

#include <QActionGroup>
#include <QApplication>
#include <QElapsedTimer>
#include <QFileDialog>
#include <QFileInfo>
#include <QImage>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QSettings>
#include <QStatusBar>
#include <QThread>
#include <QTimer>
#include <QWindow>

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
    statistics_ = new QLabel(this);
    statusBar()->addPermanentWidget(statistics_, 1);
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
    file->addAction(tr("&Open…"), QKeySequence::Open, this, &MainWindow::openDialog);
    file->addAction(tr("&Save As…"), QKeySequence::SaveAs, this, &MainWindow::saveDialog);
    file->addSeparator();
    file->addAction(tr("Open Sess&ion…"), QKeySequence(tr("Ctrl+Shift+O")), this,
                    &MainWindow::openSessionDialog);
    file->addAction(tr("Save S&ession As…"), QKeySequence(tr("Ctrl+Shift+E")), this,
                    &MainWindow::saveSessionDialog);
    file->addSeparator();
    recentMenu_ = file->addMenu(tr("Open &Recent"));
    updateRecentMenu();
    file->addSeparator();
    file->addAction(tr("&Quit"), QKeySequence::Quit, this, &QWidget::close);

    QMenu* edit = menuBar()->addMenu(tr("&Edit"));
    edit->addAction(remesh_->undoAction());
    edit->addAction(remesh_->redoAction());
    edit->addSeparator();
    edit->addAction(remesh_->scanAction());
    edit->addAction(remesh_->acceptAction());
    edit->addAction(remesh_->rejectAction());

    QMenu* viewMenu = menuBar()->addMenu(tr("&View"));
    const std::pair<StandardView, const char*> views[] = {
        {StandardView::Iso, "&Iso"},      {StandardView::PosX, "From +&X"}, {StandardView::NegX, "From −X"},
        {StandardView::PosY, "From +&Y"}, {StandardView::NegY, "From −Y"},  {StandardView::PosZ, "From +&Z"},
        {StandardView::NegZ, "From −Z"}};
    for (const auto& [v, label] : views)
        viewMenu->addAction(tr(label), this, [this, v = v] { view()->setStandardView(v); });

    QMenu* colors = menuBar()->addMenu(tr("&Colour"));
    auto* group = new QActionGroup(this);
    const std::pair<widgets::ColorMap, const char*> maps[] = {{widgets::ColorMap::None, "&Plain"},
                                                              {widgets::ColorMap::MinAngle, "&Minimum angle"},
                                                              {widgets::ColorMap::Valence, "&Valence"}};
    for (const auto& [m, label] : maps) {
        QAction* action = colors->addAction(tr(label), this, [this, m = m] { view()->setColorMap(m); });
        action->setCheckable(true);
        action->setChecked(m == view()->colorMap());
        group->addAction(action);
        colorActions_.emplace_back(m, action);
    }
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
    addRecentFile(path);
    updateStatistics();
    return true;
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
    const QString path =
        QFileDialog::getOpenFileName(this, tr("Open mesh"), QFileInfo(meshPath_).path(),
                                     tr("Meshes (*.off *.obj *.ply *.stl *.msh *.vtu *.vtp *.vtk);;OFF "
                                        "(*.off);;OBJ (*.obj);;PLY (*.ply);;STL (*.stl);;gmsh MSH "
                                        "(*.msh);;VTK (*.vtu *.vtp *.vtk);;All files (*)"));
    if (!path.isEmpty()) openMesh(path);
}

void MainWindow::saveDialog() {
    const QString path = QFileDialog::getSaveFileName(
        this, tr("Save mesh"), meshPath_,
        tr("PLY, keeps scan ids and quality (*.ply);;OFF (*.off);;OBJ (*.obj);;STL (*.stl);;gmsh MSH 4.1, "
           "groups as physical surfaces (*.msh);;Abaqus INP (*.inp);;Nastran BDF (*.bdf *.nas);;I-deas UNV "
           "(*.unv);;VTK unstructured grid (*.vtu);;VTK poly data (*.vtp)"));
    if (!path.isEmpty()) saveMesh(path);
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
    addRecentFile(path);
    statusBar()->showMessage(tr("Session saved to %1.").arg(QFileInfo(path).fileName()), 5000);
    return true;
}

void MainWindow::openSessionDialog() {
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
