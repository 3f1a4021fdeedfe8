// VtkView's layers over the mesh and its scan buffers, under a real X server (Xvfb): the scan-id colour
// map, 2D overlays, the ghost and preview meshes, createMeshRenderer() against the CPU ray caster, and
// the device pixel ratio (ctest runs this program twice: as is, and with QT_SCALE_FACTOR=2).
// Pixel statistics and projected reference points, no stored images.
#include "pixel_stats.h"
#include "test_data.h"

#include <fss/camera.h>
#include <fss/error.h>
#include <fss/mesh_io.h>
#include <fss/render/colour_maps.h>
#include <fss/render/snapshot.h>
#include <fss/scan_pipeline.h>
#include <fss/shapes.h>
#include <fss/widgets/vtk_view.h>

#include <QApplication>
#include <QElapsedTimer>
#include <QHBoxLayout>
#include <QTest>

#include <cmath>
#include <functional>
#include <memory>

using fss::widgets::ColorMap;
using fss::widgets::OverlayPath;
using fss::widgets::VtkView;

namespace {

const fss::Mesh& fandisk() {
    static const fss::Mesh mesh = fss::readMesh(fss::test::meshPath("fandisk.off"));
    return mesh;
}

Eigen::Vector3d centroid(const fss::Mesh& mesh, fss::FaceIndex f) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    int n = 0;
    for (fss::VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f))) {
        const fss::Point3& p = mesh.point(v);
        c += Eigen::Vector3d(p.x(), p.y(), p.z());
        ++n;
    }
    return c / n;
}

// The faces of \p mesh whose centroid satisfies \p keep, as a new mesh (all vertices kept).
fss::Mesh selectFaces(const fss::Mesh& mesh, const std::function<bool(const Eigen::Vector3d&)>& keep) {
    fss::Mesh out;
    std::vector<fss::VertexIndex> map(mesh.num_vertices());
    for (fss::VertexIndex v : mesh.vertices())
        map[std::size_t(v)] = out.add_vertex(mesh.point(v));
    for (fss::FaceIndex f : mesh.faces()) {
        if (!keep(centroid(mesh, f))) continue;
        std::vector<fss::VertexIndex> corners;
        for (fss::VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f)))
            corners.push_back(map[std::size_t(v)]);
        out.add_face(corners);
    }
    return out;
}

bool inSquare(const Eigen::Vector3d& c, double lo, double hi) {
    return c.x() > lo && c.x() < hi && c.y() > lo && c.y() < hi;
}

// Image pixel under the world point \p p seen by \p camera (Camera screen coordinates: row 0 on top).
QPoint pixelOf(const fss::Camera& camera, const Eigen::Vector3d& p) {
    const Eigen::Vector3d s = camera.project(p);
    return {int(std::floor(s.x())), int(std::floor(s.y()))};
}

QRgb at(const QImage& image, QPoint p) {
    return image.pixel(p);
}

int maxChannelDiff(QRgb a, QRgb b) {
    return std::max(
        {std::abs(qRed(a) - qRed(b)), std::abs(qGreen(a) - qGreen(b)), std::abs(qBlue(a) - qBlue(b))});
}

// A shown view of \p mesh at \p size widget pixels looking from +z.
std::unique_ptr<VtkView> shownView(const fss::Mesh& mesh, QSize size = {400, 400},
                                   fss::StandardView side = fss::StandardView::PosZ) {
    auto view = std::make_unique<VtkView>();
    view->resize(size);
    view->setInitialView(side);
    view->setMesh(mesh);
    view->show();
    if (!QTest::qWaitForWindowExposed(view.get())) return nullptr;
    return view;
}

// Euclidean distance from \p p to the segment ab.
double distanceToSegment(QPointF p, QPointF a, QPointF b) {
    const QPointF ab = b - a, ap = p - a;
    const double len2 = QPointF::dotProduct(ab, ab);
    const double t = len2 > 0 ? std::clamp(QPointF::dotProduct(ap, ab) / len2, 0.0, 1.0) : 0.0;
    const QPointF q = a + t * ab - p;
    return std::sqrt(QPointF::dotProduct(q, q));
}

} // namespace

