// VtkView under a real X server (Xvfb): navigation, zoom, several views, standard views, camera
// conversion, and what the rendered image shows (pixel statistics, no stored images).
#include "pixel_stats.h"
#include "test_data.h"

#include <fss/camera.h>
#include <fss/error.h>
#include <fss/mesh_io.h>
#include <fss/widgets/vtk_view.h>

#include <QApplication>
#include <QHBoxLayout>
#include <QMouseEvent>
#include <QSignalSpy>
#include <QTest>
#include <QWheelEvent>

#include <algorithm>
#include <memory>

using fss::widgets::ColorMap;
using fss::widgets::VtkView;

namespace {

const fss::Mesh& fandisk() {
    static const fss::Mesh mesh = fss::readMesh(fss::test::meshPath("fandisk.off"));
    return mesh;
}

void sendMouse(QWidget* w, QEvent::Type type, QPointF pos, Qt::MouseButton button, Qt::MouseButtons buttons) {
    QMouseEvent event(type, pos, w->mapToGlobal(pos), button, buttons, Qt::NoModifier);
    QApplication::sendEvent(w, &event);
}

void sendWheel(QWidget* w, QPointF pos, int angle) {
    QWheelEvent event(pos, w->mapToGlobal(pos), QPoint(), QPoint(0, angle), Qt::NoButton, Qt::NoModifier,
                      Qt::NoScrollPhase, false);
    QApplication::sendEvent(w, &event);
}

} // namespace

class VtkViewTest : public QObject {
    Q_OBJECT
private:
    // A shown 600×450 view with fandisk, ready to render (fandisk's 13k faces with their edges need that
    // many pixels for the faces' colour to dominate the edges').
    std::unique_ptr<VtkView> shownView() {
        auto view = std::make_unique<VtkView>();
        view->resize(600, 450);
        view->setMesh(fandisk());
        view->show();
        if (!QTest::qWaitForWindowExposed(view.get())) return nullptr;
        return view;
    }

private slots:
    void dragRotatesAroundFocalPoint() {
        auto view = shownView();
        QVERIFY(view);
        QSignalSpy moved(view.get(), &VtkView::cameraChanged);
        const fss::Camera before = view->camera();
        sendMouse(view.get(), QEvent::MouseButtonPress, {300, 225}, Qt::LeftButton, Qt::LeftButton);
        for (int i = 1; i <= 10; ++i)
            sendMouse(view.get(), QEvent::MouseMove, {300.0 + 8 * i, 225.0 + 3 * i}, Qt::NoButton,
                      Qt::LeftButton);
        sendMouse(view.get(), QEvent::MouseButtonRelease, {380, 255}, Qt::LeftButton, Qt::NoButton);
        QVERIFY(moved.count() > 0); // reported while dragging
        const fss::Camera after = view->camera();
        const double distance = (before.eye - before.focal).norm();
        QVERIFY2((after.eye - before.eye).norm() > 0.1 * distance, "the eye did not move");
        QVERIFY((after.focal - before.focal).norm() < 1e-9 * distance); // trackball rotation: focal stays
        QVERIFY(std::abs((after.eye - after.focal).norm() - distance) < 1e-6 * distance);
        // The mesh is still in view after rotating.
        QVERIFY(fss::test::pixelFraction(view->grabImage(), fss::test::surfaceColored) > 0.03);
    }

    void wheelZooms() {
        auto view = shownView();
        QVERIFY(view);
        const fss::Camera start = view->camera();
        const double d0 = (start.eye - start.focal).norm();
        sendWheel(view.get(), {300, 225}, 120);
        const fss::Camera in = view->camera();
        const double d1 = (in.eye - in.focal).norm();
        QVERIFY2(d1 < 0.95 * d0, "wheel forward did not move the eye closer");
        QVERIFY((in.focal - start.focal).norm() < 1e-9 * d0);
        QVERIFY(in.viewDirection().dot(start.viewDirection()) > 1 - 1e-12); // zoom only, no rotation
        sendWheel(view.get(), {300, 225}, -120);
        sendWheel(view.get(), {300, 225}, -120);
        const fss::Camera out = view->camera();
        QVERIFY2((out.eye - out.focal).norm() > d0 * 1.01, "wheel backward did not move the eye away");
        // Zooming in enlarges the mesh on screen.
        const double coverageOut = fss::test::pixelFraction(view->grabImage(), fss::test::notBackground);
        sendWheel(view.get(), {300, 225}, 120);
        sendWheel(view.get(), {300, 225}, 120);
        sendWheel(view.get(), {300, 225}, 120);
        const double coverageIn = fss::test::pixelFraction(view->grabImage(), fss::test::notBackground);
        QVERIFY2(coverageIn > coverageOut * 1.2,
                 qPrintable(QString("coverage %1 -> %2").arg(coverageOut).arg(coverageIn)));
    }

