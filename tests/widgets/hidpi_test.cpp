// RemeshWidget on a HiDPI screen (QT_SCALE_FACTOR=2, device pixel ratio 2 under Xvfb): mouse positions
// arrive in device-independent pixels, the view's camera has twice as many device pixels, and the scan
// image has the ScanPanel's resolution — lasso and fishbone positions must land where the user pointed.
#include <fss/camera.h>
#include <fss/mask.h>
#include <fss/shapes.h>
#include <fss/widgets/fishbone_tool.h>
#include <fss/widgets/lasso_tool.h>
#include <fss/widgets/remesh_widget.h>
#include <fss/widgets/scan_panel.h>
#include <fss/widgets/scan_tool.h>
#include <fss/widgets/screen_mapping.h>
#include <fss/widgets/vtk_view.h>

#include <QApplication>
#include <QLineF>
#include <QMouseEvent>
#include <QTest>

#include <cmath>
#include <memory>
#include <numbers>

using fss::widgets::RemeshWidget;

namespace {

void sendMouse(QWidget* w, QEvent::Type type, QPointF pos, Qt::MouseButton button, Qt::MouseButtons buttons) {
    QMouseEvent event(type, pos, w->mapToGlobal(pos), button, buttons, Qt::NoModifier);
    QApplication::sendEvent(w, &event);
}

std::unique_ptr<RemeshWidget> shownWidget(const fss::Mesh& mesh) {
    auto w = std::make_unique<RemeshWidget>();
    w->resize(900, 600);
    w->show();
    if (!QTest::qWaitForWindowExposed(w.get()) || !w->setMesh(mesh)) return nullptr;
    QTest::qWait(20);
    return w;
}

} // namespace

class HiDpiTest : public QObject {
    Q_OBJECT
private slots:
    void lassoLandsWhereDrawn() {
        auto w = shownWidget(fss::shapes::icosphere(4));
        QVERIFY(w);
        QWidget* view = w->view();
        QCOMPARE(view->devicePixelRatioF(), 2.0);
        w->view()->setStandardView(fss::StandardView::PosZ);
        QCOMPARE(w->view()->camera().width, 2 * view->width());
        w->scanPanel()->setResolution(300);
        // One sample per scan pixel (the paper's lattice), so that the patch's sample count measures the
        // disc's area in scan pixels; the default adaptive lattice puts 1–1/cos θ0 times as many.
        w->scanPanel()->setLattice(fss::Lattice::Square);
        w->setActiveTool(w->lassoTool());
        // A circle of radius 60 DIP, centred 40 DIP right of the view's centre.
        const QPointF centre(view->width() / 2.0 + 40, view->height() / 2.0);
        const double radius = 60;
        sendMouse(view, QEvent::MouseButtonPress, centre + QPointF(radius, 0), Qt::LeftButton,
                  Qt::LeftButton);
        for (int i = 1; i <= 40; ++i) {
            const double a = 2 * std::numbers::pi * i / 40;
            sendMouse(view, QEvent::MouseMove, centre + radius * QPointF(std::cos(a), std::sin(a)),
                      Qt::NoButton, Qt::LeftButton);
        }
        sendMouse(view, QEvent::MouseButtonRelease, centre + QPointF(radius, 0), Qt::LeftButton,
                  Qt::NoButton);
        QVERIFY(w->lassoTool()->hasLasso());
        QVERIFY(w->scan());
        const fss::ScanPreview& preview = *w->session()->preview();
        const fss::Camera& camera = preview.step.params.camera;
        QCOMPARE(std::max(camera.width, camera.height), 300);
        // The patch is the disc the user drew: its centroid in the scan image is the lasso's centre mapped
        // by scan size / view DIP size (no device pixel ratio in between), its area the disc's.
        const double sx = double(camera.width) / view->width(), sy = double(camera.height) / view->height();
        Eigen::Vector2d sum(0, 0);
        std::size_t n = 0;
        for (fss::VertexIndex v : preview.patch.mesh.vertices()) {
            const fss::Point3& p = preview.patch.mesh.point(v);
            sum += camera.project({p.x(), p.y(), p.z()}).head<2>();
            ++n;
        }
        QVERIFY(n > 100);
        const Eigen::Vector2d centroid = sum / double(n);
        const Eigen::Vector2d expected(centre.x() * sx, centre.y() * sy);
        QVERIFY2((centroid - expected).norm() < 2.0,
                 qPrintable(QString("patch centre (%1, %2), lasso centre (%3, %4) scan px")
                                .arg(centroid.x())
                                .arg(centroid.y())
                                .arg(expected.x())
                                .arg(expected.y())));
        const double discSamples = std::numbers::pi * radius * sx * radius * sy;
        QVERIFY2(double(n) > 0.75 * discSamples && double(n) < 1.05 * discSamples,
                 qPrintable(QString("%1 samples for a disc of %2 px²").arg(n).arg(discSamples)));
    }

    void fishboneSeedLandsWhereClicked() {
        auto w = shownWidget(fss::shapes::cylinder(64, 32));
        QVERIFY(w);
        QWidget* view = w->view();
        w->view()->setStandardView(fss::StandardView::PosX);
        w->scanPanel()->setResolution(200);
        w->setActiveTool(w->fishboneTool());
        const QPointF seed(view->width() / 2.0 + 25, view->height() / 2.0 + 10);
        sendMouse(view, QEvent::MouseButtonPress, seed, Qt::LeftButton, Qt::LeftButton);
        sendMouse(view, QEvent::MouseButtonRelease, seed, Qt::LeftButton, Qt::NoButton);
        QTRY_VERIFY_WITH_TIMEOUT(!w->isBusy() && w->hasPreview(), 60000);
        const fss::ScanPreview& preview = *w->session()->preview();
        QVERIFY(preview.step.fishbone && preview.step.fishbone->seed);
        const fss::Camera& camera = preview.step.params.camera;
        const Eigen::Vector2d expected(seed.x() * camera.width / view->width(),
                                       seed.y() * camera.height / view->height());
        const Eigen::Vector2d got = *preview.step.fishbone->seed;
        QVERIFY2((got - expected).norm() < 1e-9, qPrintable(QString("seed (%1, %2) scan px, clicked (%3, %4)")
                                                                .arg(got.x(), 0, 'g', 17)
                                                                .arg(got.y(), 0, 'g', 17)
                                                                .arg(expected.x(), 0, 'g', 17)
                                                                .arg(expected.y(), 0, 'g', 17)));
        // The backbone shown passes through the clicked point.
        double nearest = 1e9;
        for (const QPointF& p : w->fishboneTool()->backbone())
            nearest = std::min(nearest, QLineF(p, seed).length());
        QVERIFY2(nearest < 2.0, qPrintable(QString::number(nearest)));
    }
};

int main(int argc, char** argv) {
    qputenv("QT_SCALE_FACTOR", "2");
    fss::widgets::VtkView::setDefaultSurfaceFormat();
    QApplication app(argc, argv);
    HiDpiTest test;
    return QTest::qExec(&test, argc, argv);
}

#include "hidpi_test.moc"
