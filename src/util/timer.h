// timer.h — wall-clock stopwatch (steady clock), milliseconds/seconds.
#pragma once

#include <chrono>

namespace gdpt {

class Timer {
public:
    Timer() : start_(std::chrono::steady_clock::now()) {}
    void restart() { start_ = std::chrono::steady_clock::now(); }
    [[nodiscard]] double seconds() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    }
    [[nodiscard]] double ms() const { return seconds() * 1e3; }

private:
    std::chrono::steady_clock::time_point start_;
};

}  // namespace gdpt
