#pragma once
// The progress bar of fss-remesh: one line on stderr, redrawn in place, shown only when stderr is a
// terminal (so pipes, files and the tests see nothing of it).
#include "fss/progress.h"

#include <chrono>
#include <string>
#include <string_view>

namespace fss::cli {

class TerminalProgress {
public:
    /// A bar that is shown when \p wanted and stderr is a terminal.
    explicit TerminalProgress(bool wanted = true);
    ~TerminalProgress();
    TerminalProgress(const TerminalProgress&) = delete;
    TerminalProgress& operator=(const TerminalProgress&) = delete;

    /// Whether the bar is shown at all.
    bool shown() const { return shown_; }
    /// The fss::Progress that draws this bar (it never cancels); a silent Progress when the bar is not
    /// shown. The bar must outlive it.
    Progress progress();
    /// Draws "[####      ] 40% stage" (at most every 0.2 s while the percentage and the stage stay the same);
    /// nothing when the bar is not shown.
    void update(double fraction, std::string_view stage);
    /// Clears the line (the next update draws it again).
    void finish();

private:
    using Clock = std::chrono::steady_clock;
    bool shown_ = false;
    bool drawn_ = false;
    int lastPercent_ = -1;
    std::string lastStage_;
    Clock::time_point lastDraw_{};
};

} // namespace fss::cli
