#pragma once
// Internal (not installed): the range checks of the options' validate() functions. Each failure throws
// InvalidOptionError naming "<Struct>::<field>" and the range, e.g.
// "StitchOptions::minAngleFloorDeg must be in [0, 30), not 45.".
#include "fss/error.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <system_error>

namespace fss::detail {

/// The shortest text that reads back to \p v ("45", "0.1", "1e+300", "inf", "nan").
inline std::string optionNumber(double v) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return r.ec == std::errc() ? std::string(buf, r.ptr) : std::to_string(v);
}

/// The checks of one options struct \p owner ("StitchOptions").
class OptionCheck {
public:
    explicit OptionCheck(const char* owner) : owner_(owner) {}

    [[noreturn]] void fail(const std::string& field, const std::string& requirement) const {
        throw InvalidOptionError(owner_, field, requirement);
    }
    /// \p v finite and in the interval from \p lo to \p hi (open ends as given).
    void inRange(const std::string& field, double v, double lo, double hi, bool loOpen, bool hiOpen) const {
        const bool ok = std::isfinite(v) && (loOpen ? v > lo : v >= lo) && (hiOpen ? v < hi : v <= hi);
        if (!ok)
            fail(field, "must be in " + std::string(loOpen ? "(" : "[") + optionNumber(lo) + ", " +
                            optionNumber(hi) + (hiOpen ? ")" : "]") + ", not " + optionNumber(v));
    }
    /// \p v finite and > 0.
    void positive(const std::string& field, double v) const {
        if (!(std::isfinite(v) && v > 0))
            fail(field, "must be a positive finite number, not " + optionNumber(v));
    }
    /// \p v finite and ≥ 0.
    void nonNegative(const std::string& field, double v) const {
        if (!(std::isfinite(v) && v >= 0))
            fail(field, "must be a finite number of at least 0, not " + optionNumber(v));
    }
    /// An integer in [lo, hi].
    void intRange(const std::string& field, long long v, long long lo, long long hi) const {
        if (v < lo || v > hi)
            fail(field, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], not " +
                            std::to_string(v));
    }
    /// An integer ≥ lo.
    void intAtLeast(const std::string& field, long long v, long long lo) const {
        if (v < lo) fail(field, "must be at least " + std::to_string(lo) + ", not " + std::to_string(v));
    }
    /// A count that a session file can hold (a JSON integer of at most 2^63 − 1).
    void count(const std::string& field, std::uint64_t v, std::uint64_t lo = 0) const {
        constexpr std::uint64_t hi = std::uint64_t(std::numeric_limits<std::int64_t>::max());
        if (v < lo || v > hi)
            fail(field, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], not " +
                            std::to_string(v));
    }

private:
    const char* owner_;
};

/// Runs \p check (the validate() of a member struct) and names its failures as fields of \p owner under
/// \p prefix: "ScanParams::quality.margin ...".
template <class Check> void nestedOptions(const char* owner, const std::string& prefix, Check&& check) {
    try {
        check();
    } catch (const InvalidOptionError& e) {
        throw InvalidOptionError(owner, prefix + e.field(), e.requirement());
    }
}

} // namespace fss::detail
