// poisson_gpu_engine.h — the GPU building blocks of the screened Poisson solver: the
// poisson_*.comp pipelines (PoissonKernels, size-independent, created once per context) and
// the buffers + multigrid level layout of one image size (PoissonGpuEngine), with one
// record*() call per kernel. PoissonSolverGpu (poisson_gpu.h) strings these into solvers;
// tests drive the single operators to compare them with the CPU reference (poisson_cpu.h).
//
// Every record*() call dispatches one kernel and ends with a compute barrier, so calls can
// be chained freely in one command buffer. Field layout: shaders/shared/poisson_shared.h.
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "poisson_shared.h"
#include "vk/buffer.h"
#include "vk/kernel.h"

namespace gdpt::vk {
class Context;
class GpuTimer;
}  // namespace gdpt::vk

namespace gdpt {

// The poisson_*.comp kernels.
enum class PoissonOp {
    Setup,
    Coarsen,
    Residual,
    Smooth,
    Restrict,
    Prolong,
    Coarsest,
    CgDirection,
    CgUpdate,
    Scalars,
    IrlsWeights,
    Count
};

// How the kernels reach the field buffers (poisson_shared.h): descriptors (faster on
// lavapipe) unless a field exceeds maxStorageBufferRange, then device addresses.
enum class PoissonAddressing { Descriptors = 0, DeviceAddress = 1 };

// The poisson_* pipelines for one workgroup shape (2D kernels; reductions need x·y to be a
// power of two ≤ 256). Each kernel has one pipeline variant per set of kPoissonFlag* bits
// (the specialisation constant kSpecPoissonFlags, so that untaken paths are compiled out),
// created on first use and kept. Pipeline creation dominates set-up on lavapipe, so callers
// that solve many sizes keep one PoissonKernels and pass it to each engine.
class PoissonKernels {
public:
    using Buffers = std::array<const vk::Buffer*, gpu::kPoissonBindCount>;

    PoissonKernels(const vk::Context& ctx, std::uint32_t groupX = 16, std::uint32_t groupY = 16);
    ~PoissonKernels();
    PoissonKernels(const PoissonKernels&) = delete;
    PoissonKernels& operator=(const PoissonKernels&) = delete;

    [[nodiscard]] std::uint32_t groupX() const { return groupX_; }
    [[nodiscard]] std::uint32_t groupY() const { return groupY_; }

    // The variant of `op` for `flags` and `addressing`, bound to the buffers of the last
    // bindAll() for that addressing.
    const vk::Kernel& get(PoissonOp op, std::uint32_t flags,
                          PoissonAddressing addressing = PoissonAddressing::Descriptors);
    // Points every variant of `addressing` (existing and future) at `buffers`, indexed by
    // kPoissonBind* (each variant binds only the bindings its shader declares).
    void bindAll(const Buffers& buffers, PoissonAddressing addressing);
    // Number of pipelines created so far (for tests and set-up cost reports).
    [[nodiscard]] std::size_t variantCount() const;

private:
    const vk::Context& ctx_;
    std::uint32_t groupX_, groupY_;
    static constexpr std::size_t kModes = 2;  // PoissonAddressing values
    std::array<std::array<vk::KernelDesc, static_cast<std::size_t>(PoissonOp::Count)>, kModes> descs_;
    std::array<std::array<std::map<std::uint32_t, std::unique_ptr<vk::Kernel>>,
                          static_cast<std::size_t>(PoissonOp::Count)>,
               kModes>
        variants_;
    std::array<Buffers, kModes> bound_{};
};

struct PoissonLevel {
    int width = 0;
    int height = 0;
    std::uint32_t offset = 0;  // float offset of this level's 3 planes in X, B, R and Coef
    [[nodiscard]] std::uint32_t pixels() const {
        return static_cast<std::uint32_t>(width) * static_cast<std::uint32_t>(height);
    }
};

// V-cycle parameters (Briggs et al., "A Multigrid Tutorial", ch. 3).
struct VcycleParams {
    bool jacobi = false;  // smoother: damped Jacobi (else red-black Gauss-Seidel)
    int preSmooth = 1;    // sweeps before the coarse-grid correction (Jacobi: rounded to even)
    int postSmooth = 1;   // sweeps after it (≥ 1)
    float omega = 0.8f;   // Jacobi damping
};

class PoissonGpuEngine {
public:
    // Allocates every buffer for a width x height RGB problem; uses `kernels` if given (it
    // must outlive the engine), else creates its own. Throws gdpt::Error naming the device
    // limit if a field exceeds maxMemoryAllocationSize.
    // `addressing` forces one way of reaching the fields (tests); by default descriptors
    // when every field fits maxStorageBufferRange, else device addresses.
    PoissonGpuEngine(const vk::Context& ctx, int width, int height, PoissonKernels* kernels = nullptr,
                     std::optional<PoissonAddressing> addressing = std::nullopt);

