#include "args.h"

#include <charconv>
#include <cmath>
#include <iostream>
#include <sstream>

namespace fss::cli {

ArgParser::ArgParser(std::string command, std::string summary)
    : command_(std::move(command)), summary_(std::move(summary)) {}

void ArgParser::positional(std::string name, std::string help, std::string* out, bool required) {
    positionals_.push_back({std::move(name), std::move(help), out, required});
}

void ArgParser::option(std::string name, std::string valueName, std::string help, std::string* out, bool* seen) {
    options_.push_back({std::move(name), std::move(valueName), std::move(help), out, seen, nullptr});
}

void ArgParser::flag(std::string name, std::string help, bool* out) {
    options_.push_back({std::move(name), "", std::move(help), nullptr, nullptr, out});
}

bool ArgParser::parse(const std::vector<std::string>& args) {
    std::size_t nextPositional = 0;
    for (std::size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "--help" || a == "-h") {
            std::cout << help();
            return false;
        }
        if (a.size() > 1 && a[0] == '-') {
            std::string name = a, value;
            bool hasInlineValue = false;
            if (auto eq = a.find('='); eq != std::string::npos) {
                name = a.substr(0, eq);
                value = a.substr(eq + 1);
                hasInlineValue = true;
            }
            Option* opt = nullptr;
            for (Option& o : options_)
                if (o.name == name) opt = &o;
            if (!opt) throw UsageError("Unknown option " + name + " for '" + command_ + "'; see --help.");
            if (opt->flag) {
                if (hasInlineValue) throw UsageError("The flag " + name + " takes no value.");
                *opt->flag = true;
                continue;
            }
            if (!hasInlineValue) {
                if (i + 1 >= args.size())
                    throw UsageError("The option " + name + " needs a value (" + opt->valueName + ").");
                value = args[++i];
            }
            *opt->out = value;
            if (opt->seen) *opt->seen = true;
            continue;
        }
        if (nextPositional >= positionals_.size())
            throw UsageError("Unexpected argument '" + a + "' for '" + command_ + "'; see --help.");
        *positionals_[nextPositional++].out = a;
    }
    for (std::size_t k = nextPositional; k < positionals_.size(); ++k)
        if (positionals_[k].required)
            throw UsageError("'" + command_ + "' needs the argument " + positionals_[k].name + "; see --help.");
    return true;
}

std::string ArgParser::help() const {
    std::ostringstream os;
    os << "usage: " << command_;
    for (const Positional& p : positionals_) os << (p.required ? " " : " [") << p.name << (p.required ? "" : "]");
    if (!options_.empty()) os << " [options]";
    os << "\n\n" << summary_ << "\n";
    if (!positionals_.empty()) {
        os << "\narguments:\n";
        for (const Positional& p : positionals_) os << "  " << p.name << "\n      " << p.help << "\n";
    }
    os << "\noptions:\n";
    for (const Option& o : options_) {
        os << "  " << o.name;
        if (!o.valueName.empty()) os << " " << o.valueName;
        os << "\n      " << o.help << "\n";
    }
    os << "  --help\n      Print this help and exit.\n";
    if (!epilog_.empty()) os << "\n" << epilog_ << "\n";
    return os.str();
}

int parseInt(const std::string& option, const std::string& value, int min, int max) {
    long long v = 0;
    const char* end = value.data() + value.size();
    auto [ptr, ec] = std::from_chars(value.data(), end, v);
    if (ec != std::errc() || ptr != end)
        throw UsageError("The value '" + value + "' of " + option + " is not a whole number.");
    if (v < min || v > max)
        throw UsageError("The value " + value + " of " + option + " is outside the range " + std::to_string(min) +
                         " to " + std::to_string(max) + ".");
    return int(v);
}

double parseDouble(const std::string& option, const std::string& value) {
    std::size_t used = 0;
    double v = 0;
    try {
        v = std::stod(value, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != value.size() || !std::isfinite(v))
        throw UsageError("The value '" + value + "' of " + option + " is not a finite number.");
    return v;
}

std::pair<int, int> parseResolution(const std::string& option, const std::string& value, int maxSide) {
    const auto x = value.find_first_of("xX");
    if (x == std::string::npos) {
        const int w = parseInt(option, value, 1, maxSide);
        return {w, w};
    }
    return {parseInt(option, value.substr(0, x), 1, maxSide), parseInt(option, value.substr(x + 1), 1, maxSide)};
}

std::vector<double> parseDoubleList(const std::string& option, const std::string& value) {
    std::vector<double> out;
    std::size_t start = 0;
    while (start <= value.size()) {
        const auto comma = value.find(',', start);
        const std::string item = value.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        out.push_back(parseDouble(option, item));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return out;
}

} // namespace fss::cli
