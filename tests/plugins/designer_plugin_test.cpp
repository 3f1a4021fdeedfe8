// The Qt Designer plugin: loaded the way Designer loads it (QPluginLoader on the built file), its
// collection offers FSS's widgets with sensible metadata, and every widget it creates is a working
// widget (parented, shown under Xvfb; the VtkView renders its background). Not linked to FSS::widgets:
// the widgets come from the plugin only.
#include <QApplication>
#include <QDesignerCustomWidgetCollectionInterface>
#include <QDesignerCustomWidgetInterface>
#include <QDir>
#include <QFileInfo>
#include <QOpenGLWidget>
#include <QPluginLoader>
#include <QSurfaceFormat>
#include <QTest>
#include <QVBoxLayout>

#include <memory>

class DesignerPluginTest : public QObject {
    Q_OBJECT
private slots:
    void loadsAndCreatesEveryWidget() {
        QPluginLoader loader(QStringLiteral(FSS_DESIGNER_PLUGIN));
        QVERIFY2(loader.load(), qPrintable(loader.errorString()));
        QObject* instance = loader.instance();
        QVERIFY(instance);
        QCOMPARE(instance->metaObject()->className(), "fss::designer::WidgetCollection");
        auto* collection = qobject_cast<QDesignerCustomWidgetCollectionInterface*>(instance);
        QVERIFY2(collection, "the plugin is not a QDesignerCustomWidgetCollectionInterface");
        const QList<QDesignerCustomWidgetInterface*> widgets = collection->customWidgets();
        QVERIFY(!widgets.isEmpty());

        QStringList names;
        for (QDesignerCustomWidgetInterface* w : widgets) {
            const QString name = w->name();
            names << name;
            QVERIFY2(name.startsWith("fss::widgets::"), qPrintable(name));
            QCOMPARE(w->group(), QStringLiteral("FSS"));
            QVERIFY(!w->toolTip().isEmpty());
            QVERIFY(!w->whatsThis().isEmpty());
            QVERIFY(!w->isContainer());
            // The include file is a public header of FSS::widgets.
            QVERIFY2(w->includeFile().startsWith("fss/widgets/") && w->includeFile().endsWith(".h"),
                     qPrintable(w->includeFile()));
            QVERIFY2(QFileInfo::exists(QStringLiteral(FSS_WIDGETS_INCLUDE_DIR "/") + w->includeFile()),
                     qPrintable(w->includeFile()));
            QVERIFY(w->domXml().contains(QStringLiteral("class=\"%1\"").arg(name)));
            QVERIFY(!w->isInitialized());
            w->initialize(nullptr);
            QVERIFY(w->isInitialized());

            // Created with a parent, shown, it is the named class and works.
            QWidget window;
            auto* layout = new QVBoxLayout(&window);
            QWidget* widget = w->createWidget(&window);
            QVERIFY(widget);
            QCOMPARE(widget->parentWidget(), &window);
            QCOMPARE(QString::fromLatin1(widget->metaObject()->className()), name);
            layout->addWidget(widget);
            window.resize(320, 240);
            window.show();
            QVERIFY(QTest::qWaitForWindowExposed(&window));
            QVERIFY(widget->isVisible());
            QVERIFY(widget->width() > 100 && widget->height() > 100);
            if (auto* gl = qobject_cast<QOpenGLWidget*>(widget)) {
                // An empty VtkView shows its background: (0.32, 0.34, 0.43) · 255.
                const QImage image = gl->grabFramebuffer();
                QVERIFY(!image.isNull());
                const QRgb centre = image.pixel(image.width() / 2, image.height() / 2);
                QVERIFY2(std::abs(qRed(centre) - 82) <= 2 && std::abs(qGreen(centre) - 87) <= 2 &&
                             std::abs(qBlue(centre) - 110) <= 2,
                         qPrintable(QColor(centre).name()));
            }
        }
        for (const char* expected : {"fss::widgets::VtkView", "fss::widgets::RemeshWidget",
                                     "fss::widgets::ScanPanel", "fss::widgets::QualityPanel"})
            QVERIFY2(names.contains(QString::fromLatin1(expected)), qPrintable(names.join(", ")));
        qInfo("the plugin offers %lld widget(s): %s", qlonglong(names.size()), qPrintable(names.join(", ")));
    }
};

int main(int argc, char** argv) {
    // As an application using VtkView does (VtkView::setDefaultSurfaceFormat, not linked here).
    QSurfaceFormat format;
    format.setRenderableType(QSurfaceFormat::OpenGL);
    format.setVersion(3, 2);
    format.setProfile(QSurfaceFormat::CoreProfile);
    format.setDepthBufferSize(24);
    format.setStencilBufferSize(8);
    format.setAlphaBufferSize(8);
    format.setSamples(0);
    // FSS_TEST_QT_DEFAULT_FORMAT=1 keeps Qt's default format instead, as Designer itself does.
    if (!qEnvironmentVariableIsSet("FSS_TEST_QT_DEFAULT_FORMAT")) QSurfaceFormat::setDefaultFormat(format);
    QApplication app(argc, argv);
    DesignerPluginTest test;
    return QTest::qExec(&test, argc, argv);
}

#include "designer_plugin_test.moc"