    // Issue #21 item 9: edges on/off (dense meshes turn dark), the axis triad in the lower-left corner,
    // Y-up standard views, framing.
    void edgesTriadUpAxisAndFraming() {
        auto view = shownView();
        QVERIFY(view);
        auto dark = [](QRgb p) { return std::max({qRed(p), qGreen(p), qBlue(p)}) < 70; };
        QVERIFY(view->edgesVisible());
        const double darkWith = fss::test::pixelFraction(view->grabImage(), dark);
        view->setEdgesVisible(false);
        const double darkWithout = fss::test::pixelFraction(view->grabImage(), dark);
        QVERIFY2(darkWith > 2 * darkWithout + 0.01,
                 qPrintable(QString("dark pixels %1 with edges, %2 without").arg(darkWith).arg(darkWithout)));

        // The triad: the lower-left 16 % is background but for it (the mesh is framed in the middle).
        QImage image = view->grabImage();
        const QRect corner(0, image.height() * 84 / 100, image.width() * 16 / 100, image.height() * 16 / 100);
        QVERIFY(!view->axesVisible()); // hidden in a bare view
        view->setAxesVisible(true);
        image = view->grabImage();
        const double triad = fss::test::pixelFraction(image, fss::test::notBackground, corner);
        view->setAxesVisible(false);
        image = view->grabImage();
        const double none = fss::test::pixelFraction(image, fss::test::notBackground, corner);
        QVERIFY2(triad > 0.01 && none < 0.002,
                 qPrintable(QString("corner %1 with the triad, %2 without").arg(triad).arg(none)));

        QCOMPARE(view->upAxis(), VtkView::UpAxis::Z);
        view->setStandardView(fss::StandardView::PosX);
        QVERIFY(view->camera().up.dot(Eigen::Vector3d::UnitZ()) > 1 - 1e-9);
        view->setUpAxis(VtkView::UpAxis::Y);
        view->setStandardView(fss::StandardView::PosX);
        QVERIFY(view->camera().up.dot(Eigen::Vector3d::UnitY()) > 1 - 1e-9);
        view->setStandardView(fss::StandardView::Iso);
        QVERIFY(view->camera().up.y() > 0.8 && view->camera().up.z() < 0);

        // Framing after a zoom: the same direction, the whole mesh back in view.
        const fss::Camera framed = view->camera();
        for (int i = 0; i < 5; ++i)
            sendWheel(view.get(), {300, 225}, 120);
        QVERIFY((view->camera().eye - framed.focal).norm() < 0.8 * (framed.eye - framed.focal).norm());
        view->frameMesh();
        const fss::Camera c = view->camera();
        QVERIFY(c.viewDirection().dot(framed.viewDirection()) > 1 - 1e-9);
        const Eigen::AlignedBox3d box = fss::boundingBox(fandisk());
        for (int k = 0; k < 8; ++k) {
            const Eigen::Vector3d p = c.project(box.corner(Eigen::AlignedBox3d::CornerType(k)));
            QVERIFY2(p.x() >= 0 && p.x() <= c.width && p.y() >= 0 && p.y() <= c.height,
                     qPrintable(QString("corner %1 at %2, %3").arg(k).arg(p.x()).arg(p.y())));
        }
    }

