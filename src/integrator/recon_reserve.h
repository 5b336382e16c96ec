// recon_reserve.h — how long the screened Poisson reconstruction after a timed G-PT render
// will take, so that `render --time` and `converge` can stop sampling early enough for the
// whole run to fit its budget (the reconstruction is part of what the user waits for).
//
// The estimate is a measurement: a solve of a synthetic noisy problem of the render's size
// (calibrate), or the time of the last real reconstruction with the same device, driver,
// size and settings, remembered in a small cache file (ReconTimeCache) with the load its
// run's sampling felt (util/cpu_share.h), so that a render under another load scales it. The
// first timed render of a configuration pays for one calibration solve; later ones pay nothing.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "image/image.h"
#include "integrator/render_options.h"
#include "poisson/poisson_gpu.h"

namespace gdpt::vk {
class Context;
}  // namespace gdpt::vk

namespace gdpt {

// Seconds of one `options` solve of the synthetic problem with `solver` (the solver's size).
// warmUp: after an untimed solve that compiles its pipeline variants (the steady-state time,
// for benchmarks); without it the figure includes that one-off cost and the calibration
// costs one solve, not two (for a render about to solve once for real).
double calibrateReconSeconds(PoissonSolverGpu& solver, const SolveOptions& options, bool warmUp);

// Remembered times, one JSON object in `path` (key -> {"seconds", "load"}; a bare number, as
// earlier versions wrote, is seconds of unknown load). Read and write failures are ignored:
// the cache only saves a calibration solve.
class ReconTimeCache {
public:
    // $GDPT_CACHE_DIR/recon_times.json, else $XDG_CACHE_HOME/gdpt/..., else
    // $HOME/.cache/gdpt/...; empty (no cache) if none is set.
    static std::string defaultPath();

    // `scope` (e.g. the scene's path; empty: none): times differ by scene (the L1
    // reconstruction's iterations follow the image), so get() prefers the entry of the key in
    // this scope and falls back to the key's latest entry of any scope; put() writes both.
    explicit ReconTimeCache(std::string path, std::string scope = "")
        : path_(std::move(path)), scope_(std::move(scope)) {}
    [[nodiscard]] std::optional<ReservedTime> get(const std::string& key) const;
    void put(const std::string& key, ReservedTime time) const;

private:
    std::string path_;
    std::string scope_;
};

// The part of a reservation's cache key that names the configuration's device, driver and
// image size ("<device>|<driver>|<w>x<h>"); the reconstruction and the finishing time of a
// timed render extend it.
std::string reservationKey(const vk::Context& ctx, std::uint32_t width, std::uint32_t height);

// The reservation of a timed G-PT render: the cache key of its configuration (device,
// driver, size, each solve's method, alpha and tolerance) and the time to reserve (the
// cached time and its load, else the sum of one calibration solve per entry of `solves`,
// measured now: load 0).
struct ReconReservation {
    std::string key;
    ReservedTime time;
};
ReconReservation reserveReconstruction(const vk::Context& ctx, PoissonSolverGpu& solver,
                                       const std::vector<SolveOptions>& solves, const ReconTimeCache& cache);

}  // namespace gdpt
