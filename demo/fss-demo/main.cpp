// fss-demo: the FSS demo application (a main window around VtkView).
//
//   fss-demo [--view V] [--colormap C] [MESH]
//   fss-demo --screenshot FILE.png [--view iso|+x|-x|+y|-y|+z|-z] [--colormap none|angle|valence|scan-id]
//            [--size WxH] [--scan VIEW]... [--resolution N] [MESH | --session FILE.json]
//
// Without MESH the bundled default mesh (CGAL's fandisk) is opened. --session loads and replays a session
// file (as File > Open Session) instead of opening a mesh; --scan steps then follow its last step.
// --screenshot renders the window to FILE and exits: 0 on success, 1 with one sentence on stderr when it
// failed, 2 for a wrong command line. Each --scan VIEW first takes a regular scan of the whole view from that
// standard view (at --resolution, default 256) and accepts it, as a user would with Take scan and Accept.
// --help and --version print and exit. The command line is read with QCommandLineParser.
#include "main_window.h"

#include <fss/camera.h>
#include <fss/error.h>
#include <fss/mesh_io.h>
#include <fss/widgets/remesh_widget.h>
#include <fss/widgets/scan_panel.h>
#include <fss/widgets/vtk_view.h>

#include <QApplication>
#include <QCommandLineParser>
#include <QCoreApplication>
#include <QElapsedTimer>
#include <QThread>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

namespace {

struct Options {
    std::string mesh = FSS_DEFAULT_MESH;
    std::optional<std::string> screenshot;
    fss::StandardView view = fss::StandardView::Iso;
    fss::widgets::ColorMap colorMap = fss::widgets::ColorMap::None;
    int width = 1024, height = 768;
    std::vector<fss::StandardView> scans;
    int resolution = 256;
    std::optional<std::string> session; // a session file to replay instead of opening the mesh
};

// Writes errors to stderr instead of opening a box (the --screenshot mode must never block).
class StderrPresenter final : public fss::demo::MessagePresenter {
public:
    void showError(QWidget*, const QString&, const QString& message) override {
        std::cerr << message.toStdString() << "\n";
    }
};

// What the command line asks for.
enum class Request { Run, Help, Version, Wrong };

// Parses the command line into \p o with QCommandLineParser (no QApplication needed: --help, --version and
// a wrong command line work without a display). A wrong command line is told in one sentence on stderr.
Request parse(int argc, char** argv, Options& o, QCommandLineParser& parser) {
    parser.setApplicationDescription(
        "The FSS demo application: a main window around the remeshing widget, opening MESH (by default the "
        "bundled fandisk) or replaying a session file.\n\n"
        "--screenshot renders the window to FILE.png and exits: 0 on success, 1 with one sentence on stderr "
        "when it failed, 2 for a wrong command line. Each --scan VIEW first takes a regular scan of the "
        "whole view from that standard view (at --resolution) and accepts it, as a user would with Take scan "
        "and Accept; with --session the scans follow the session's last step.");
    const QCommandLineOption help(QStringList{"h", "help"}, "Print this help and exit.");
    parser.addOption(help);
    const QCommandLineOption version = parser.addVersionOption();
    const QCommandLineOption screenshot("screenshot", "Render the window to FILE.png and exit.", "FILE.png");
    const QCommandLineOption view("view", "Standard view: iso, +x, -x, +y, -y, +z or -z (default iso).", "V");
    const QCommandLineOption colorMap("colormap",
                                      "Colour map: none, angle, valence or scan-id (default none).", "C");
    const QCommandLineOption size("size", "Window size WIDTHxHEIGHT, each 64 to 8192 (default 1024x768).",
                                  "WxH");
    const QCommandLineOption scan(
        "scan",
        "Scan and accept the whole view from this standard view first (repeatable; with --screenshot).",
        "VIEW");
    const QCommandLineOption resolution("resolution",
                                        "Resolution of the --scan scans, 16 to 4096 (default 256).", "N");
    const QCommandLineOption session(
        "session", "Load and replay this session file instead of opening a mesh.", "FILE.json");
    parser.addOptions({screenshot, view, colorMap, size, scan, resolution, session});
    parser.addPositionalArgument("MESH", "The mesh to open (.off .obj .ply .stl; default: fandisk).",
                                 "[MESH]");

    QStringList arguments;
    for (int i = 0; i < argc; ++i)
        arguments << QString::fromLocal8Bit(argv[i]);
    auto wrong = [](const std::string& sentence) {
        std::cerr << sentence << "\n";
        return Request::Wrong;
    };
    if (!parser.parse(arguments))
        return wrong(parser.errorText().toStdString() + " Run 'fss-demo --help' for the options.");
    if (parser.isSet(help)) return Request::Help;
    if (parser.isSet(version)) return Request::Version;

    if (parser.isSet(screenshot)) o.screenshot = parser.value(screenshot).toStdString();
    if (parser.isSet(session)) o.session = parser.value(session).toStdString();
    // Each option's last value counts; --scan counts every time.
    if (parser.isSet(view)) {
        const std::string v = parser.value(view).toStdString();
        const auto parsed = fss::parseStandardView(v);
        if (!parsed) return wrong("Unknown view '" + v + "': use iso, +x, -x, +y, -y, +z or -z.");
        o.view = *parsed;
    }
    for (const QString& value : parser.values(scan)) {
        const std::string v = value.toStdString();
        const auto parsed = fss::parseStandardView(v);
        if (!parsed) return wrong("Unknown scan view '" + v + "': use iso, +x, -x, +y, -y, +z or -z.");
        o.scans.push_back(*parsed);
    }
    if (parser.isSet(resolution)) {
        const std::string v = parser.value(resolution).toStdString();
        char rest = 0;
        if (std::sscanf(v.c_str(), "%d%c", &o.resolution, &rest) != 1 || o.resolution < 16 ||
            o.resolution > 4096)
            return wrong("Bad resolution '" + v + "': use a number of pixels between 16 and 4096.");
    }
    if (parser.isSet(colorMap)) {
        const std::string v = parser.value(colorMap).toStdString();
        const auto map = fss::widgets::parseColorMap(v);
        if (!map) return wrong("Unknown colour map '" + v + "': use none, angle, valence or scan-id.");
        o.colorMap = *map;
    }
    if (parser.isSet(size)) {
        const std::string v = parser.value(size).toStdString();
        int w = 0, h = 0;
        char rest = 0;
        if (std::sscanf(v.c_str(), "%dx%d%c", &w, &h, &rest) != 2 || w < 64 || h < 64 || w > 8192 || h > 8192)
            return wrong("Bad size '" + v + "': use WIDTHxHEIGHT, each between 64 and 8192.");
        o.width = w;
        o.height = h;
    }
    const QStringList meshes = parser.positionalArguments();
    if (meshes.size() > 1) return wrong("Only one mesh file can be given.");
    if (!meshes.isEmpty()) {
        if (o.session) return wrong("Give either a mesh or --session, not both.");
        o.mesh = meshes.front().toStdString();
    }
    return Request::Run;
}

} // namespace

