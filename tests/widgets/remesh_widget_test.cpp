// RemeshWidget under a real X server (Xvfb), driven by synthetic mouse events: navigation, a lasso + scan
// + accept (every invariant of DESIGN.md §5 checked with CGAL), exact undo / redo, a fishbone grid from a
// seed and two clicked key-ribs and the QualityPanel's histograms against independent counts. The trial
// stitch, the accept latency and the worker thread: remesh_widget_accept_test.cpp.

#include "remesh_widget_helpers.h"

using namespace remesh_widget_test_helpers;

class RemeshWidgetTest : public QObject {
    Q_OBJECT
private slots:
    void dragRotatesAndLassoConsumesTheLeftButton() {
        auto w = shownWidget(fss::readMesh(fss::test::meshPath("fandisk.off")));
        QVERIFY(w);
        QWidget* view = w->view();
        const QPointF c(view->width() / 2.0, view->height() / 2.0);
        const fss::Camera before = w->view()->camera();
        sendMouse(view, QEvent::MouseButtonPress, c, Qt::LeftButton, Qt::LeftButton);
        for (int i = 1; i <= 10; ++i)
            sendMouse(view, QEvent::MouseMove, c + QPointF(8 * i, 3 * i), Qt::NoButton, Qt::LeftButton);
        sendMouse(view, QEvent::MouseButtonRelease, c + QPointF(80, 30), Qt::LeftButton, Qt::NoButton);
        const fss::Camera rotated = w->view()->camera();
        QVERIFY2((rotated.eye - before.eye).norm() > 0.1 * (before.eye - before.focal).norm(), "no rotation");

        w->setActiveTool(w->lassoTool());
        QVERIFY(w->statusText().contains("Drag"));
        drawLasso(view, c, 100);
        const fss::Camera after = w->view()->camera();
        QVERIFY2((after.eye - rotated.eye).norm() < 1e-12, "the lasso's drag moved the camera");
        QVERIFY(w->lassoTool()->hasLasso());
        QVERIFY(w->statusText().contains("Lasso set"));
        QTest::keyClick(view, Qt::Key_Escape);
        QVERIFY(!w->lassoTool()->hasLasso());
    }