    void exitKeysDoNotQuit() {
        auto view = shownView();
        QVERIFY(view);
        // VTK's trackball style calls exit() on 'e' and 'q'; the view must swallow them (the test would die).
        QTest::keyClick(view.get(), Qt::Key_E, Qt::NoModifier);
        QTest::keyClick(view.get(), Qt::Key_Q, Qt::NoModifier);
        QTest::keyClick(view.get(), Qt::Key_W, Qt::NoModifier); // would switch to wireframe
        QVERIFY(fss::test::pixelFraction(view->grabImage(), fss::test::surfaceColored) > 0.03);
    }

    void twoViewsInOneWindowBothRender() {
        QWidget window;
        auto* layout = new QHBoxLayout(&window);
        auto* plain = new VtkView;
        auto* colored = new VtkView;
        layout->addWidget(plain);
        layout->addWidget(colored);
        window.resize(1200, 450);
        plain->setMesh(fandisk());
        colored->setMesh(fandisk());
        colored->setColorMap(ColorMap::MinAngle);
        colored->setStandardView(fss::StandardView::PosZ);
        window.show();
        QVERIFY(QTest::qWaitForWindowExposed(&window));
        // Render both, twice, interleaved: each view must keep its own context and state.
        for (int round = 0; round < 2; ++round) {
            const QImage a = plain->grabImage();
            const QImage b = colored->grabImage();
            QVERIFY(!a.isNull() && !b.isNull());
            const double coverA = fss::test::pixelFraction(a, fss::test::notBackground);
            const double coverB = fss::test::pixelFraction(b, fss::test::notBackground);
            QVERIFY2(coverA > 0.05 && coverA < 0.95, qPrintable(QString::number(coverA)));
            QVERIFY2(coverB > 0.05 && coverB < 0.95, qPrintable(QString::number(coverB)));
            QVERIFY(fss::test::pixelFraction(a, fss::test::surfaceColored) > 0.03);
            QVERIFY(fss::test::pixelFraction(a, fss::test::qualityGreen) < 0.001);
            QVERIFY(fss::test::pixelFraction(b, fss::test::qualityGreen) > 0.02);
        }
        // The composed window shows both (what the user sees, not only each widget's framebuffer).
        const QImage whole = window.grab().toImage();
        const int half = whole.width() / 2;
        QVERIFY(fss::test::pixelFraction(whole, fss::test::surfaceColored,
                                         QRect(0, 0, half, whole.height())) > 0.03);
        QVERIFY(fss::test::pixelFraction(whole, fss::test::qualityGreen,
                                         QRect(half, 0, half, whole.height())) > 0.02);
    }

    void standardViewsLookAlongTheAxis() {
        auto view = shownView();
        QVERIFY(view);
        const struct {
            fss::StandardView view;
            Eigen::Vector3d direction;
        } cases[] = {{fss::StandardView::PosX, {-1, 0, 0}},
                     {fss::StandardView::NegX, {1, 0, 0}},
                     {fss::StandardView::PosY, {0, -1, 0}},
                     {fss::StandardView::NegY, {0, 1, 0}},
                     {fss::StandardView::PosZ, {0, 0, -1}},
                     {fss::StandardView::NegZ, {0, 0, 1}},
                     {fss::StandardView::Iso, Eigen::Vector3d(-1, -1, -1).normalized()}};
        for (const auto& c : cases) {
            view->setStandardView(c.view);
            const fss::Camera camera = view->camera();
            QVERIFY2(camera.viewDirection().dot(c.direction) > 1 - 1e-9,
                     fss::standardViewName(c.view).c_str());
            QCOMPARE(camera.width, 600 * int(view->devicePixelRatioF()));
            // The whole mesh is in the picture and the picture is centred on it.
            const QImage image = view->grabImage();
            const double cover = fss::test::pixelFraction(image, fss::test::notBackground);
            QVERIFY2(cover > 0.05 && cover < 0.9, fss::standardViewName(c.view).c_str());
            const int w = image.width(), h = image.height();
            QCOMPARE(fss::test::pixelFraction(image, fss::test::notBackground, QRect(0, 0, w, 2)), 0.0);
            QCOMPARE(fss::test::pixelFraction(image, fss::test::notBackground, QRect(0, h - 2, w, 2)), 0.0);
        }
    }