class VtkViewLayersTest : public QObject {
    Q_OBJECT
private slots:
    void colorMapNames() {
        QCOMPARE(fss::widgets::parseColorMap("scan-id"), std::optional<ColorMap>(ColorMap::ScanId));
        QCOMPARE(fss::widgets::colorMapName(ColorMap::ScanId), QStringLiteral("scan-id"));
        for (ColorMap m : {ColorMap::None, ColorMap::MinAngle, ColorMap::Valence, ColorMap::ScanId})
            QCOMPARE(fss::widgets::parseColorMap(fss::widgets::colorMapName(m).toStdString()),
                     std::optional(m));
        QVERIFY(!fss::widgets::parseColorMap("scanid"));
        // Input faces grey; the first 12 scan ids saturated and pairwise at least 20° of hue apart.
        const QColor grey = fss::widgets::scanIdColor(-1);
        QCOMPARE(grey.red(), grey.green());
        QCOMPARE(grey.green(), grey.blue());
        for (int a = 0; a < 12; ++a) {
            QVERIFY(fss::widgets::scanIdColor(a).hsvSaturationF() > 0.5);
            QCOMPARE(fss::widgets::scanIdColor(a), fss::widgets::scanIdColor(a)); // stable
            for (int b = a + 1; b < 12; ++b) {
                const int d =
                    std::abs(fss::widgets::scanIdColor(a).hsvHue() - fss::widgets::scanIdColor(b).hsvHue());
                QVERIFY2(std::min(d, 360 - d) >= 20, qPrintable(QString("ids %1 and %2").arg(a).arg(b)));
            }
        }
    }

    void colourMapsAreTheRenderLayers() {
        // The view colours faces with the render layer's maps (colour_maps.h), those of the snapshots.
        for (int id : {-1, 0, 1, 5, 11}) {
            const fss::render::Rgb c = fss::render::scanIdColor(id);
            QCOMPARE(fss::widgets::scanIdColor(id), QColor(c[0], c[1], c[2]));
        }
        // A grid of right isosceles triangles (smallest angle 45°) seen frontally: every face centre has the
        // hue of minAngleColor(45) in the view and in a snapshot from the view's camera.
        const fss::Mesh mesh = fss::shapes::grid(8, 8);
        auto view = std::make_unique<VtkView>();
        view->setColorMap(ColorMap::MinAngle);
        view->resize(400, 400);
        view->setInitialView(fss::StandardView::PosZ);
        view->setMesh(mesh);
        view->show();
        QVERIFY(QTest::qWaitForWindowExposed(view.get()));
        const QImage image = view->grabImage();
        const fss::Camera camera = view->camera();
        fss::render::SnapshotOptions options;
        options.renderer = fss::render::SnapshotOptions::Renderer::Cpu;
        const fss::render::Snapshot snapshot = fss::render::renderSnapshot(mesh, camera, options);
        QCOMPARE(snapshot.image.width, image.width());
        const fss::render::Rgb c = fss::render::minAngleColor(45);
        const int expected = QColor(c[0], c[1], c[2]).hsvHue();
        auto hueDistance = [](int a, int b) { return std::min(std::abs(a - b), 360 - std::abs(a - b)); };
        for (fss::FaceIndex f : mesh.faces()) {
            const QPoint p = pixelOf(camera, centroid(mesh, f));
            const QColor inView(at(image, p));
            const fss::render::Rgb s = snapshot.image.pixel(p.x(), p.y());
            const QColor inSnapshot(s[0], s[1], s[2]);
            QVERIFY2(inView.hsvSaturation() > 100 && hueDistance(inView.hsvHue(), expected) <= 8,
                     qPrintable(QString("face %1 is %2 in the view").arg(std::size_t(f)).arg(inView.name())));
            QVERIFY2(hueDistance(inSnapshot.hsvHue(), inView.hsvHue()) <= 8,
                     qPrintable(QString("face %1: view %2, snapshot %3")
                                    .arg(std::size_t(f))
                                    .arg(inView.name(), inSnapshot.name())));
        }
    }

