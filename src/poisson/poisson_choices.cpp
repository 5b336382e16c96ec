// poisson_choices.cpp — the reconstructions and solvers of poisson_gpu.h by name (the command
// line's --recon and --solver), and what each reconstruction needs.
#include "poisson/poisson_gpu.h"
#include "util/error.h"
#include "vk/context.h"

namespace gdpt {

Reconstruction parseReconstruction(const std::string& t) {
    if (t == "l2") return Reconstruction::L2;
    if (t == "wl2") return Reconstruction::WeightedL2;
    if (t == "l1") return Reconstruction::L1;
    if (t == "wl1") return Reconstruction::WeightedL1;
    throw UsageError("unknown reconstruction '" + t + "' (expected l1, l2, wl2 or wl1)");
}

bool isIrls(Reconstruction r) {
    return r == Reconstruction::L1 || r == Reconstruction::WeightedL1;
}

bool needsVariance(Reconstruction r) {
    return r == Reconstruction::WeightedL2 || r == Reconstruction::WeightedL1;
}

bool debiases(Reconstruction r, int debiasCells) {
    return debiasCells > 0 && r != Reconstruction::L2;
}

GpuSolver parseGpuSolver(const std::string& t) {
    if (t == "mg-pcg") return GpuSolver::MgPcg;
    if (t == "cg") return GpuSolver::Cg;
    if (t == "jacobi") return GpuSolver::Jacobi;
    if (t == "mg") return GpuSolver::Mg;
    if (t == "host-pcg") return GpuSolver::HostPcg;
    throw UsageError("unknown solver '" + t + "' (expected mg-pcg, cg, jacobi, mg or host-pcg)");
}

const char* toString(Reconstruction r) {
    switch (r) {
        case Reconstruction::L2:
            return "l2";
        case Reconstruction::WeightedL2:
            return "wl2";
        case Reconstruction::L1:
            return "l1";
        case Reconstruction::WeightedL1:
            return "wl1";
    }
    return "?";
}

std::optional<GpuSolver> parseSolverChoice(const std::string& text) {
    if (text == "auto") return std::nullopt;
    return parseGpuSolver(text);
}

GpuSolver resolveSolver(std::optional<GpuSolver> choice, const vk::Context& ctx) {
    if (choice) return *choice;
    return ctx.info().isCpu ? GpuSolver::HostPcg : GpuSolver::MgPcg;
}

const char* toString(GpuSolver s) {
    switch (s) {
        case GpuSolver::MgPcg:
            return "mg-pcg";
        case GpuSolver::Cg:
            return "cg";
        case GpuSolver::Jacobi:
            return "jacobi";
        case GpuSolver::Mg:
            return "mg";
        case GpuSolver::HostPcg:
            return "host-pcg";
    }
    return "?";
}

}  // namespace gdpt
