// progress.h — progress on stderr, driven by completed GPU work (the caller reports after
// each fence). On a terminal one line is redrawn in place; otherwise (CI logs) a plain line
// is printed at most every `plainIntervalSeconds`. Quiet mode prints nothing.
#pragma once

#include <string>

#include "util/timer.h"

namespace gdpt {

class Progress {
public:
    Progress(std::string label, double total, bool quiet, double plainIntervalSeconds = 5.0);
    // Reports that `done` units out of total are complete; `extra` is appended (e.g. rate).
    void update(double done, const std::string& extra = "");
    // Ends the line (on a TTY) and prints the final state.
    void finish(const std::string& extra = "");

private:
    void print(double done, const std::string& extra, bool final);

    std::string label_;
    double total_;
    bool quiet_;
    bool tty_;
    double interval_;
    double lastPrint_ = -1e9;
    double lastDone_ = 0.0;
    bool finished_ = false;
    Timer timer_;
};

}  // namespace gdpt