    void scanIdColoursInputGreyAndScansByHue() {
        // 8 × 8 grid: faces left of x = 4 are input faces (−1), the right half made by scans 0..3 in bands.
        fss::Mesh mesh = fss::shapes::grid(8, 8);
        auto [ids, created] = mesh.add_property_map<fss::FaceIndex, std::int32_t>(fss::props::faceScanId, -1);
        QVERIFY(created);
        for (fss::FaceIndex f : mesh.faces()) {
            const Eigen::Vector3d c = centroid(mesh, f);
            ids[f] = c.x() < 4 ? -1 : std::int32_t(c.y() / 2);
        }
        auto view = std::make_unique<VtkView>();
        view->setColorMap(ColorMap::ScanId); // before the mesh: kept for it
        view->setLegendVisible(false);       // the face colours are probed, not the legend over them
        view->resize(400, 400);
        view->setInitialView(fss::StandardView::PosZ);
        view->setMesh(mesh);
        view->show();
        QVERIFY(QTest::qWaitForWindowExposed(view.get()));
        const QImage image = view->grabImage();
        const fss::Camera camera = view->camera();
        int greyFaces = 0, hueFaces = 0;
        for (fss::FaceIndex f : mesh.faces()) {
            const QRgb p = at(image, pixelOf(camera, centroid(mesh, f)));
            const QColor c(p);
            if (ids[f] < 0) {
                QVERIFY2(maxChannelDiff(p, qRgb(qRed(p), qRed(p), qRed(p))) <= 4 && qGray(p) > 60,
                         qPrintable(QString("input face %1 is %2").arg(std::size_t(f)).arg(c.name())));
                ++greyFaces;
            } else {
                const int expected = fss::widgets::scanIdColor(ids[f]).hsvHue();
                const int d = std::abs(c.hsvHue() - expected);
                QVERIFY2(c.hsvSaturation() > 100 && std::min(d, 360 - d) <= 8,
                         qPrintable(QString("scan %1 face is %2").arg(ids[f]).arg(c.name())));
                ++hueFaces;
            }
        }
        QCOMPARE(greyFaces, 64);
        QCOMPARE(hueFaces, 64);
        // Whole-image statistics: the left half of the mesh is grey, the right half coloured.
        const QPoint lo = pixelOf(camera, {0, 8, 0}), mid = pixelOf(camera, {4, 0, 0}),
                     hi = pixelOf(camera, {8, 0, 0});
        const QRect left(lo, QPoint(mid.x() - 1, mid.y())), right(QPoint(mid.x() + 1, lo.y()), hi);
        auto grey = [](QRgb p) {
            return std::abs(qRed(p) - qGreen(p)) <= 4 && std::abs(qGreen(p) - qBlue(p)) <= 4;
        };
        auto saturated = [](QRgb p) { return QColor(p).hsvSaturation() > 100; };
        const double greyLeft = fss::test::pixelFraction(image, grey, left);
        const double colouredRight = fss::test::pixelFraction(image, saturated, right);
        QVERIFY2(greyLeft > 0.9, qPrintable(QString::number(greyLeft)));
        QVERIFY2(colouredRight > 0.85, qPrintable(QString::number(colouredRight)));
        QVERIFY(fss::test::pixelFraction(image, saturated, left) < 0.01);
        // Without the property every face is an input face.
        view->setMesh(fss::shapes::grid(8, 8));
        QVERIFY(fss::test::pixelFraction(view->grabImage(), saturated) < 0.001);
    }

