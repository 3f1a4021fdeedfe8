#pragma once
// The subcommands of fss-remesh. Each takes its arguments (after the subcommand name) and returns the
// process exit code; errors propagate as exceptions and are turned into one sentence by main().
#include <string>
#include <vector>

namespace fss::cli {

int runInfo(const std::vector<std::string>& args);
#ifdef FSS_HAVE_RENDER
int runScan(const std::vector<std::string>& args);
int runRun(const std::vector<std::string>& args);
int runAuto(const std::vector<std::string>& args);
#endif

} // namespace fss::cli