    void lassoScanAcceptKeepsInvariantsAndUndoIsExact() {
        const fss::Mesh input = fss::shapes::icosphere(4); // closed, 5120 faces
        auto w = shownWidget(input);
        QVERIFY(w);
        w->view()->setStandardView(fss::StandardView::PosZ);
        w->scanPanel()->setResolution(200);
        w->setActiveTool(w->lassoTool());
        QWidget* view = w->view();
        const QPointF centre(view->width() / 2.0, view->height() / 2.0);
        const double radius = view->height() / 6.0;
        const QPolygonF drawn = drawLasso(view, centre, radius);
        QVERIFY(w->lassoTool()->hasLasso());

        // Lasso positions are converted from view DIP to scan-image pixels.
        const fss::ScanStep step = w->scanTool()->step();
        QVERIFY(step.params.lasso.has_value());
        const QSize image(step.params.camera.width, step.params.camera.height);
        QCOMPARE(std::max(image.width(), image.height()), 200);
        QCOMPARE(step.params.lasso->points.size(), std::size_t(w->lassoTool()->polygon().size()));
        const double sx = double(image.width()) / view->width(), sy = double(image.height()) / view->height();
        for (std::size_t i = 0; i < step.params.lasso->points.size(); ++i) {
            const QPointF p = w->lassoTool()->polygon()[qsizetype(i)];
            QVERIFY(std::abs(step.params.lasso->points[i].x() - p.x() * sx) < 1e-9);
            QVERIFY(std::abs(step.params.lasso->points[i].y() - p.y() * sy) < 1e-9);
        }

        QSignalSpy accepted(w.get(), &RemeshWidget::scanAccepted);
        QSignalSpy changed(w.get(), &RemeshWidget::meshChanged);
        QVERIFY(w->scan());
        QVERIFY(w->hasPreview());
        const fss::Mesh patch = w->session()->preview()->patch.mesh;
        QVERIFY(patch.number_of_faces() > 200);
        // Every patch vertex lies inside the lasso (in scan pixels, from the step's camera).
        const fss::Camera scanCamera = w->session()->preview()->step.params.camera;
        for (fss::VertexIndex v : patch.vertices()) {
            const Eigen::Vector3d s = scanCamera.project(vec(patch.point(v)));
            QVERIFY(fss::insideLasso(*step.params.lasso, s.head<2>()));
        }
        // ... and they fill it: the patch's screen area is most of the lasso's (a circle of radius r·sx).
        const double lassoArea = std::numbers::pi * radius * sx * radius * sy;
        double patchArea = 0;
        for (fss::FaceIndex f : patch.faces()) {
            std::vector<Eigen::Vector2d> q;
            for (fss::VertexIndex v : CGAL::vertices_around_face(patch.halfedge(f), patch))
                q.push_back(scanCamera.project(vec(patch.point(v))).head<2>());
            patchArea +=
                std::abs((q[1] - q[0]).x() * (q[2] - q[0]).y() - (q[1] - q[0]).y() * (q[2] - q[0]).x()) / 2;
        }
        QVERIFY2(patchArea > 0.7 * lassoArea && patchArea < lassoArea,
                 qPrintable(QString("patch %1 px², lasso %2 px²").arg(patchArea).arg(lassoArea)));

        const fss::Mesh before = w->mesh();
        const std::size_t panelUpdates = w->qualityPanel()->updateCount();
        w->accept();
        QVERIFY(w->isBusy());
        QVERIFY(!w->lassoTool()->isEnabled()); // tools are disabled while the stitch runs
        QVERIFY(waitIdle(*w));
        QCOMPARE(accepted.count(), 1);
        QCOMPARE(changed.count(), 1);
        QVERIFY(!w->hasPreview());
        const fss::Mesh after = w->mesh();
        QVERIFY(!identical(before, after));
        QVERIFY(after.number_of_faces() != before.number_of_faces());
        const auto report = accepted.at(0).at(0).value<fss::StitchReport>();
        QVERIFY(report.facesAdded > 0 && report.facesRemoved > 0);
        const std::size_t far = checkInvariants(before, after, patch);
        QVERIFY2(far > 1000, qPrintable(QString("only %1 far faces were checked").arg(far)));
        QCOMPARE(w->qualityPanel()->updateCount(), panelUpdates + 1);
        compareQuality(*w->qualityPanel(), after);
        QCOMPARE(w->undoStack()->count(), 1);
        QCOMPARE(w->historyView()->model()->rowCount(), 2); // "Input mesh" and the scan
        qInfo("lasso scan: %zu patch faces; stitch removed %zu, added %zu faces; %zu far faces untouched",
              std::size_t(patch.number_of_faces()), report.facesRemoved, report.facesAdded, far);

        // Undo restores the exact previous mesh; redo the exact result.
        w->undoStack()->undo();
        QVERIFY(identical(w->mesh(), before));
        compareQuality(*w->qualityPanel(), before);
        QCOMPARE(changed.count(), 2);
        w->undoStack()->redo();
        QVERIFY(identical(w->mesh(), after));
        compareQuality(*w->qualityPanel(), after);
        QCOMPARE(w->session()->undoCount(), std::size_t(1));
        QCOMPARE(w->qualityPanel()->updateCount(), panelUpdates + 3);
    }