    void overlayLandsAtDevicePixels() {
        auto view = shownView(fandisk(), {500, 400}, fss::StandardView::Iso);
        QVERIFY(view);
        const qreal dpr = view->devicePixelRatioF();
        const QImage before = view->grabImage();
        const std::vector<QPointF> line{{40, 60}, {300, 60}, {300, 200}};
        OverlayPath red{line, QColor(255, 0, 0), false, false, 3};
        OverlayPath dots{{{100, 330}, {200, 330}}, QColor(0, 255, 0), false, true, 0};
        view->setOverlay({red, dots});
        QCOMPARE(view->overlay().size(), std::size_t(2));
        const QImage after = view->grabImage();
        QCOMPARE(after.size(), before.size());
        auto isRed = [](QRgb p) { return qRed(p) > 230 && qGreen(p) < 30 && qBlue(p) < 30; };
        // Along the polyline: the pixel under widget point p is image pixel p·dpr.
        for (double t = 0.05; t < 1; t += 0.05) {
            for (const auto& [a, b] : {std::pair{line[0], line[1]}, std::pair{line[1], line[2]}}) {
                const QPointF p = a + t * (b - a);
                const QPointF q = view->toImagePixels(p);
                QCOMPARE(q, p * dpr);
                QVERIFY2(isRed(after.pixel(q.toPoint())),
                         qPrintable(QString("(%1, %2)").arg(q.x()).arg(q.y())));
            }
        }
        QVERIFY(!isRed(after.pixel((QPointF(170, 80) * dpr).toPoint()))); // off the line: not painted
        // Markers: dots at the points, no line between them (width 0).
        auto isGreen = [](QRgb p) { return qGreen(p) > 230 && qRed(p) < 30 && qBlue(p) < 30; };
        QVERIFY(isGreen(after.pixel((QPointF(100, 330) * dpr).toPoint())));
        QVERIFY(isGreen(after.pixel((QPointF(200, 330) * dpr).toPoint())));
        QCOMPARE(after.pixel((QPointF(150, 330) * dpr).toPoint()),
                 before.pixel((QPointF(150, 330) * dpr).toPoint()));
        // Every changed pixel is near the paths (half the pen or the dot radius, plus antialiasing).
        long changed = 0, far = 0;
        for (int y = 0; y < after.height(); ++y)
            for (int x = 0; x < after.width(); ++x) {
                if (after.pixel(x, y) == before.pixel(x, y)) continue;
                ++changed;
                const QPointF w = QPointF(x + 0.5, y + 0.5) / dpr; // pixel centre in widget pixels
                const double dLine =
                    std::min(distanceToSegment(w, line[0], line[1]), distanceToSegment(w, line[1], line[2]));
                const double dDots = std::min(distanceToSegment(w, {100, 330}, {100, 330}),
                                              distanceToSegment(w, {200, 330}, {200, 330}));
                if (dLine > 1.5 + 1.5 && dDots > 1.5 + 1.5) ++far;
            }
        QCOMPARE(far, 0L);
        // Roughly the painted area: 400 px of line × 3 px wide, in device pixels.
        QVERIFY2(changed > 0.8 * 400 * 3 * dpr * dpr, qPrintable(QString::number(changed)));
        view->clearOverlay();
        QVERIFY(view->overlay().empty());
        QCOMPARE(view->grabImage(), before);
    }

    void ghostShowsWhereTheMeshIsMissing() {
        const fss::Mesh full = fss::shapes::grid(8, 8);
        const fss::Mesh holed =
            selectFaces(full, [](const Eigen::Vector3d& c) { return !inSquare(c, 3, 5); });
        auto view = shownView(holed);
        QVERIFY(view);
        const fss::Camera camera = view->camera();
        const QImage before = view->grabImage();
        const QRect hole(pixelOf(camera, {3.2, 4.8, 0}), pixelOf(camera, {4.8, 3.2, 0}));
        QVERIFY(hole.width() > 20 && hole.height() > 20);
        QCOMPARE(fss::test::pixelFraction(before, fss::test::notBackground, hole), 0.0);

        view->setGhostMesh(full);
        QVERIFY(view->ghostVisible());
        const QImage ghost = view->grabImage();
        // In the hole: the ghost colour blended over the background (bluer and brighter).
        auto ghostly = [](QRgb p) {
            const double* bg = VtkView::kBackground;
            return qBlue(p) > std::lround(bg[2] * 255) + 15 && qBlue(p) > qRed(p) + 20 &&
                   fss::test::notBackground(p);
        };
        QVERIFY2(fss::test::pixelFraction(ghost, ghostly, hole) > 0.99,
                 qPrintable(QString::number(fss::test::pixelFraction(ghost, ghostly, hole))));
        // Where the mesh is, it wins over the coincident ghost: face interiors unchanged.
        int faces = 0;
        for (fss::FaceIndex f : holed.faces()) {
            const QPoint p = pixelOf(camera, centroid(holed, f));
            QVERIFY2(maxChannelDiff(ghost.pixel(p), before.pixel(p)) <= 2,
                     qPrintable(QString("face %1: %2 -> %3")
                                    .arg(std::size_t(f))
                                    .arg(QColor(before.pixel(p)).name(), QColor(ghost.pixel(p)).name())));
            ++faces;
        }
        QCOMPARE(faces, 128 - 8);
        // Nothing changes outside the hole [3, 5]² (the whole image but it, with 2 pixels of margin).
        const QRect wholeHole =
            QRect(pixelOf(camera, {3, 5, 0}), pixelOf(camera, {5, 3, 0})).adjusted(-2, -2, 2, 2);
        long changedOutside = 0;
        for (int y = 0; y < ghost.height(); ++y)
            for (int x = 0; x < ghost.width(); ++x)
                if (!wholeHole.contains(x, y) && maxChannelDiff(ghost.pixel(x, y), before.pixel(x, y)) > 8)
                    ++changedOutside;
        QVERIFY2(changedOutside == 0, qPrintable(QString::number(changedOutside)));

        view->setGhostVisible(false);
        QVERIFY(!view->ghostVisible());
        QCOMPARE(view->grabImage(), before);
        view->setGhostVisible(true);
        QCOMPARE(view->grabImage(), ghost);
        view->clearGhostMesh();
        QVERIFY(!view->ghostVisible());
        QCOMPARE(view->grabImage(), before);
    }

