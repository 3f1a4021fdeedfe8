#pragma once
// The subcommands of fss-remesh. Each add*() declares its subcommand, with its options bound to the
// command's own state, on the CLI11 application and returns it with the work that runs once the command
// line is parsed. The work returns the process exit code; errors propagate as exceptions and are turned
// into one sentence by main().
#include <CLI/CLI.hpp>

#include <functional>

namespace fss::cli {

/// A subcommand of fss-remesh.
struct Subcommand {
    CLI::App* app = nullptr;  ///< its CLI11 subcommand (options, --help)
    std::function<int()> run; ///< its work, once app->parsed()
};

Subcommand addInfo(CLI::App& app);
#ifdef FSS_HAVE_RENDER
Subcommand addScan(CLI::App& app);
Subcommand addRun(CLI::App& app);
Subcommand addAuto(CLI::App& app);
#endif

} // namespace fss::cli