    void fishboneSeedAndTwoKeyRibsGiveAGridPreview() {
        // A cylinder seen from the side: the minimal curvature runs along its axis (vertical on screen), the
        // maximal one around it (horizontal).
        auto w = shownWidget(fss::shapes::cylinder(96, 48, 1.0, 2.0, true));
        QVERIFY(w);
        w->view()->setStandardView(fss::StandardView::PosX);
        w->scanPanel()->setResolution(256);
        w->scanPanel()->setFishboneSpacing(3.0);
        w->setActiveTool(w->fishboneTool());
        FishboneTool* tool = w->fishboneTool();
        QVERIFY(w->statusText().contains("seed"));
        tool->setRibMode(FishboneTool::RibMode::KeyRibs);
        QWidget* view = w->view();
        const QPointF centre(view->width() / 2.0, view->height() / 2.0);
        click(view, centre); // the seed: the first fishbone scan estimates the curvature on the worker
        QVERIFY(waitIdle(*w));
        QTRY_VERIFY_WITH_TIMEOUT(tool->backbone().size() > 10, 30000);
        QVERIFY2(!tool->hasGridPreview(), "key-rib mode shows only the backbone before two key-ribs");
        QVERIFY(!w->hasPreview());
        QVERIFY(w->statusText().contains("key-rib 1"));
        // Around the seed the backbone runs along the axis: vertical on the screen. (Beyond the side it
        // follows the rims, the caps' creases, whose minimal curvature direction runs along them.)
        const QPolygonF backbone = tool->backbone();
        qsizetype i0 = 0;
        for (qsizetype i = 0; i < backbone.size(); ++i)
            if (QLineF(backbone[i], centre).length() < QLineF(backbone[i0], centre).length()) i0 = i;
        QVERIFY(QLineF(backbone[i0], centre).length() < 3.0);
        QVERIFY(i0 >= 15 && i0 + 15 < backbone.size());
        QPolygonF side;
        for (qsizetype i = i0 - 15; i <= i0 + 15; ++i)
            side << backbone[i];
        const QRectF bb = side.boundingRect();
        QVERIFY2(bb.height() > 100 && bb.width() < 2,
                 qPrintable(QString("backbone near the seed %1 x %2").arg(bb.width()).arg(bb.height())));

        const QPointF k1 = backbone[i0 - 12], k2 = backbone[i0 + 12];
        click(view, k1 + QPointF(3, 0)); // a little off the backbone: snapped onto it
        QVERIFY(w->statusText().contains("key-rib 2"));
        click(view, k2 + QPointF(-3, 0));
        QCOMPARE(tool->keyRibs().size(), std::size_t(2));
        QVERIFY(tool->hasGridPreview());
        QVERIFY(w->hasPreview());
        QVERIFY(tool->ribCount() > 10);
        const fss::ScanPreview& preview = *w->session()->preview();
        QVERIFY(preview.fishbone.has_value());
        QVERIFY(preview.step.fishbone.has_value());
        QCOMPARE(preview.step.fishbone->keyRibs.size(), std::size_t(2));
        QVERIFY(preview.fishbone->rows > 10 && preview.fishbone->cols > 10);
        QVERIFY(preview.patch.mesh.number_of_faces() > 100);
        // The key-ribs were converted to scan pixels: each lies on a backbone sample of the grid.
        const fss::widgets::ScreenMapping mapping{
            QSizeF(view->size()), QSize(preview.step.params.camera.width, preview.step.params.camera.height)};
        for (std::size_t k = 0; k < 2; ++k) {
            const Eigen::Vector2d expected = mapping.toImage(tool->keyRibs()[k]);
            QVERIFY((preview.step.fishbone->keyRibs[k] - expected).norm() < 1e-9);
            double nearest = 1e9;
            for (int r = 0; r < preview.fishbone->rows; ++r)
                if (preview.fishbone->isPresent(r, preview.fishbone->backboneColumn))
                    nearest = std::min(
                        nearest,
                        (preview.fishbone->at(r, preview.fishbone->backboneColumn) - expected).norm());
            QVERIFY2(nearest < 0.5, qPrintable(QString::number(nearest)));
        }
        // Ribs run around the cylinder: horizontal on the screen (the rib through the seed's row).
        int mid = 0;
        const Eigen::Vector2d seedImage = mapping.toImage(centre);
        for (int r = 0; r < preview.fishbone->rows; ++r)
            if (preview.fishbone->isPresent(r, preview.fishbone->backboneColumn) &&
                (preview.fishbone->at(r, preview.fishbone->backboneColumn) - seedImage).norm() <
                    (preview.fishbone->at(mid, preview.fishbone->backboneColumn) - seedImage).norm())
                mid = r;
        Eigen::Vector2d first(0, 0), last(0, 0);
        bool haveFirst = false;
        for (int c = 0; c < preview.fishbone->cols; ++c)
            if (preview.fishbone->isPresent(mid, c)) {
                if (!haveFirst) first = preview.fishbone->at(mid, c);
                haveFirst = true;
                last = preview.fishbone->at(mid, c);
            }
        QVERIFY(std::abs((last - first).x()) > 5 * std::abs((last - first).y()));
        qInfo("fishbone: %d x %d grid, %zu rib vertices shown as %zu ribs, patch %zu faces",
              preview.fishbone->rows, preview.fishbone->cols, preview.fishbone->presentCount(),
              tool->ribCount(), std::size_t(preview.patch.mesh.number_of_faces()));

        // Dragging a key-rib along the backbone rescans.
        const QPointF from = tool->keyRibs()[0];
        const QPointF to = backbone[i0 - 9];
        sendMouse(view, QEvent::MouseButtonPress, from, Qt::LeftButton, Qt::LeftButton);
        sendMouse(view, QEvent::MouseMove, to, Qt::NoButton, Qt::LeftButton);
        sendMouse(view, QEvent::MouseButtonRelease, to, Qt::LeftButton, Qt::NoButton);
        QVERIFY(std::hypot(tool->keyRibs()[0].x() - to.x(), tool->keyRibs()[0].y() - to.y()) < 1e-9);
        QVERIFY(tool->hasGridPreview());
        if (qEnvironmentVariableIsSet("FSS_TEST_SCREENSHOTS"))
            w->grab().save(QStringLiteral("/tmp/fishbone_widget.png"));

        // The sampling image: by default about one pixel per sample (h = 3 → the largest divisor of both
        // sides up to 3); "Fine direction field" rescans on the full image.
        {
            const fss::ScanPreview& coarse = *w->session()->preview();
            const fss::Camera& scanCamera = coarse.step.params.camera;
            QCOMPARE(coarse.step.fishbone->samplingFactor, 0);
            const int k = fss::fishboneSamplingFactor(scanCamera, *coarse.step.fishbone);
            QVERIFY(k >= 2);
            QCOMPARE(coarse.grid.camera.width, scanCamera.width / k);
            w->scanPanel()->setFishboneFineField(true);
            QVERIFY(waitIdle(*w));
            const fss::ScanPreview& fine = *w->session()->preview();
            QCOMPARE(fine.step.fishbone->samplingFactor, 1);
            QCOMPARE(fine.grid.camera.width, scanCamera.width);
            QVERIFY(tool->hasGridPreview());
            QVERIFY(fine.patch.mesh.number_of_faces() > 100);
        }

        // Accept: the fishbone patch is stitched in.
        const fss::Mesh before = w->mesh();
        const fss::Mesh patch = w->session()->preview()->patch.mesh;
        QTest::keyClick(view, Qt::Key_Return);
        QVERIFY(waitIdle(*w));
        QCOMPARE(w->undoStack()->count(), 1);
        QVERIFY(!identical(before, w->mesh()));
        checkInvariants(before, w->mesh(), patch);
        compareQuality(*w->qualityPanel(), w->mesh());
    }

