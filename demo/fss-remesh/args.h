#pragma once
// A small command-line parser for fss-remesh subcommands: positional arguments, --options with a value
// (`--name VALUE` or `--name=VALUE`) and flags, with generated --help text. Errors are UsageError.

#include "fss/error.h"

#include <functional>
#include <string>
#include <vector>

namespace fss::cli {

/// Wrong use of the command line (unknown option, missing argument, malformed value); exit code 2.
class UsageError : public InvalidInputError {
public:
    using InvalidInputError::InvalidInputError;
};

class ArgParser {
public:
    ArgParser(std::string command, std::string summary);

    /// A positional argument stored into *out.
    void positional(std::string name, std::string help, std::string* out, bool required = true);
    /// An option taking a value, stored into *out; *seen (if given) becomes true when it was given.
    void option(std::string name, std::string valueName, std::string help, std::string* out, bool* seen = nullptr);
    /// A flag without a value.
    void flag(std::string name, std::string help, bool* out);
    /// Free text appended to --help (examples, notes).
    void epilog(std::string text) { epilog_ = std::move(text); }

    /// Parses args (without the program and subcommand names). Returns false when --help was printed.
    /// \throw UsageError with one sentence.
    bool parse(const std::vector<std::string>& args);
    std::string help() const;

private:
    struct Positional {
        std::string name, help;
        std::string* out;
        bool required;
    };
    struct Option {
        std::string name, valueName, help;
        std::string* out = nullptr;
        bool* seen = nullptr;
        bool* flag = nullptr;
    };
    std::string command_, summary_, epilog_;
    std::vector<Positional> positionals_;
    std::vector<Option> options_;
};

// Value parsers: each throws UsageError naming the option and the bad value.
int parseInt(const std::string& option, const std::string& value, int min, int max);
double parseDouble(const std::string& option, const std::string& value);
/// "W" or "WxH" → (W, H), each within [1, maxSide].
std::pair<int, int> parseResolution(const std::string& option, const std::string& value, int maxSide);
/// "a,b,c,..." → doubles.
std::vector<double> parseDoubleList(const std::string& option, const std::string& value);

} // namespace fss::cli
