// fss-remesh: head-less feature-sensitive remeshing by virtual range scanning.
#include "args.h"
#include "commands.h"

#include "fss/error.h"

#include <exception>
#include <iostream>
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

} // namespace

int main(int argc, char** argv) {
    std::vector<std::string> args(argv + 1, argv + argc);
    if (args.empty()) {
        std::cerr << kUsage;
        return 2;
    }
    const std::string command = args.front();
    args.erase(args.begin());
    try {
        if (command == "--help" || command == "-h" || command == "help") {
            std::cout << kUsage;
            return 0;
        }
        if (command == "--version") {
            std::cout << "fss-remesh " << FSS_VERSION << "\n";
            return 0;
        }
        if (command == "info") return fss::cli::runInfo(args);
#ifdef FSS_HAVE_RENDER
        if (command == "scan") return fss::cli::runScan(args);
        if (command == "run") return fss::cli::runRun(args);
        if (command == "auto") return fss::cli::runAuto(args);
#endif
        std::cerr << "fss-remesh: unknown command '" << command << "'; run 'fss-remesh --help'.\n";
        return 2;
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
