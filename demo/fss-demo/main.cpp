// fss-demo: the FSS demo application (a main window around VtkView).
//
//   fss-demo [--view V] [--colormap C] [MESH]
//   fss-demo --screenshot FILE.png [--view iso|+x|-x|+y|-y|+z|-z] [--colormap none|angle|valence|scan-id]
//            [--size WxH] [--scan VIEW]... [--resolution N] [MESH | --session FILE.json]
//
// Without MESH the bundled default mesh (CGAL's fandisk) is opened. --session loads and replays a session
// file (as File > Open Session) instead of opening a mesh; --scan steps then follow its last step. --screenshot renders the window to
// FILE and exits: 0 on success, 1 with one sentence on stderr when it failed, 2 for a wrong command line.
// Each --scan VIEW first takes a regular scan of the whole view from that standard view (at --resolution,
// default 256) and accepts it, as a user would with Take scan and Accept.
#include "main_window.h"

#include <fss/camera.h>
#include <fss/error.h>
#include <fss/mesh_io.h>
#include <fss/widgets/remesh_widget.h>
#include <fss/widgets/scan_panel.h>
#include <fss/widgets/vtk_view.h>

#include <QApplication>
#include <QElapsedTimer>
#include <QThread>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

namespace {

const char* const kUsage =
    "usage: fss-demo [--screenshot FILE.png] [--view iso|+x|-x|+y|-y|+z|-z] [--colormap none|angle|valence|scan-id]\n"
    "                [--size WxH] [--scan VIEW]... [--resolution N] [MESH | --session FILE.json]\n";

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

// Parses the command line; prints one sentence and returns nullopt when it is wrong.
std::optional<Options> parse(int argc, char** argv, bool& help) {
    Options o;
    bool haveMesh = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&](const char* name) -> std::optional<std::string> {
            if (i + 1 >= argc) {
                std::cerr << "Option " << name << " needs a value.\n" << kUsage;
                return std::nullopt;
            }
            return std::string(argv[++i]);
        };
        if (a == "-h" || a == "--help") {
            help = true;
            return o;
        } else if (a == "--screenshot") {
            const auto v = value("--screenshot");
            if (!v) return std::nullopt;
            o.screenshot = *v;
        } else if (a == "--session") {
            const auto v = value("--session");
            if (!v) return std::nullopt;
            o.session = *v;
        } else if (a == "--view") {
            const auto v = value("--view");
            if (!v) return std::nullopt;
            const auto view = fss::parseStandardView(*v);
            if (!view) {
                std::cerr << "Unknown view '" << *v << "': use iso, +x, -x, +y, -y, +z or -z.\n";
                return std::nullopt;
            }
            o.view = *view;
        } else if (a == "--scan") {
            const auto v = value("--scan");
            if (!v) return std::nullopt;
            const auto view = fss::parseStandardView(*v);
            if (!view) {
                std::cerr << "Unknown scan view '" << *v << "': use iso, +x, -x, +y, -y, +z or -z.\n";
                return std::nullopt;
            }
            o.scans.push_back(*view);
        } else if (a == "--resolution") {
            const auto v = value("--resolution");
            if (!v) return std::nullopt;
            char rest = 0;
            if (std::sscanf(v->c_str(), "%d%c", &o.resolution, &rest) != 1 || o.resolution < 16 ||
                o.resolution > 4096) {
                std::cerr << "Bad resolution '" << *v << "': use a number of pixels between 16 and 4096.\n";
                return std::nullopt;
            }
        } else if (a == "--colormap") {
            const auto v = value("--colormap");
            if (!v) return std::nullopt;
            const auto map = fss::widgets::parseColorMap(*v);
            if (!map) {
                std::cerr << "Unknown colour map '" << *v << "': use none, angle or valence.\n";
                return std::nullopt;
            }
            o.colorMap = *map;
        } else if (a == "--size") {
            const auto v = value("--size");
            if (!v) return std::nullopt;
            int w = 0, h = 0;
            char rest = 0;
            if (std::sscanf(v->c_str(), "%dx%d%c", &w, &h, &rest) != 2 || w < 64 || h < 64 || w > 8192 ||
                h > 8192) {
                std::cerr << "Bad size '" << *v << "': use WIDTHxHEIGHT, each between 64 and 8192.\n";
                return std::nullopt;
            }
            o.width = w;
            o.height = h;
        } else if (!a.empty() && a[0] == '-') {
            std::cerr << "Unknown option '" << a << "'.\n" << kUsage;
            return std::nullopt;
        } else if (haveMesh) {
            std::cerr << "Only one mesh file can be given.\n" << kUsage;
            return std::nullopt;
        } else {
            o.mesh = a;
            haveMesh = true;
        }
    }
    if (haveMesh && o.session) {
        std::cerr << "Give either a mesh or --session, not both.\n" << kUsage;
        return std::nullopt;
    }
    return o;
}

} // namespace

int main(int argc, char** argv) {
    bool help = false;
    const std::optional<Options> options = parse(argc, argv, help);
    if (help) {
        std::cout << kUsage;
        return 0;
    }
    if (!options) return 2;

    // In --screenshot mode the mesh is read before any window exists, so that a bad file ends the program
    // with its one sentence and nothing else.
    std::optional<fss::Mesh> mesh;
    if (options->screenshot && !options->session) {
        try {
            mesh = fss::readMesh(options->mesh);
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
    if (options->screenshot) presenter = std::make_unique<StderrPresenter>();
    fss::demo::MainWindow window(std::move(presenter));
    window.resize(options->width, options->height);
    window.view()->setInitialView(options->view);
    window.setColorMap(options->colorMap);

    if (options->screenshot) {
        if (options->session) {
            QString failure;
            QObject::connect(&window, &fss::demo::MainWindow::errorOccurred,
                             [&failure](const QString& message) { failure = message; });
            window.show(); // the replay's scans render in the view's GL context
            QApplication::processEvents();
            if (window.openSession(QString::fromStdString(*options->session)))
                while (window.remeshWidget()->isLoadingSession()) {
                    QApplication::processEvents(QEventLoop::AllEvents, 50);
                    QThread::msleep(5);
                }
            if (!failure.isEmpty() || window.mesh().is_empty()) return 1; // the presenter printed why
        } else {
            window.setMesh(std::move(*mesh),
                           QString::fromStdString(std::filesystem::path(options->mesh).filename().string()));
        }
        if (!options->scans.empty()) {
            window.show(); // the scans use the view's camera at its final size
            QApplication::processEvents();
            fss::widgets::RemeshWidget* remesh = window.remeshWidget();
            remesh->scanPanel()->setResolution(options->resolution);
            QString failure;
            QObject::connect(remesh, &fss::widgets::RemeshWidget::errorOccurred,
                             [&failure](const QString& message) { failure = message; });
            for (const fss::StandardView v : options->scans) {
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
            window.view()->setStandardView(options->view);
        }
        const QString error = window.saveScreenshot(QString::fromStdString(*options->screenshot));
        if (!error.isEmpty()) {
            std::cerr << error.toStdString() << "\n";
            return 1;
        }
        return 0;
    }
    window.show();
    if (options->session)
        window.openSession(QString::fromStdString(*options->session));
    else
        window.openMesh(QString::fromStdString(options->mesh));
    return app.exec();
}