    void cameraRoundTrip() {
        auto view = shownView();
        QVERIFY(view);
        fss::Camera camera = view->camera();
        camera.eye = {3, -2, 1.5};
        camera.focal = {0.1, 0.2, 0.3};
        camera.up = {0, 0, 1};
        camera.viewAngleDeg = 25;
        camera.nearPlane = 0.5;
        camera.farPlane = 20;
        view->setCamera(camera);
        const fss::Camera back = view->camera();
        QVERIFY((back.eye - camera.eye).norm() < 1e-12);
        QVERIFY((back.focal - camera.focal).norm() < 1e-12);
        QVERIFY(std::abs(back.viewAngleDeg - 25) < 1e-12);
        QVERIFY(std::abs(back.nearPlane - 0.5) < 1e-12 && std::abs(back.farPlane - 20) < 1e-12);
        QVERIFY(back.up.dot(back.viewDirection()) < 1e-12); // orthogonalised, still "up"
        QVERIFY(back.up.z() > 0.5);
        fss::Camera bad = camera;
        bad.eye = bad.focal;
        QVERIFY_THROWS_EXCEPTION(fss::InvalidInputError, view->setCamera(bad));
        QVERIFY((view->camera().eye - camera.eye).norm() < 1e-12); // unchanged after the refusal
    }

    void screenshotShowsTheMesh() {
        auto view = shownView();
        QVERIFY(view);
        const QImage plain = view->grabImage();
        QCOMPARE(plain.size(), QSize(600, 450) * view->devicePixelRatioF());
        const double cover = fss::test::pixelFraction(plain, fss::test::notBackground);
        QVERIFY2(cover > 0.15 && cover < 0.8, qPrintable(QString::number(cover)));
        const double tan = fss::test::pixelFraction(plain, fss::test::surfaceColored);
        QVERIFY2(tan > 0.2 * cover, qPrintable(QString("surface %1 of %2").arg(tan).arg(cover)));
        // Edges are drawn: some dark pixels inside the mesh.
        QVERIFY(fss::test::pixelFraction(plain, [](QRgb p) { return qGray(p) < 60; }) > 0.01);

        view->setColorMap(ColorMap::MinAngle);
        const QImage angle = view->grabImage();
        QVERIFY(fss::test::pixelFraction(angle, fss::test::qualityGreen) > 0.02);
        QCOMPARE(fss::test::pixelFraction(angle, fss::test::notBackground) > 0.9 * cover, true);

        view->setColorMap(ColorMap::Valence);
        const QImage valence = view->grabImage();
        QVERIFY(fss::test::pixelFraction(valence, fss::test::qualityGreen) >
                0.02); // 80 % of fandisk is regular
        // Orange / red faces (a corner of valence 4 or 8 and worse) exist on fandisk too.
        QVERIFY(fss::test::pixelFraction(valence, [](QRgb p) {
                    return qRed(p) > qGreen(p) + 60 && qRed(p) > qBlue(p) + 60;
                }) > 0.001);

        view->clearMesh();
        QVERIFY(!view->hasMesh());
        QCOMPARE(fss::test::pixelFraction(view->grabImage(), fss::test::notBackground), 0.0);
    }

    void survivesReparenting() {
        QWidget first, second;
        auto* layout1 = new QHBoxLayout(&first);
        auto* view = new VtkView;
        layout1->addWidget(view);
        view->setMesh(fandisk());
        first.resize(600, 450);
        first.show();
        QVERIFY(QTest::qWaitForWindowExposed(&first));
        QVERIFY(fss::test::pixelFraction(view->grabImage(), fss::test::surfaceColored) > 0.03);
        auto* layout2 = new QHBoxLayout(&second);
        layout2->addWidget(view); // re-parents: the GL context is recreated
        second.resize(650, 450);
        second.show();
        QVERIFY(QTest::qWaitForWindowExposed(&second));
        QVERIFY(fss::test::pixelFraction(view->grabImage(), fss::test::surfaceColored) > 0.03);
    }
};

int main(int argc, char** argv) {
    VtkView::setDefaultSurfaceFormat();
    QApplication app(argc, argv);
    VtkViewTest test;
    return QTest::qExec(&test, argc, argv);
}

#include "vtk_view_test.moc"
