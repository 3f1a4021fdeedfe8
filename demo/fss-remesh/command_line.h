#pragma once
// The command line of fss-remesh on CLI11: subcommands, options (`--name VALUE` or `--name=VALUE`), flags
// and --help come from CLI11; the values are checked while CLI11 parses, and every mistake ends the
// program with one sentence (UsageError, exit code 2) that names the option and the value at fault.
//
// Numbers, resolutions and the like are read by the value parsers below (our syntax: decimal whole
// numbers, finite numbers, "WxH"); the domain parsers of the subcommands (--camera, --lasso, --fishbone)
// run as CLI11 option callbacks in the same way.

#include "fss/error.h"

#include <CLI/CLI.hpp>

#include <string>
#include <utility>
#include <vector>

namespace fss::cli {

/// Wrong use of the command line (unknown option, missing argument, malformed value); exit code 2.
class UsageError : public InvalidInputError {
public:
    using InvalidInputError::InvalidInputError;
};

// --- Value parsers: each throws UsageError naming the option and the bad value. ---

/// A decimal whole number within [min, max].
int parseInt(const std::string& option, const std::string& value, int min, int max);
/// A finite number.
double parseDouble(const std::string& option, const std::string& value);
/// "W" or "WxH" → (W, H), each within [1, maxSide].
std::pair<int, int> parseResolution(const std::string& option, const std::string& value, int maxSide);
/// "a,b,c,..." → finite numbers.
std::vector<double> parseDoubleList(const std::string& option, const std::string& value);

// --- Options on a CLI11 subcommand. Checks run while CLI11 parses and throw UsageError. ---

/// The subcommand \p name of \p app: \p summary heads its --help, \p examples close it.
CLI::App* addCommand(CLI::App& app, const std::string& name, const std::string& summary,
                     const std::string& examples);

/// -o / --output OUT, required: a mesh file with a supported extension (.off .obj .ply .stl).
CLI::Option* addOutputMesh(CLI::App& command, std::string& out, const std::string& help);

/// An option taking a whole number within [min, max] (the range checked by CLI::Range).
CLI::Option* addInt(CLI::App& command, const std::string& name, int& out, int min, int max,
                    const std::string& valueName, const std::string& help);

/// An option taking a finite number; with \p positive it must be > 0.
CLI::Option* addDouble(CLI::App& command, const std::string& name, double& out, bool positive,
                       const std::string& valueName, const std::string& help);

/// An option taking a resolution "W" or "WxH" (each side 1 to maxSide), stored into \p width, \p height.
CLI::Option* addResolution(CLI::App& command, const std::string& name, int& width, int& height, int maxSide,
                           const std::string& valueName, const std::string& help);

/// A CLI11 check that the value of \p option is one of \p names (CLI::IsMember).
CLI::Validator oneOf(const std::string& option, std::vector<std::string> names);

/// A CLI11 check that the value of \p option names a standard view (fss::parseStandardView).
CLI::Validator standardViewName(const std::string& option);

#ifdef FSS_HAVE_RENDER
/// --renderer R: one of \p extra or of render::kRendererChoiceNames ("auto", "gpu", "cpu").
CLI::Option* addRenderer(CLI::App& command, std::string& out, std::vector<std::string> extra,
                         const std::string& help);
#endif

/// \throw UsageError "Give either A or B, not both." when both options were given.
void requireNotBoth(const CLI::Option& a, const CLI::Option& b);

/// The one sentence for a mistake CLI11 found while parsing \p app's command line (unknown option or
/// argument, missing argument or value), as fss-remesh has always said it.
std::string usageSentence(const CLI::App& app, const CLI::ParseError& error);

} // namespace fss::cli
