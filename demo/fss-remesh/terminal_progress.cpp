#include "terminal_progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace fss::cli {

TerminalProgress::TerminalProgress(bool wanted) : shown_(wanted && ::isatty(STDERR_FILENO) == 1) {}

TerminalProgress::~TerminalProgress() {
    finish();
}

Progress TerminalProgress::progress() {
    if (!shown_) return Progress();
    return Progress([this](double fraction, std::string_view stage) {
        update(fraction, stage);
        return true;
    });
}

void TerminalProgress::update(double fraction, std::string_view stage) {
    if (!shown_) return;
    const int percent = int(fraction * 100.0 + 1e-9);
    const auto now = Clock::now();
    if (percent == lastPercent_ && stage == lastStage_ &&
        std::chrono::duration<double>(now - lastDraw_).count() < 0.2)
        return;
    lastPercent_ = percent;
    lastStage_ = std::string(stage);
    lastDraw_ = now;
    constexpr int kWidth = 30;
    const int filled = std::clamp(int(fraction * kWidth), 0, kWidth);
    std::string text = "\r[" + std::string(std::size_t(filled), '#') +
                       std::string(std::size_t(kWidth - filled), ' ') + "] " + std::to_string(percent) +
                       "% " + lastStage_;
    if (text.size() > 100) text.resize(100);
    std::fprintf(stderr, "%s\x1b[K", text.c_str());
    std::fflush(stderr);
    drawn_ = true;
}

void TerminalProgress::finish() {
    if (drawn_) std::fprintf(stderr, "\r\x1b[K");
    std::fflush(stderr);
    drawn_ = false;
}

} // namespace fss::cli