    [[nodiscard]] int width() const { return levels_[0].width; }
    [[nodiscard]] int height() const { return levels_[0].height; }
    [[nodiscard]] std::uint32_t pixels() const { return levels_[0].pixels(); }
    [[nodiscard]] const std::vector<PoissonLevel>& levels() const { return levels_; }
    // Partial sums per slot and channel: fine-level workgroups × subgroups per workgroup.
    [[nodiscard]] std::uint32_t groups() const;
    [[nodiscard]] const vk::Context& context() const { return ctx_; }

    // Points every kernel's descriptors at this engine's buffers (call before recording
    // when several engines share one PoissonKernels).
    void bind();
    [[nodiscard]] PoissonAddressing addressing() const { return addressing_; }
    // The pipelines this engine dispatches (its own, or the ones it was given).
    [[nodiscard]] PoissonKernels& kernels() { return *kernels_; }

    // The fields (kPoissonField*: bound as descriptors, or read through the device addresses
    // listed in fieldTable) and the descriptor-bound scalars.
    vk::Buffer coef, x, b, r, p, ap, sol, rhs, primal, dx, dy, weights, irls, partials;
    vk::Buffer fieldTable, scalars, gate;  // fieldTable: device-address build only

    // Early exit inside a recorded batch. While gated, every dispatch reads its group counts
    // from `gate`, which poisson_scalars zeroes once all channels have converged (Beta and
    // Record modes), so iterations recorded past convergence cost only their dispatch
    // overhead. armGate() restores the counts; call it while the device is idle, before
    // submitting gated work.
    void setGated(bool gated) { gated_ = gated; }
    void armGate();

    // ---- one kernel each (see the kernel files for the maths) ----
    void recordSetup(VkCommandBuffer cmd, float alpha2, bool irlsWeights, vk::GpuTimer* timer);
    void recordCoarsenAll(VkCommandBuffer cmd, vk::GpuTimer* timer);
    void recordResidual(VkCommandBuffer cmd, int level, std::uint32_t flags, vk::GpuTimer* timer);
    void recordSmooth(VkCommandBuffer cmd, int level, std::uint32_t flags, std::uint32_t colour, float omega,
                      vk::GpuTimer* timer);
    void recordRestrict(VkCommandBuffer cmd, int level, std::uint32_t flags, vk::GpuTimer* timer);
    void recordProlong(VkCommandBuffer cmd, int level, vk::GpuTimer* timer);
    void recordCoarsest(VkCommandBuffer cmd, bool zeroGuess, vk::GpuTimer* timer);
    void recordCgDirection(VkCommandBuffer cmd, std::uint32_t flags, std::uint32_t pOld, std::uint32_t pNew,
                           vk::GpuTimer* timer);
    void recordCgUpdate(VkCommandBuffer cmd, std::uint32_t pNew, vk::GpuTimer* timer);
    void recordScalars(VkCommandBuffer cmd, std::uint32_t mode, std::uint32_t flags, std::uint32_t iteration,
                       float tolerance, float value, vk::GpuTimer* timer);
    void recordIrlsWeights(VkCommandBuffer cmd, float alpha2, float reg, vk::GpuTimer* timer);

    // One V-cycle on level 0 for X₀ ≈ A⁻¹ B₀ (zeroGuess: X₀ starts at 0). dotOut: the last
    // post-sweep writes partial sums of B₀·X₀ (r·z for PCG) to slot RZ.
    void recordVcycle(VkCommandBuffer cmd, const VcycleParams& params, bool zeroGuess, bool dotOut,
                      vk::GpuTimer* timer);
    // Copies `floats` floats between buffers (with a barrier).
    static void recordCopy(VkCommandBuffer cmd, const vk::Buffer& from, const vk::Buffer& to,
                           std::uint64_t floats);

private:
    void vcycleLevel(VkCommandBuffer cmd, int level, const VcycleParams& params, bool zeroGuess, bool dotOut,
                     vk::GpuTimer* timer);
    // The field buffers in kPoissonField* order.
    [[nodiscard]] std::array<const vk::Buffer*, gpu::kPoissonFieldCount> fieldBuffers() const;
    const vk::Kernel& kernel(PoissonOp op, std::uint32_t flags) const {
        return kernels_->get(op, flags, addressing_);
    }
    void dispatch(VkCommandBuffer cmd, const vk::Kernel& kernel, int itemsX, int itemsY, const void* push,
                  vk::GpuTimer* timer);
    void dispatchGroups(VkCommandBuffer cmd, const vk::Kernel& kernel, std::uint32_t gx, std::uint32_t gy,
                        const void* push, vk::GpuTimer* timer);
    // Workgroups covering itemsX × itemsY invocations with the kernels' workgroup size.
    [[nodiscard]] std::pair<std::uint32_t, std::uint32_t> gridGroups(int itemsX, int itemsY) const;
    void addGateShape(std::pair<std::uint32_t, std::uint32_t> groups);

    const vk::Context& ctx_;
    std::unique_ptr<PoissonKernels> ownKernels_;
    PoissonKernels* kernels_ = nullptr;
    std::vector<PoissonLevel> levels_;
    PoissonAddressing addressing_ = PoissonAddressing::Descriptors;
    bool gated_ = false;
    std::vector<std::uint32_t> gateArgs_;                                         // 3 per shape
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> gateEntry_;  // shape -> entry
};

}  // namespace gdpt
