// The processor share and load factor of util/cpu_share.h: the arithmetic by hand, and the
// meter against threads whose use of the processors is known (one asleep, one spinning).
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "util/cpu_share.h"

namespace gdpt {
namespace {

TEST(CpuShare, LoadFactorIsTheInverseShare) {
    EXPECT_DOUBLE_EQ(loadFactor(0.5), 2.0);
    EXPECT_DOUBLE_EQ(loadFactor(1.0), 1.0);
    EXPECT_DOUBLE_EQ(loadFactor(0.0), 0.0) << "a share not known gives a factor not known";
}

// Seconds measured at one load carry to another by the ratio of the factors, within the
// trusted range, and stay as they are when either factor is not known.
TEST(CpuShare, AtLoadScalesByTheRatioOfTheFactors) {
    EXPECT_DOUBLE_EQ(atLoad(1.0, 2.0, 4.0), 2.0);
    EXPECT_DOUBLE_EQ(atLoad(3.0, 4.0, 2.0), 1.5);
    EXPECT_DOUBLE_EQ(atLoad(3.0, 0.0, 2.0), 3.0);
    EXPECT_DOUBLE_EQ(atLoad(3.0, 2.0, 0.0), 3.0);
    EXPECT_DOUBLE_EQ(atLoad(1.0, 1.0, 100.0), 8.0) << "at most 8x";
    EXPECT_DOUBLE_EQ(atLoad(1.0, 100.0, 1.0), 0.25) << "at least a quarter";
}

TEST(CpuShare, UsableProcessorsAreThoseOfTheMachineAtMost) {
    EXPECT_GE(usableProcessors(), 1u);
    const unsigned hardware = std::thread::hardware_concurrency();
    if (hardware > 0) {
        EXPECT_LE(usableProcessors(), hardware);
    }
}

// A process that sleeps uses (almost) none of the machine: the meter must count CPU time, not
// wall time (which would give a share of 1).
TEST(CpuShare, SleepingIsNoShare) {
    CpuShareMeter meter;
    std::this_thread::sleep_for(std::chrono::milliseconds(60));
    EXPECT_LE(meter.share(), 0.05);
    EXPECT_GT(meter.share(), 0.0) << "measured: at least the floor";
}

// One thread spinning uses at most one processor of the usable ones: the meter must divide by
// them (a share of 1 on a machine of two would be one processor counted as the machine).
// Under other load the thread gets less, so only the upper bound is tested (plus 3 % for the
// clocks' granularity).
TEST(CpuShare, OneSpinningThreadIsAtMostOneProcessor) {
    CpuShareMeter meter;
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(150);
    volatile unsigned long spins = 0;
    while (std::chrono::steady_clock::now() < end) spins = spins + 1;
    EXPECT_LE(meter.share(), 1.0 / usableProcessors() + 0.03);
    EXPECT_GT(meter.share(), 1.0 / 64.0);
}

TEST(CpuShare, NotKnownBeforeFiveMilliseconds) {
    const CpuShareMeter meter;
    EXPECT_EQ(meter.share(), 0.0);
}

}  // namespace
}  // namespace gdpt
