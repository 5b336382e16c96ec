// cpu_share.h — the load on the machine as a render on a CPU Vulkan device (lavapipe) feels
// it: the share of the usable processors that this process's threads got over an interval
// (their CPU time ÷ (wall time × processors)), and its load factor, 1 / share.
//
// Times measured under one load carry to another by the ratio of the two load factors
// (atLoad): a timed render reserves for its reconstruction and output what an earlier run
// took, and scales it by how much less (or more) of the machine it gets now than that run got
// (integrator/sampling_loop.h). Both factors come from the same kind of work (sampling), so
// what lavapipe never uses of the machine (threads waiting on each other) cancels in the ratio.
#pragma once

#include "util/timer.h"

namespace gdpt {

// Processors this process may run on (sched_getaffinity; at least 1).
unsigned usableProcessors();

class CpuShareMeter {
public:
    CpuShareMeter() { restart(); }
    void restart();
    // The share since restart(), in [1/64, 1]; 0 (not known) before 5 ms of wall time.
    [[nodiscard]] double share() const;

private:
    Timer wall_;
    double cpu0_ = 0.0;
};

// 1 / share; 0 (not known) for a share of 0.
double loadFactor(double share);

// `seconds` measured at load factor `then`, carried to load factor `now`: scaled by now / then
// (clamped to [1/4, 8], a bound on how far one measurement is trusted), or unchanged if either
// factor is not known (0).
double atLoad(double seconds, double then, double now);

}  // namespace gdpt