    void aDrawnBackboneGivesAGridAlongIt() {
        auto w = shownWidget(fss::shapes::cylinder(96, 48, 1.0, 2.0, true));
        QVERIFY(w);
        w->view()->setStandardView(fss::StandardView::PosX);
        w->scanPanel()->setResolution(256);
        w->scanPanel()->setFishboneSpacing(3.0);
        w->setActiveTool(w->fishboneTool());
        FishboneTool* tool = w->fishboneTool();
        tool->setInputMode(FishboneTool::InputMode::DrawBackbone);
        QVERIFY(w->statusText().contains("draw the backbone"));
        QWidget* view = w->view();
        // A slanted stroke across the side of the cylinder.
        const QPointF a(view->width() / 2.0 - 40, view->height() / 2.0 - 80);
        const QPointF b(view->width() / 2.0 + 40, view->height() / 2.0 + 80);
        sendMouse(view, QEvent::MouseButtonPress, a, Qt::LeftButton, Qt::LeftButton);
        for (int i = 1; i <= 20; ++i)
            sendMouse(view, QEvent::MouseMove, a + (b - a) * (i / 20.0), Qt::NoButton, Qt::LeftButton);
        sendMouse(view, QEvent::MouseButtonRelease, b, Qt::LeftButton, Qt::NoButton);
        QVERIFY(tool->drawnBackbone().size() >= 10);
        QVERIFY(!tool->seed());
        QVERIFY(waitIdle(*w));
        QTRY_VERIFY_WITH_TIMEOUT(tool->hasGridPreview(), 30000);
        const fss::ScanPreview& preview = *w->session()->preview();
        QVERIFY(preview.step.fishbone && !preview.step.fishbone->drawnBackbone.empty());
        QVERIFY(preview.patch.mesh.number_of_faces() > 100);
        // The grid's backbone follows the stroke: every backbone sample lies on the segment a–b (DIP).
        for (const QPointF& p : tool->backbone()) {
            const QPointF d = b - a;
            const double t = std::clamp(QPointF::dotProduct(p - a, d) / QPointF::dotProduct(d, d), 0.0, 1.0);
            QVERIFY2(QLineF(p, a + t * d).length() < 1.5,
                     qPrintable(QString("(%1, %2)").arg(p.x()).arg(p.y())));
        }
        QVERIFY(tool->backbone().size() > 20);
    }

