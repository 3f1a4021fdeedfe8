#pragma once
/// \file progress.h
/// Progress reporting and cancellation for long core operations (MeshLab-filter style: the core never
/// touches a GUI; the caller turns the callback into a progress bar or a cancel button).

#include "fss/error.h"

#include <functional>
#include <string_view>

namespace fss {

/// Receives (fraction done in [0,1], stage name). Returning false requests cancellation.
using ProgressCallback = std::function<bool(double fraction, std::string_view stage)>;

/// Light wrapper passed by reference into long operations. A default-constructed Progress ignores
/// reports and never cancels.
class Progress {
public:
    Progress() = default;
    explicit Progress(ProgressCallback callback) : callback_(std::move(callback)) {}

    /// Reports progress; throws CancelledError when the callback asks to stop.
    void report(double fraction, std::string_view stage) const {
        if (callback_ && !callback_(fraction, stage)) throw CancelledError();
    }

private:
    ProgressCallback callback_;
};

} // namespace fss