int main(int argc, char** argv) {
    Options options;
    QCommandLineParser parser;
    switch (parse(argc, argv, options, parser)) {
    case Request::Help: {
        const QCoreApplication application(argc, argv); // the program's name in the usage line
        std::cout << parser.helpText().toStdString();
        return 0;
    }
    case Request::Version:
        std::cout << "fss-demo " << FSS_VERSION << "\n";
        return 0;
    case Request::Wrong:
        return 2;
    case Request::Run:
        break;
    }
    // In --screenshot mode the mesh is read before any window exists, so that a bad file ends the program
    // with its one sentence and nothing else.
    std::optional<fss::Mesh> mesh;
    if (options.screenshot && !options.session) {
        try {
            mesh = fss::readMesh(options.mesh);
        } catch (const std::exception& e) {
            std::cerr << e.what() << "\n";
            return 1;
        }
    }

    fss::widgets::VtkView::setDefaultSurfaceFormat(); // before the QApplication exists
    QApplication app(argc, argv);
    QApplication::setOrganizationName(QStringLiteral("FSS"));
    QApplication::setApplicationName(QStringLiteral("fss-demo"));
    QApplication::setApplicationVersion(QStringLiteral(FSS_VERSION));

    std::unique_ptr<fss::demo::MessagePresenter> presenter;
    if (options.screenshot) presenter = std::make_unique<StderrPresenter>();
    fss::demo::MainWindow window(std::move(presenter));
    window.resize(options.width, options.height);
    window.view()->setInitialView(options.view);
    window.setColorMap(options.colorMap);

    if (options.screenshot) {
        if (options.session) {
            QString failure;
            QObject::connect(&window, &fss::demo::MainWindow::errorOccurred,
                             [&failure](const QString& message) { failure = message; });
            window.show(); // the replay's scans render in the view's GL context
            QApplication::processEvents();
            if (window.openSession(QString::fromStdString(*options.session)))
                while (window.remeshWidget()->isLoadingSession()) {
                    QApplication::processEvents(QEventLoop::AllEvents, 50);
                    QThread::msleep(5);
                }
            if (!failure.isEmpty() || window.mesh().is_empty()) return 1; // the presenter printed why
        } else {
            window.setMesh(std::move(*mesh),
                           QString::fromStdString(std::filesystem::path(options.mesh).filename().string()));
        }
        if (!options.scans.empty()) {
            window.show(); // the scans use the view's camera at its final size
            QApplication::processEvents();
            fss::widgets::RemeshWidget* remesh = window.remeshWidget();
            remesh->scanPanel()->setResolution(options.resolution);
            QString failure;
            QObject::connect(remesh, &fss::widgets::RemeshWidget::errorOccurred,
                             [&failure](const QString& message) { failure = message; });
            for (const fss::StandardView v : options.scans) {
                window.view()->setStandardView(v);
                QApplication::processEvents();
                if (remesh->scan()) {
                    remesh->accept();
                    while (remesh->isBusy()) {
                        QApplication::processEvents(QEventLoop::AllEvents, 50);
                        QThread::msleep(5);
                    }
                }
                if (!failure.isEmpty()) {
                    std::cerr << "The scan from " << fss::standardViewName(v)
                              << " failed: " << failure.toStdString() << "\n";
                    return 1;
                }
            }
            window.view()->setStandardView(options.view);
        }
        const QString error = window.saveScreenshot(QString::fromStdString(*options.screenshot));
        if (!error.isEmpty()) {
            std::cerr << error.toStdString() << "\n";
            return 1;
        }
        return 0;
    }
    window.show();
    if (options.session)
        window.openSession(QString::fromStdString(*options.session));
    else
        window.openMesh(QString::fromStdString(options.mesh));
    return app.exec();
}