    void aLassoOverTheBackgroundFailsWithOneSentence() {
        auto w = shownWidget(fss::shapes::icosphere(3));
        QVERIFY(w);
        w->view()->setStandardView(fss::StandardView::PosZ);
        w->setActiveTool(w->lassoTool());
        drawLasso(w->view(), QPointF(30, 30), 15); // in the corner: background only
        QSignalSpy errors(w.get(), &RemeshWidget::errorOccurred);
        QVERIFY(!w->scan());
        QCOMPARE(errors.count(), 1);
        const QString message = errors.at(0).at(0).toString();
        QVERIFY2(message.endsWith('.') && !message.contains('\n'), qPrintable(message));
        QVERIFY(!w->hasPreview());
        QCOMPARE(w->statusText(), message);
        w->accept(); // nothing to accept: a sentence, no work started
        QCOMPARE(errors.count(), 2);
        QVERIFY(!w->isBusy());
        QCOMPARE(w->undoStack()->count(), 0);
    }

    void cancelStopsTheCurvatureEstimate() {
        auto w =
            shownWidget(fss::shapes::torus(320, 160, 1.0, 0.4)); // 100k faces: the estimate takes a while
        QVERIFY(w);
        w->view()->setStandardView(fss::StandardView::PosZ);
        w->setActiveTool(w->fishboneTool());
        QWidget* view = w->view();
        click(view, QPointF(view->width() / 2.0 + view->height() / 3.0, view->height() / 2.0));
        QVERIFY(w->isBusy());
        QVERIFY(!w->fishboneTool()->isEnabled());
        QVERIFY(w->statusText().contains("curvature"));
        QPushButton* cancel = nullptr;
        for (QPushButton* b : w->findChildren<QPushButton*>())
            if (b->text() == "Cancel") cancel = b;
        QVERIFY(cancel && cancel->isVisible());
        QTest::mouseClick(cancel, Qt::LeftButton);
        QVERIFY(waitIdle(*w));
        QVERIFY(!w->session()->preview());
        QVERIFY(!const_cast<fss::Session*>(w->session())
                     ->fishboneCache()
                     .hasCurvature(w->session()->reference()));
        QVERIFY(!w->fishboneTool()->hasInput());
        QVERIFY2(w->statusText().contains("cancelled"), qPrintable(w->statusText()));
        QVERIFY(w->fishboneTool()->isEnabled());
    }

