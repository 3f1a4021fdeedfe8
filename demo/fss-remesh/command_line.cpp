#include "command_line.h"
#include "mesh_files.h"

#include "fss/camera.h"
#include "fss/mesh_io.h"
#ifdef FSS_HAVE_RENDER
#include "fss/render/renderer_choice.h"
#endif

#include <charconv>
#include <cmath>

namespace fss::cli {
namespace {

// The whole number in \p value (decimal digits, optionally a leading '-', nothing else).
long long parseWholeNumber(const std::string& option, const std::string& value) {
    long long v = 0;
    const char* end = value.data() + value.size();
    auto [ptr, ec] = std::from_chars(value.data(), end, v);
    if (ec != std::errc() || ptr != end)
        throw UsageError("The value '" + value + "' of " + option + " is not a whole number.");
    return v;
}

UsageError outsideRange(const std::string& option, const std::string& value, int min, int max) {
    return UsageError("The value " + value + " of " + option + " is outside the range " +
                      std::to_string(min) + " to " + std::to_string(max) + ".");
}

// A CLI11 validator that throws UsageError itself (CLI11 would prefix its own message with the option's
// name); \p check may rewrite the value.
CLI::Validator validator(std::function<void(std::string&)> check, const std::string& name) {
    return CLI::Validator(
        [check = std::move(check)](std::string& value) {
            check(value);
            return std::string();
        },
        "", name);
}

} // namespace

int parseInt(const std::string& option, const std::string& value, int min, int max) {
    const long long v = parseWholeNumber(option, value);
    if (v < min || v > max) throw outsideRange(option, value, min, max);
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
    return {parseInt(option, value.substr(0, x), 1, maxSide),
            parseInt(option, value.substr(x + 1), 1, maxSide)};
}

std::vector<double> parseDoubleList(const std::string& option, const std::string& value) {
    std::vector<double> out;
    std::size_t start = 0;
    while (start <= value.size()) {
        const auto comma = value.find(',', start);
        const std::string item =
            value.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        out.push_back(parseDouble(option, item));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return out;
}

CLI::App* addCommand(CLI::App& app, const std::string& name, const std::string& summary,
                     const std::string& examples) {
    CLI::App* command = app.add_subcommand(name, summary);
    if (!examples.empty()) command->footer(examples);
    return command;
}

CLI::Option* addOutputMesh(CLI::App& command, std::string& out, const std::string& help) {
    return command.add_option("-o,--output", out, help)
        ->type_name("OUT")
        ->required()
        ->check(validator(
            [](std::string& path) {
                if (!isOutputMeshFile(path))
                    throw UsageError("The output file " + path + " has no supported extension (" +
                                     outputExtensions() + ").");
            },
            "mesh file"));
}

CLI::Option* addInt(CLI::App& command, const std::string& name, int& out, int min, int max,
                    const std::string& valueName, const std::string& help) {
    const CLI::Validator range = CLI::Range(min, max);
    // Our decimal syntax first; CLI11 checks the range and converts the canonical decimal it leaves.
    return command.add_option(name, out, help)
        ->type_name(valueName)
        ->transform(validator(
            [name, min, max, range](std::string& value) {
                std::string canonical = std::to_string(parseWholeNumber(name, value));
                if (!range(canonical).empty()) throw outsideRange(name, value, min, max);
                value = std::move(canonical);
            },
            "whole number"));
}

CLI::Option* addDouble(CLI::App& command, const std::string& name, double& out, bool positive,
                       const std::string& valueName, const std::string& help) {
    return command
        .add_option_function<std::string>(
            name,
            [&out, name, positive](const std::string& value) {
                const double v = parseDouble(name, value);
                if (positive && !(v > 0)) throw UsageError("The value of " + name + " must be positive.");
                out = v;
            },
            help)
        ->type_name(valueName);
}

CLI::Option* addResolution(CLI::App& command, const std::string& name, int& width, int& height, int maxSide,
                           const std::string& valueName, const std::string& help) {
    return command
        .add_option_function<std::string>(
            name,
            [&width, &height, name, maxSide](const std::string& value) {
                std::tie(width, height) = parseResolution(name, value, maxSide);
            },
            help)
        ->type_name(valueName);
}

CLI::Validator oneOf(const std::string& option, std::vector<std::string> names) {
    std::string list;
    for (std::size_t i = 0; i < names.size(); ++i)
        list += (i ? ", " : "") + names[i];
    const std::string expected = names.size() == 1 ? "is not '" + list + "'" : "is not one of " + list;
    const CLI::Validator member = CLI::IsMember(std::move(names));
    return validator(
        [option, expected, member](std::string& value) {
            std::string copy = value;
            if (!member(copy).empty())
                throw UsageError("The value '" + value + "' of " + option + " " + expected + ".");
        },
        "one of");
}

CLI::Validator standardViewName(const std::string& option) {
    return validator(
        [option](std::string& value) {
            if (!parseStandardView(value))
                throw UsageError("The value '" + value + "' of " + option +
                                 " is not one of iso, +x, -x, +y, -y, +z, -z.");
        },
        "standard view");
}

#ifdef FSS_HAVE_RENDER
CLI::Option* addRenderer(CLI::App& command, std::string& out, std::vector<std::string> extra,
                         const std::string& help) {
    for (std::string_view name : render::kRendererChoiceNames)
        extra.emplace_back(name);
    return command.add_option("--renderer", out, help)
        ->type_name("R")
        ->check(oneOf("--renderer", std::move(extra)));
}
#endif

void requireNotBoth(const CLI::Option& a, const CLI::Option& b) {
    if (a.count() > 0 && b.count() > 0)
        throw UsageError("Give either " + a.get_name() + " or " + b.get_name() + ", not both.");
}

std::string usageSentence(const CLI::App& command, const CLI::ParseError& error) {
    const std::string name = "'" + command.get_parent()->get_name() + " " + command.get_name() + "'";
    if (dynamic_cast<const CLI::RequiredError*>(&error)) {
        for (const CLI::Option* option : command.get_options()) {
            if (!option->get_required() || option->count() > 0) continue;
            if (option->get_positional())
                return name + " needs the argument " + option->get_name() + "; see --help.";
            if (option->check_sname("o")) return name + " needs an output file: -o OUT.";
            return name + " needs the option " + option->get_name() + "; see --help.";
        }
    }
    if (dynamic_cast<const CLI::ExtrasError*>(&error)) {
        const std::vector<std::string> rest = command.remaining();
        if (!rest.empty()) {
            const std::string& first = rest.front();
            if (first.size() > 1 && first[0] == '-')
                return "Unknown option " + first.substr(0, first.find('=')) + " for " + name +
                       "; see --help.";
            return "Unexpected argument '" + first + "' for " + name + "; see --help.";
        }
    }
    const std::string what = error.what();
    if (dynamic_cast<const CLI::ArgumentMismatch*>(&error) && what.ends_with(" missing")) {
        // "--ref: 1 required REF missing": the option was the last argument, without its value.
        const CLI::Option* option = command.get_option_no_throw(what.substr(0, what.find(':')));
        if (option)
            return "The option " + option->get_name() + " needs a value (" + option->get_type_name() + ").";
    }
    const std::string flagOverride = " was given a disallowed flag override";
    if (dynamic_cast<const CLI::ArgumentMismatch*>(&error) && what.ends_with(flagOverride)) {
        // "json was given a disallowed flag override": --json=VALUE.
        const std::string flag = what.substr(0, what.size() - flagOverride.size());
        const CLI::Option* option = command.get_option_no_throw(flag);
        if (!option) option = command.get_option_no_throw((flag.size() == 1 ? "-" : "--") + flag);
        if (option) return "The flag " + option->get_name() + " takes no value.";
    }
    return what.empty() || what.back() == '.' ? what : what + ".";
}

} // namespace fss::cli
