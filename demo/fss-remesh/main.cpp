// fss-remesh: head-less feature-sensitive remeshing by virtual range scanning.
#include "command_line.h"
#include "commands.h"

#include "fss/error.h"

#include <CLI/CLI.hpp>

#include <exception>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

namespace {

constexpr const char* kUsage = R"(usage: fss-remesh <command> [arguments] [options]

Feature-sensitive remeshing by virtual range scanning (Vorsatz et al., VMV 2000).

commands:
  info MESH      Print quality metrics of a mesh (optionally against a reference).
  scan MESH      Scan MESH from a camera into a regular patch (and stitch it with --into).
  run SESSION    Replay a session file head-less; report metrics, timings and a snapshot.
  auto MESH      Remesh the whole surface of MESH automatically (views, resolution, coverage).

Run 'fss-remesh <command> --help' for the options of a command.
Exit status: 0 on success, 1 when the work failed, 2 when the command line is wrong.
)";

// The overview above is the --help of fss-remesh itself; the subcommands' --help is CLI11's (with a blank
// line after the summary).
class Help : public CLI::Formatter {
public:
    std::string make_help(const CLI::App* app, std::string name, CLI::AppFormatMode mode) const override {
        if (app->get_parent() == nullptr) return kUsage;
        return CLI::Formatter::make_help(app, std::move(name), mode);
    }
    std::string make_description(const CLI::App* app) const override {
        const std::string description = CLI::Formatter::make_description(app);
        return description.empty() ? description : description + "\n";
    }
};

// Parses the command line into the subcommands' state and runs the one given.
int run(int argc, char** argv, const std::string& command) {
    CLI::App app("Feature-sensitive remeshing by virtual range scanning.", "fss-remesh");
    app.formatter(std::make_shared<Help>());
    app.set_version_flag("--version", std::string("fss-remesh ") + FSS_VERSION);
    app.require_subcommand(1);
    // Subcommands copy these defaults: an option given twice takes the last value; a flag takes no value
    // (but "true").
    app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast)->disable_flag_override();
    std::vector<fss::cli::Subcommand> subcommands{fss::cli::addInfo(app)};
#ifdef FSS_HAVE_RENDER
    subcommands.push_back(fss::cli::addScan(app));
    subcommands.push_back(fss::cli::addRun(app));
    subcommands.push_back(fss::cli::addAuto(app));
#endif
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        std::cout << app.help(); // the help of the subcommand given, if any
        return 0;
    } catch (const CLI::CallForVersion& e) {
        std::cout << e.what() << "\n";
        return 0;
    } catch (const CLI::ParseError& e) {
        const std::vector<CLI::App*> given = app.get_subcommands();
        if (given.empty()) {
            std::cerr << "fss-remesh: unknown command '" << command << "'; run 'fss-remesh --help'.\n";
            return 2;
        }
        throw fss::cli::UsageError(fss::cli::usageSentence(*given.front(), e));
    }
    for (const fss::cli::Subcommand& s : subcommands)
        if (s.app->parsed()) return s.run();
    return 2; // not reached: CLI11 requires one subcommand
}

} // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::cerr << kUsage;
        return 2;
    }
    const std::string command = argv[1];
    if (command == "help") {
        std::cout << kUsage;
        return 0;
    }
    try {
        return run(argc, argv, command);
    } catch (const fss::cli::UsageError& e) {
        std::cerr << "fss-remesh " << command << ": " << e.what() << "\n";
        return 2;
    } catch (const std::bad_alloc&) {
        std::cerr << "fss-remesh " << command << ": out of memory.\n";
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "fss-remesh " << command << ": " << e.what() << "\n";
        return 1;
    }
}