    // Issue #21 item 1: camera changes keep the previews (fishbone and regular) and say what was dropped.
    void zoomAfterSeedingKeepsTheFishbonePreview() {
        auto w = shownWidget(fss::shapes::cylinder(96, 48, 1.0, 2.0, true));
        QVERIFY(w);
        w->view()->setStandardView(fss::StandardView::PosX);
        w->scanPanel()->setResolution(128);
        w->scanPanel()->setFishboneSpacing(3.0);
        w->setActiveTool(w->fishboneTool());
        QWidget* view = w->view();
        const QPointF centre(view->width() / 2.0, view->height() / 2.0);
        click(view, centre); // the seed; automatic ribs give a grid preview
        QVERIFY(waitIdle(*w));
        QTRY_VERIFY_WITH_TIMEOUT(w->hasPreview(), 30000);
        QVERIFY(w->session()->preview()->step.fishbone.has_value());
        const std::size_t faces = w->session()->preview()->patch.mesh.number_of_faces();
        const fss::Camera before = w->view()->camera();
        sendWheel(view, centre, 120); // zoom
        QVERIFY((w->view()->camera().eye - before.eye).norm() > 1e-6);
        QVERIFY(w->hasPreview());
        QVERIFY(w->view()->hasPreviewMesh());
        QCOMPARE(w->session()->preview()->patch.mesh.number_of_faces(), faces);
        QVERIFY(w->session()->preview()->step.fishbone.has_value());
        QVERIFY(!w->fishboneTool()->hasInput()); // the screen strokes are gone
        QVERIFY2(w->statusText().contains("fishbone strokes") && w->statusText().contains("preview is kept"),
                 qPrintable(w->statusText()));

        // A lasso scan, then a pan: the preview stays, the lasso goes, the status line says so.
        w->reject();
        w->setActiveTool(w->lassoTool());
        drawLasso(view, centre, 60);
        QVERIFY(w->scan());
        QVERIFY(w->lassoTool()->hasLasso());
        sendMouse(view, QEvent::MouseButtonPress, centre, Qt::MiddleButton, Qt::MiddleButton);
        for (int i = 1; i <= 5; ++i)
            sendMouse(view, QEvent::MouseMove, centre + QPointF(6 * i, 0), Qt::NoButton, Qt::MiddleButton);
        sendMouse(view, QEvent::MouseButtonRelease, centre + QPointF(30, 0), Qt::MiddleButton, Qt::NoButton);
        QVERIFY(w->hasPreview());
        QVERIFY(!w->lassoTool()->hasLasso());
        QVERIFY2(w->statusText().contains("the lasso") && w->statusText().contains("preview is kept"),
                 qPrintable(w->statusText()));
        w->reject(); // the next action clears the note
        QVERIFY2(!w->statusText().contains("dropped"), qPrintable(w->statusText()));
    }

    // Issue #21 items 2 and 6: History numbers accepted steps from 1 (rejected previews do not count) and
    // names view, resolution and grid; the entry and the status line give faces replaced, valence 6 and
    // the smallest angle before → after (checked against independent counts).
    void historyNamesStepsFromOneWithTheirFigures() {
        auto w = shownWidget(fss::shapes::icosphere(3));
        QVERIFY(w);
        w->view()->setStandardView(fss::StandardView::PosZ);
        w->scanPanel()->setResolution(96);
        w->scanPanel()->setForceReplace(true);
        QVERIFY(w->scan());
        w->reject(); // not a step
        QVERIFY(w->scan());
        const fss::Camera cam = w->session()->preview()->step.params.camera;
        const auto before = valence6AndMinAngle(w->mesh());
        QSignalSpy accepted(w.get(), &RemeshWidget::scanAccepted);
        w->accept();
        QVERIFY(waitIdle(*w));
        QCOMPARE(accepted.count(), 1);
        const auto report = accepted.at(0).at(0).value<fss::StitchReport>();
        const auto after = valence6AndMinAngle(w->mesh());
        QCOMPARE(w->undoStack()->count(), 1);
        const QString name = w->undoStack()->text(0);
        const QString prefix =
            QString("1. Scan from +Z, %1×%2 px, regular grid — ").arg(cam.width).arg(cam.height);
        QVERIFY2(name.startsWith(prefix), qPrintable(name));
        const QString figures[] = {
            QString("%1 faces replaced").arg(report.facesRemoved),
            QString("valence 6 %1 % → %2 %")
                .arg(100 * before.first, 0, 'f', 1)
                .arg(100 * after.first, 0, 'f', 1),
            QString("min angle %1° → %2°").arg(before.second, 0, 'f', 1).arg(after.second, 0, 'f', 1)};
        QVERIFY(report.facesRemoved > 0);
        for (const QString& f : figures) {
            QVERIFY2(name.contains(f), qPrintable(name + " lacks " + f));
            QVERIFY2(w->statusText().contains(f), qPrintable(w->statusText() + " lacks " + f));
        }
        QVERIFY(w->statusText().startsWith("Accepted: "));
        // Undo, then a new step: numbered 1 again (the undone one is gone).
        w->undoStack()->undo();
        QVERIFY(!w->statusText().startsWith("Accepted: ")); // stale texts go
        QVERIFY(w->scan());
        w->accept();
        QVERIFY(waitIdle(*w));
        QCOMPARE(w->undoStack()->count(), 1);
        QVERIFY(w->undoStack()->text(0).startsWith("1. Scan from +Z"));
    }

