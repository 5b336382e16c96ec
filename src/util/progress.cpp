#include "util/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace gdpt {

Progress::Progress(std::string label, double total, bool quiet, double plainIntervalSeconds)
    : label_(std::move(label)),
      total_(total),
      quiet_(quiet),
      tty_(isatty(STDERR_FILENO) != 0),
      interval_(plainIntervalSeconds) {}

void Progress::update(double done, const std::string& extra) {
    lastDone_ = done;
    if (quiet_) return;
    const double now = timer_.seconds();
    const double minGap = tty_ ? 0.1 : interval_;
    if (now - lastPrint_ < minGap) return;
    lastPrint_ = now;
    print(done, extra, false);
}

void Progress::finish(const std::string& extra) {
    if (quiet_ || finished_) return;
    finished_ = true;
    print(lastDone_, extra, true);
}

void Progress::print(double done, const std::string& extra, bool final) {
    const double frac = total_ > 0.0 ? std::clamp(done / total_, 0.0, 1.0) : 1.0;
    const double elapsed = timer_.seconds();
    const double eta = frac > 0.0 ? elapsed * (1.0 - frac) / frac : 0.0;
    char line[256];
    std::snprintf(
        line, sizeof line, "%s: %5.1f%%  %6.1fs elapsed%s%s", label_.c_str(), frac * 100.0, elapsed,
        final ? "" : (std::string(", ~") + std::to_string(static_cast<int>(eta + 0.5)) + "s left").c_str(),
        extra.empty() ? "" : ("  " + extra).c_str());
    if (tty_)
        std::fprintf(stderr, "\r\033[K%s%s", line, final ? "\n" : "");
    else
        std::fprintf(stderr, "%s\n", line);
    std::fflush(stderr);
}

}  // namespace gdpt
