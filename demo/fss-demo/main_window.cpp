#include "main_window.h"

#include <fss/error.h>
#include <fss/mesh_io.h>
#include <fss/metrics.h>

#include <QActionGroup>
#include <QApplication>
#include <QElapsedTimer>
#include <QFileDialog>
#include <QFileInfo>
#include <QImage>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QStatusBar>
#include <QThread>
#include <QWindow>

#include <utility>

namespace fss::demo {

void MessageBoxPresenter::showError(QWidget* parent, const QString& title, const QString& message) {
    QMessageBox::critical(parent, title, message);
}

MainWindow::MainWindow(std::unique_ptr<MessagePresenter> presenter, QWidget* parent)
    : QMainWindow(parent), presenter_(std::move(presenter)) {
    if (!presenter_) presenter_ = std::make_unique<MessageBoxPresenter>();
    view_ = new widgets::VtkView(this);
    setCentralWidget(view_);
    statistics_ = new QLabel(this);
    statusBar()->addPermanentWidget(statistics_, 1);
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
    file->addAction(tr("&Quit"), QKeySequence::Quit, this, &QWidget::close);

    QMenu* viewMenu = menuBar()->addMenu(tr("&View"));
    const std::pair<StandardView, const char*> views[] = {
        {StandardView::Iso, "&Iso"},    {StandardView::PosX, "From +&X"}, {StandardView::NegX, "From −X"},
        {StandardView::PosY, "From +&Y"}, {StandardView::NegY, "From −Y"}, {StandardView::PosZ, "From +&Z"},
        {StandardView::NegZ, "From −Z"}};
    for (const auto& [v, label] : views)
        viewMenu->addAction(tr(label), this, [this, v = v] { view_->setStandardView(v); });

    QMenu* colors = menuBar()->addMenu(tr("&Colour"));
    auto* group = new QActionGroup(this);
    const std::pair<widgets::ColorMap, const char*> maps[] = {{widgets::ColorMap::None, "&Plain"},
                                                              {widgets::ColorMap::MinAngle, "&Minimum angle"},
                                                              {widgets::ColorMap::Valence, "&Valence"}};
    for (const auto& [m, label] : maps) {
        QAction* action = colors->addAction(tr(label), this, [this, m = m] { view_->setColorMap(m); });
        action->setCheckable(true);
        action->setChecked(m == view_->colorMap());
        group->addAction(action);
        colorActions_.emplace_back(m, action);
    }
}

void MainWindow::setColorMap(widgets::ColorMap map) {
    view_->setColorMap(map);
    for (auto& [m, action] : colorActions_) action->setChecked(m == map);
}

bool MainWindow::openMesh(const QString& path) {
    Mesh mesh;
    try {
        mesh = readMesh(path.toStdString());
    } catch (const std::exception& e) {
        reportError(tr("Open mesh"), QString::fromStdString(e.what()));
        return false;
    }
    meshPath_ = path;
    setMesh(std::move(mesh), QFileInfo(path).fileName());
    return true;
}

bool MainWindow::saveMesh(const QString& path) {
    try {
        writeMesh(mesh_, path.toStdString());
    } catch (const std::exception& e) {
        reportError(tr("Save mesh"), QString::fromStdString(e.what()));
        return false;
    }
    meshPath_ = path;
    meshName_ = QFileInfo(path).fileName();
    updateStatistics();
    return true;
}

void MainWindow::setMesh(Mesh mesh, const QString& name) {
    mesh_ = std::move(mesh);
    meshName_ = name;
    view_->setMesh(mesh_);
    updateStatistics();
    emit meshChanged();
}

QString MainWindow::statisticsText() const { return statistics_->text(); }

void MainWindow::reportError(const QString& title, const QString& message) {
    statusBar()->showMessage(message, 10000);
    presenter_->showError(this, title, message);
    emit errorOccurred(message);
}

void MainWindow::updateStatistics() {
    setWindowTitle(meshName_.isEmpty() ? QStringLiteral("FSS demo") : meshName_ + QStringLiteral(" — FSS demo"));
    if (mesh_.is_empty()) {
        statistics_->setText(tr("No mesh"));
        return;
    }
    MetricsOptions options;
    options.selfIntersections = false;
    const Metrics m = computeMetrics(mesh_, options);
    statistics_->setText(tr("%1: %2 vertices, %3 faces, valence 6: %4 % of %5 interior vertices, min angle %6°")
                             .arg(meshName_)
                             .arg(m.vertices)
                             .arg(m.faces)
                             .arg(100.0 * m.fracValence6Interior, 0, 'f', 1)
                             .arg(m.interiorVertices)
                             .arg(m.minAngleDeg, 0, 'f', 1));
}

void MainWindow::openDialog() {
    const QString path = QFileDialog::getOpenFileName(this, tr("Open mesh"), QFileInfo(meshPath_).path(),
                                                      tr("Meshes (*.off *.obj *.ply *.stl);;All files (*)"));
    if (!path.isEmpty()) openMesh(path);
}

void MainWindow::saveDialog() {
    const QString path = QFileDialog::getSaveFileName(this, tr("Save mesh"), meshPath_,
                                                      tr("Meshes (*.off *.obj *.ply *.stl)"));
    if (!path.isEmpty()) saveMesh(path);
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
