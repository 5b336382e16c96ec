#include "util/cpu_share.h"

#include <sched.h>

#include <algorithm>

namespace gdpt {

unsigned usableProcessors() {
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof set, &set) != 0) return 1;
    return static_cast<unsigned>(std::max(1, CPU_COUNT(&set)));
}

void CpuShareMeter::restart() {
    wall_.restart();
    cpu0_ = processCpuSeconds();
}

double CpuShareMeter::share() const {
    const double wall = wall_.seconds();
    if (wall < 5e-3) return 0.0;
    const double share = (processCpuSeconds() - cpu0_) / (wall * usableProcessors());
    return std::clamp(share, 1.0 / 64.0, 1.0);
}

double loadFactor(double share) {
    return share > 0.0 ? 1.0 / share : 0.0;
}

double atLoad(double seconds, double then, double now) {
    if (!(then > 0.0) || !(now > 0.0)) return seconds;
    return seconds * std::clamp(now / then, 0.25, 8.0);
}

}  // namespace gdpt