    void previewDrawnOverCoincidentMesh() {
        const fss::Mesh full = fss::shapes::grid(8, 8);
        const fss::Mesh patch = selectFaces(full, [](const Eigen::Vector3d& c) { return inSquare(c, 3, 5); });
        auto view = shownView(full);
        QVERIFY(view);
        const fss::Camera camera = view->camera();
        const QImage before = view->grabImage();
        view->setPreviewMesh(patch);
        QVERIFY(view->hasPreviewMesh());
        const QImage preview = view->grabImage();
        auto previewBlue = [](QRgb p) { return qBlue(p) > qRed(p) + 80 && qBlue(p) > qGreen(p) + 40; };
        for (fss::FaceIndex f : full.faces()) {
            const Eigen::Vector3d c = centroid(full, f);
            const QPoint p = pixelOf(camera, c);
            if (inSquare(c, 3, 5))
                QVERIFY2(previewBlue(preview.pixel(p)), qPrintable(QColor(preview.pixel(p)).name()));
            else
                QVERIFY(maxChannelDiff(preview.pixel(p), before.pixel(p)) <= 2);
        }
        const QRect square(pixelOf(camera, {3.1, 4.9, 0}), pixelOf(camera, {4.9, 3.1, 0}));
        const double blue = fss::test::pixelFraction(preview, previewBlue, square);
        QVERIFY2(blue > 0.85, qPrintable(QString::number(blue))); // the rest: the preview's dark edges
        view->clearPreviewMesh();
        QVERIFY(!view->hasPreviewMesh());
        QCOMPARE(view->grabImage(), before);
    }

