// recon_reserve.cpp — reconstruction-time estimates for timed G-PT renders (recon_reserve.h).
#include "integrator/recon_reserve.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "image/atomic_write.h"
#include "util/cache_dir.h"
#include "util/timer.h"
#include "vk/context.h"

namespace gdpt {

double calibrateReconSeconds(PoissonSolverGpu& solver, const SolveOptions& options, bool warmUp) {
    const SyntheticReconProblem p = syntheticReconProblem(solver.width(), solver.height());
    PoissonInput in;
    in.primal = &p.primal;
    in.dx = &p.dx;
    in.dy = &p.dy;
    in.varPrimal = in.varDx = in.varDy = &p.variance;
    Image out;
    if (warmUp) (void)solver.solve(in, options, out);
    Timer t;
    (void)solver.solve(in, options, out);
    return t.seconds();
}

std::string ReconTimeCache::defaultPath() {
    const std::filesystem::path dir = cacheDirectory();
    return dir.empty() ? std::string() : (dir / "recon_times.json").string();
}

namespace {

nlohmann::json readCache(const std::string& path) {
    if (path.empty()) return nlohmann::json::object();
    std::ifstream in(path);
    nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    return j.is_object() ? j : nlohmann::json::object();
}

std::optional<ReservedTime> entry(const nlohmann::json& j, const std::string& key) {
    const auto it = j.find(key);
    if (it == j.end()) return std::nullopt;
    ReservedTime t;
    if (it->is_number()) {
        t.seconds = it->get<double>();
    } else if (it->is_object() && it->contains("seconds") && (*it)["seconds"].is_number()) {
        t.seconds = (*it)["seconds"].get<double>();
        if (it->contains("load") && (*it)["load"].is_number())
            t.load = std::max(0.0, (*it)["load"].get<double>());
    } else {
        return std::nullopt;
    }
    if (!(t.seconds >= 0.0) || !std::isfinite(t.seconds) || !std::isfinite(t.load)) return std::nullopt;
    return t;
}

}  // namespace

std::optional<ReservedTime> ReconTimeCache::get(const std::string& key) const {
    const nlohmann::json j = readCache(path_);
    if (!scope_.empty())
        if (std::optional<ReservedTime> scoped = entry(j, key + "|" + scope_)) return scoped;
    return entry(j, key);
}

void ReconTimeCache::put(const std::string& key, ReservedTime time) const {
    if (path_.empty()) return;
    try {
        nlohmann::json j = readCache(path_);
        const nlohmann::json value = {{"seconds", time.seconds}, {"load", time.load}};
        j[key] = value;
        if (!scope_.empty()) j[key + "|" + scope_] = value;
        std::filesystem::create_directories(std::filesystem::path(path_).parent_path());
        writeTextFileAtomically(path_, j.dump(1) + "\n");
    } catch (const std::exception&) {
        // A cache that cannot be written only costs the next run a calibration solve.
    }
}

std::string reservationKey(const vk::Context& ctx, std::uint32_t width, std::uint32_t height) {
    return ctx.info().name + "|" + ctx.info().driverInfo + "|" + std::to_string(width) + "x" +
           std::to_string(height);
}

ReconReservation reserveReconstruction(const vk::Context& ctx, PoissonSolverGpu& solver,
                                       const std::vector<SolveOptions>& solves, const ReconTimeCache& cache) {
    ReconReservation r;
    r.key = reservationKey(ctx, solver.width(), solver.height());
    for (const SolveOptions& so : solves)
        r.key += std::string("|") + toString(so.method) + " alpha " + std::to_string(so.alpha) + " tol " +
                 std::to_string(so.tolerance) + " " + toString(so.solver);
    if (const std::optional<ReservedTime> known = cache.get(r.key)) {
        r.time = *known;
    } else {
        for (const SolveOptions& so : solves)
            r.time.seconds += calibrateReconSeconds(solver, so, /*warmUp=*/false);
    }
    return r;
}

}  // namespace gdpt