    // Issue #21 item 5: the side panel scrolls instead of collapsing; spin boxes keep their height.
    void sidePanelStaysUsableInSmallWindows() {
        for (const QSize size : {QSize(800, 500), QSize(640, 420)}) {
            auto w = shownWidget(fss::shapes::icosphere(2), size);
            QVERIFY(w);
            const auto boxes = w->scanPanel()->findChildren<QAbstractSpinBox*>();
            QVERIFY(boxes.size() >= 8);
            for (QAbstractSpinBox* b : boxes)
                QVERIFY2(b->height() >= b->sizeHint().height(), qPrintable(QString("%1 px high at %2×%3")
                                                                               .arg(b->height())
                                                                               .arg(size.width())
                                                                               .arg(size.height())));
            QVERIFY(w->scanPanel()->width() >= w->scanPanel()->minimumSizeHint().width());
            auto* scroll = w->findChild<QScrollArea*>();
            QVERIFY(scroll && scroll->isVisible());
            QVERIFY(scroll->verticalScrollBar()->maximum() > 0); // the rest is reachable by scrolling
            QVERIFY(w->historyView()->height() >= 100);
            QVERIFY(w->view()->width() >= 200);
        }
    }

    // Issue #21 items 7 and 8: a target edge length in world units (default: the input's mean edge
    // length) sets the resolution for the view; a typed resolution is held; Enter in it scans.
    void targetEdgeLengthSetsTheResolutionAndEnterScans() {
        const fss::Mesh sphere = fss::shapes::icosphere(3);
        auto w = shownWidget(sphere);
        QVERIFY(w);
        fss::widgets::ScanPanel* panel = w->scanPanel();
        double sum = 0;
        for (fss::HalfedgeIndex h : sphere.halfedges())
            sum += std::sqrt(
                CGAL::squared_distance(sphere.point(sphere.source(h)), sphere.point(sphere.target(h))));
        const double mean = sum / double(sphere.number_of_halfedges());
        QVERIFY(std::abs(panel->inputEdgeLength() - mean) < 1e-9 * mean);
        QVERIFY(std::abs(panel->targetEdgeLength() - mean) < 1e-3 * mean);
        QVERIFY(panel->followsTargetEdgeLength());

        const double target = mean / 8;
        panel->setTargetEdgeLength(target);
        const int r1 = panel->resolution();
        QVERIFY2(r1 > 32 && r1 < 4096, qPrintable(QString::number(r1)));
        const Eigen::Vector3d centre = fss::boundingBox(sphere).center();
        auto footprint = [&] { return panel->scanCamera(w->view()->camera()).pixelFootprint(centre); };
        QVERIFY2(std::abs(footprint() - target) < 0.01 * target,
                 qPrintable(QString("%1 vs %2").arg(footprint()).arg(target)));
        QVERIFY(std::abs(panel->edgeLength() - footprint()) < 1e-12 * target);
        // Twice as close: half the resolution for the same edge length.
        fss::Camera c = w->view()->camera();
        const fss::Camera far = c;
        c.eye = c.focal + 0.5 * (c.eye - c.focal);
        w->view()->setCamera(c);
        QVERIFY2(std::abs(panel->resolution() - r1 / 2.0) <= 1.5,
                 qPrintable(QString("%1 then %2").arg(r1).arg(panel->resolution())));
        QVERIFY(std::abs(footprint() - target) < 0.02 * target);
        // A typed resolution is held when the view changes.
        panel->setResolution(100);
        QVERIFY(!panel->followsTargetEdgeLength());
        w->view()->setCamera(far);
        QCOMPARE(panel->resolution(), 100);

        auto* box = panel->findChild<QSpinBox*>("resolution");
        QVERIFY(box);
        box->setFocus();
        QTest::keyClick(box, Qt::Key_Return);
        QVERIFY(w->hasPreview());
        const fss::Camera scanned = w->session()->preview()->step.params.camera;
        QCOMPARE(std::max(scanned.width, scanned.height), 100);
    }