    void previewVisibleOnCurvedMesh() {
        // A patch of fandisk's own faces (coincident with the curved surface): the faces visible in the
        // centre of the view turn preview blue almost everywhere.
        auto view = shownView(fandisk(), {500, 400}, fss::StandardView::Iso);
        QVERIFY(view);
        auto renderer = view->createMeshRenderer();
        renderer->setMesh(fandisk());
        const fss::FrameBuffers ids = renderer->render(view->camera());
        const QImage before = view->grabImage();
        std::vector<bool> inPatch(fandisk().num_faces(), false);
        const int w = ids.width(), h = ids.height();
        for (int y = h / 3; y < 2 * h / 3; ++y)
            for (int x = w / 3; x < 2 * w / 3; ++x)
                if (ids.covered(x, y)) inPatch[ids.faceAt(x, y)] = true;
        fss::Mesh patch;
        {
            std::vector<fss::VertexIndex> map(fandisk().num_vertices());
            for (fss::VertexIndex v : fandisk().vertices())
                map[std::size_t(v)] = patch.add_vertex(fandisk().point(v));
            for (fss::FaceIndex f : fandisk().faces())
                if (inPatch[std::size_t(f)]) {
                    std::vector<fss::VertexIndex> c;
                    for (fss::VertexIndex v : fandisk().vertices_around_face(fandisk().halfedge(f)))
                        c.push_back(map[std::size_t(v)]);
                    patch.add_face(c);
                }
        }
        QVERIFY(patch.number_of_faces() > 100);
        view->setPreviewMesh(patch);
        const QImage preview = view->grabImage();
        QCOMPARE(preview.size(), QSize(w, h));
        long patchPixels = 0, blue = 0, changedElsewhere = 0, elsewhere = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const QRgb p = preview.pixel(x, y);
                if (ids.covered(x, y) && inPatch[ids.faceAt(x, y)]) {
                    ++patchPixels;
                    blue += qBlue(p) > qRed(p) + 40 ? 1 : 0;
                } else if (ids.covered(x, y)) {
                    ++elsewhere;
                    changedElsewhere += maxChannelDiff(p, before.pixel(x, y)) > 8 ? 1 : 0;
                }
            }
        const double blueFraction = double(blue) / double(patchPixels);
        QVERIFY2(blueFraction > 0.9,
                 qPrintable(QString("%1 of %2 patch pixels blue").arg(blue).arg(patchPixels)));
        // The patch's border edges may spill a pixel over its neighbours, nothing more.
        QVERIFY2(changedElsewhere < 0.02 * elsewhere,
                 qPrintable(QString("%1 of %2").arg(changedElsewhere).arg(elsewhere)));
    }

    void meshRendererAgreesWithCpuAndLeavesTheViewAlone() {
        auto view = std::make_unique<VtkView>();
        view->resize(500, 400);
        view->setMesh(fandisk());
        auto renderer = view->createMeshRenderer();
        renderer->setMesh(fandisk()); // before the widget is shown: no GL yet, nothing thrown
        QVERIFY_THROWS_EXCEPTION(fss::Error, renderer->render(view->camera())); // no context yet
        view->show();
        QVERIFY(QTest::qWaitForWindowExposed(view.get()));
        // Overlay, ghost and preview shown too: all of the view's state must survive the scan renders.
        view->setOverlay({OverlayPath{{{20, 20}, {200, 120}}, Qt::red, false, true, 2}});
        view->setGhostMesh(fss::shapes::icosphere(2, 1.0));
        view->setPreviewMesh(selectFaces(fandisk(), [](const Eigen::Vector3d& c) { return c.z() > 0; }));
        const QImage before = view->grabImage();
        const fss::Camera camera = view->camera();
        QCOMPARE(camera.width, int(std::lround(500 * view->devicePixelRatioF())));

        const fss::FrameBuffers gpu = renderer->render(camera);
        QCOMPARE(view->grabImage(), before);
        QCOMPARE(gpu.width(), camera.width);
        QCOMPARE(gpu.height(), camera.height);

        fss::CpuMeshRenderer cpuRenderer;
        cpuRenderer.setMesh(fandisk());
        const fss::FrameBuffers cpu = cpuRenderer.render(camera);
        std::size_t covered = 0, agree = 0;
        for (std::size_t i = 0; i < gpu.faceId.size(); ++i) {
            if (gpu.faceId[i] == fss::FrameBuffers::kNoFace && cpu.faceId[i] == fss::FrameBuffers::kNoFace)
                continue;
            ++covered;
            agree += gpu.faceId[i] == cpu.faceId[i] ? 1 : 0;
        }
        const double agreement = double(agree) / double(covered);
        qInfo("createMeshRenderer vs CPU ray casting at %dx%d: %zu covered pixels, face ids agree on %.4f %%",
              camera.width, camera.height, covered, 100 * agreement);
        QVERIFY(covered > 0.1 * gpu.faceId.size());
        QVERIFY2(agreement >= 0.999, qPrintable(QString::number(agreement, 'f', 5)));

        // Repeated renders interleaved with paints give the same buffers and leave the image alone.
        view->update();
        QCOMPARE(view->grabImage(), before);
        const fss::FrameBuffers again = renderer->render(camera);
        QVERIFY(again.faceId == gpu.faceId);
        QVERIFY(again.depth == gpu.depth);
        QCOMPARE(view->grabImage(), before);

        // Other scan resolutions: their own size, the view's image unchanged. (The time is information,
        // not a check: speed targets live in bench/.)
        for (const QSize size : {QSize(128, 96), QSize(512, 512)}) {
            fss::Camera scan = camera;
            scan.width = size.width();
            scan.height = size.height();
            QElapsedTimer timer;
            timer.start();
            const fss::FrameBuffers buffers = renderer->render(scan);
            qInfo("scan %dx%d of fandisk in the view's context: %lld ms", size.width(), size.height(),
                  timer.elapsed());
            QCOMPARE(int(buffers.faceId.size()), size.width() * size.height());
            QVERIFY(buffers.coveredCount() > 0.05 * size.width() * size.height());
            QCOMPARE(view->grabImage(), before);
        }
    }

    void meshRendererFollowsReparentingAndOutlivesTheView() {
        QWidget first, second;
        auto* layout1 = new QHBoxLayout(&first);
        auto* view = new VtkView;
        layout1->addWidget(view);
        view->setMesh(fandisk());
        first.resize(500, 400);
        first.show();
        QVERIFY(QTest::qWaitForWindowExposed(&first));
        auto renderer = view->createMeshRenderer();
        renderer->setMesh(fandisk());
        const fss::Camera camera = view->camera();
        const fss::FrameBuffers a = renderer->render(camera);
        QVERIFY(a.coveredCount() > 0.1 * a.faceId.size());
        auto* layout2 = new QHBoxLayout(&second);
        layout2->addWidget(view); // re-parents: the GL context is recreated, the renderer's resources freed
        second.resize(500, 400);
        second.show();
        QVERIFY(QTest::qWaitForWindowExposed(&second));
        QVERIFY(fss::test::pixelFraction(view->grabImage(), fss::test::surfaceColored) > 0.03);
        const fss::FrameBuffers b = renderer->render(camera); // uploaded again in the new context
        QVERIFY(b.faceId == a.faceId);
        delete view;
        QVERIFY_THROWS_EXCEPTION(fss::Error, renderer->render(camera));
        renderer.reset(); // no crash after the view and its context are gone
        QVERIFY(!renderer);
    }

    void devicePixelRatioAppliedToImageCameraAndPicking() {
        const QByteArray scale = qgetenv("QT_SCALE_FACTOR");
        const fss::Mesh grid = fss::shapes::grid(8, 8);
        auto view = shownView(grid, {400, 300}, fss::StandardView::Iso);
        QVERIFY(view);
        const qreal dpr = view->devicePixelRatioF();
        qInfo("device pixel ratio %.2f (QT_SCALE_FACTOR=%s)", dpr,
              scale.isEmpty() ? "unset" : scale.constData());
        if (!scale.isEmpty()) QCOMPARE(dpr, scale.toDouble());
        const fss::Camera camera = view->camera();
        QCOMPARE(camera.width, int(std::lround(400 * dpr)));
        QCOMPARE(camera.height, int(std::lround(300 * dpr)));
        const QImage image = view->grabImage();
        QCOMPARE(image.size(), QSize(camera.width, camera.height));
        QCOMPARE(view->toImagePixels({10.5, 20.25}), QPointF(10.5 * dpr, 20.25 * dpr));

        // The mesh is drawn where Camera::project puts it: the grid's projected corners bound the image's
        // non-background pixels (within the edge lines' width).
        double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
        for (const Eigen::Vector3d& corner : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(8, 0, 0),
                                              Eigen::Vector3d(0, 8, 0), Eigen::Vector3d(8, 8, 0)}) {
            const Eigen::Vector3d s = camera.project(corner);
            x0 = std::min(x0, s.x()), x1 = std::max(x1, s.x()), y0 = std::min(y0, s.y()),
            y1 = std::max(y1, s.y());
        }
        int px0 = image.width(), px1 = -1, py0 = image.height(), py1 = -1;
        for (int y = 0; y < image.height(); ++y)
            for (int x = 0; x < image.width(); ++x)
                if (fss::test::notBackground(image.pixel(x, y))) {
                    px0 = std::min(px0, x), px1 = std::max(px1, x), py0 = std::min(py0, y),
                    py1 = std::max(py1, y);
                }
        qInfo("projected corners x %.1f..%.1f y %.1f..%.1f; drawn x %d..%d y %d..%d", x0, x1, y0, y1, px0,
              px1, py0, py1);
        QVERIFY(std::abs(px0 - x0) < 2.5 && std::abs(px1 + 1 - x1) < 2.5);
        QVERIFY(std::abs(py0 - y0) < 2.5 && std::abs(py1 + 1 - y1) < 2.5);

        // Picking: a widget point over a face's centroid → image pixel → that face in the view's scan
        // buffers.
        auto renderer = view->createMeshRenderer();
        renderer->setMesh(grid);
        const fss::FrameBuffers ids = renderer->render(camera);
        int hits = 0;
        for (fss::FaceIndex f : grid.faces()) {
            const Eigen::Vector3d s = camera.project(centroid(grid, f));
            const QPointF widgetPoint(s.x() / dpr, s.y() / dpr); // where the user sees the face
            const QPointF q = view->toImagePixels(widgetPoint);
            hits += ids.faceAt(int(q.x()), int(q.y())) == std::uint32_t(f) ? 1 : 0;
        }
        QCOMPARE(hits, int(grid.number_of_faces()));
    }
};

int main(int argc, char** argv) {
    VtkView::setDefaultSurfaceFormat();
    QApplication app(argc, argv);
    VtkViewLayersTest test;
    return QTest::qExec(&test, argc, argv);
}

#include "vtk_view_layers_test.moc"
