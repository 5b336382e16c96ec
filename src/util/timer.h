// timer.h — wall-clock stopwatch (steady clock), milliseconds/seconds.
#pragma once

#include <sys/resource.h>

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

// CPU time (user + system) consumed by this process so far, all threads. On a CPU Vulkan
// device this measures the work a kernel did, independent of other load on the machine.
inline double processCpuSeconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
           1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

}  // namespace gdpt