    // Issue #21 item 10: every tool-bar action has a tooltip that says more than its label.
    // The scan panel's lattice reaches the scan: the default is the core's (adaptive, slant mask 35°); on the
    // square lattice every sample sits at a pixel centre of the scan image, on the adaptive one most do not.
    void scanPanelLatticeReachesTheScan() {
        auto w = shownWidget(fss::shapes::icosphere(4), {900, 700});
        QVERIFY(w);
        w->view()->setStandardView(fss::StandardView::Iso);
        w->scanPanel()->setResolution(64);
        QCOMPARE(w->scanPanel()->lattice(), fss::ScanOptions{}.lattice);
        QCOMPARE(w->scanPanel()->minLatticeAngleDeg(), fss::ScanOptions{}.minLatticeAngleDeg);
        // Share of the preview's vertices within 1e-6 px of a pixel centre of the scan image.
        auto atPixelCentres = [&w] {
            const fss::ScanPreview& preview = *w->session()->preview();
            const fss::Camera& camera = preview.step.params.camera;
            std::size_t n = 0, centred = 0;
            for (fss::VertexIndex v : preview.patch.mesh.vertices()) {
                const fss::Point3& p = preview.patch.mesh.point(v);
                const Eigen::Vector3d q = camera.project({p.x(), p.y(), p.z()});
                ++n;
                centred += std::abs(q.x() - 0.5 - std::round(q.x() - 0.5)) < 1e-6 &&
                                   std::abs(q.y() - 0.5 - std::round(q.y() - 0.5)) < 1e-6
                               ? 1
                               : 0;
            }
            return n > 100 ? double(centred) / double(n) : -1.0;
        };
        QVERIFY(w->scan());
        QCOMPARE(w->session()->preview()->step.params.scan.lattice, fss::Lattice::Adaptive);
        const double adaptive = atPixelCentres();
        w->reject();
        w->scanPanel()->setLattice(fss::Lattice::Square);
        w->scanPanel()->setMinLatticeAngleDeg(0);
        QVERIFY(w->scan());
        const fss::ScanParams& params = w->session()->preview()->step.params;
        QCOMPARE(params.scan.lattice, fss::Lattice::Square);
        QCOMPARE(params.scan.minLatticeAngleDeg, 0.0);
        const double square = atPixelCentres();
        QVERIFY2(square > 0.999 && adaptive >= 0 && adaptive < 0.5,
                 qPrintable(QString("at pixel centres: square %1, adaptive %2").arg(square).arg(adaptive)));
    }

    void toolBarActionsExplainThemselves() {
        RemeshWidget w;
        auto* bar = w.findChild<QToolBar*>();
        QVERIFY(bar);
        int checked = 0;
        for (QAction* a : bar->actions()) {
            if (a->isSeparator()) continue;
            const QString label = QString(a->text()).remove('&');
            QVERIFY2(a->toolTip().size() > label.size() + 15, qPrintable(label + ": " + a->toolTip()));
            ++checked;
        }
        QVERIFY(checked >= 12);
        QVERIFY(w.redoAction()->shortcuts().contains(QKeySequence(Qt::CTRL | Qt::Key_Y)));
        QVERIFY(w.redoAction()->shortcuts().contains(QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_Z)));
    }

    // Issue 21 item 2: a 64 px scan over the whole view is stitched on a copy in the background; the preview
    // then shades the faces the stitch keeps (blue) and trims (red), the status line counts them, and the
    // accepted mesh is the trial's.
};

int main(int argc, char** argv) {
    fss::widgets::VtkView::setDefaultSurfaceFormat();
    QApplication app(argc, argv);
    RemeshWidgetTest test;
    return QTest::qExec(&test, argc, argv);
}

#include "remesh_widget_test.moc"
