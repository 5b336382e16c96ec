// poisson_gpu_engine.cpp — pipelines, buffers, level layout and kernel recording of the GPU
// Poisson solver (see poisson_gpu_engine.h).
#include "poisson/poisson_gpu_engine.h"

#include <algorithm>
#include <string>

#include "poisson_cg_direction.spv.h"
#include "poisson_cg_direction_addr.spv.h"
#include "poisson_cg_update.spv.h"
#include "poisson_cg_update_addr.spv.h"
#include "poisson_coarsen.spv.h"
#include "poisson_coarsen_addr.spv.h"
#include "poisson_coarsest.spv.h"
#include "poisson_coarsest_addr.spv.h"
#include "poisson_irls_weights.spv.h"
#include "poisson_irls_weights_addr.spv.h"
#include "poisson_prolong.spv.h"
#include "poisson_prolong_addr.spv.h"
#include "poisson_residual.spv.h"
#include "poisson_residual_addr.spv.h"
#include "poisson_restrict.spv.h"
#include "poisson_restrict_addr.spv.h"
#include "poisson_scalars.spv.h"
#include "poisson_scalars_addr.spv.h"
#include "poisson_setup.spv.h"
#include "poisson_setup_addr.spv.h"
#include "poisson_shared.h"
#include "poisson_smooth.spv.h"
#include "poisson_smooth_addr.spv.h"
#include "util/error.h"
#include "vk/commands.h"
#include "vk/context.h"

namespace gdpt {
namespace {

using gpu::PoissonPush;

vk::KernelDesc describe(vk::KernelDesc d, std::uint32_t gx, std::uint32_t gy, bool grid, bool addressed) {
    d.bindings = {gpu::kPoissonBindScalars, gpu::kPoissonBindGate};
    if (addressed)
        d.bindings.push_back(gpu::kPoissonBindFields);
    else
        for (std::uint32_t f = 0; f < gpu::kPoissonFieldCount; ++f)
            d.bindings.push_back(gpu::kPoissonBindFieldBase + f);
    d.pushConstantBytes = sizeof(PoissonPush);
    if (grid) {
        d.specConstants = {{gpu::kSpecWorkgroupX, gx}, {gpu::kSpecWorkgroupY, gy}};
        d.localSizeX = gx;
        d.localSizeY = gy;
    }
    return d;
}

// groups: the fine-level workgroup count, the stride of the partial-sum slots.
PoissonPush levelPush(const PoissonLevel& l, std::uint32_t groups) {
    PoissonPush p{};
    p.groups = groups;
    p.width = static_cast<std::uint32_t>(l.width);
    p.height = static_cast<std::uint32_t>(l.height);
    p.xOff = p.bOff = p.rOff = p.cOff = l.offset;
    return p;
}

void withCoarse(PoissonPush& p, const PoissonLevel& c) {
    p.coarseWidth = static_cast<std::uint32_t>(c.width);
    p.coarseHeight = static_cast<std::uint32_t>(c.height);
    p.coarseXOff = p.coarseBOff = p.coarseCOff = c.offset;
}

}  // namespace

PoissonKernels::PoissonKernels(const vk::Context& ctx, std::uint32_t gx, std::uint32_t gy)
    : ctx_(ctx), groupX_(gx), groupY_(gy) {
    const std::uint32_t size = gx * gy;
    if (size == 0 || size > gpu::kPoissonMaxGroupSize || (size & (size - 1)) != 0)
        throw Error("Poisson solver: workgroup " + std::to_string(gx) + "x" + std::to_string(gy) +
                    " must have a power-of-two size <= 256");
    auto set = [&](PoissonOp op, vk::KernelDesc d, vk::KernelDesc addressed, bool grid) {
        descs_[0][static_cast<std::size_t>(op)] = describe(std::move(d), gx, gy, grid, false);
        descs_[1][static_cast<std::size_t>(op)] = describe(std::move(addressed), gx, gy, grid, true);
    };
#define GDPT_POISSON_KERNEL(op, name, grid)                            \
    set(PoissonOp::op, vk::kernelDesc(#name, GDPT_KERNEL_SPIRV(name)), \
        vk::kernelDesc(#name, GDPT_KERNEL_SPIRV(name##_addr)), grid)
    GDPT_POISSON_KERNEL(Setup, poisson_setup, true);
    GDPT_POISSON_KERNEL(Coarsen, poisson_coarsen, true);
    GDPT_POISSON_KERNEL(Residual, poisson_residual, true);
    GDPT_POISSON_KERNEL(Smooth, poisson_smooth, true);
    GDPT_POISSON_KERNEL(Restrict, poisson_restrict, true);
    GDPT_POISSON_KERNEL(Prolong, poisson_prolong, true);
    GDPT_POISSON_KERNEL(Coarsest, poisson_coarsest, false);
    GDPT_POISSON_KERNEL(CgDirection, poisson_cg_direction, true);
    GDPT_POISSON_KERNEL(CgUpdate, poisson_cg_update, true);
    GDPT_POISSON_KERNEL(Scalars, poisson_scalars, false);
    GDPT_POISSON_KERNEL(IrlsWeights, poisson_irls_weights, true);
#undef GDPT_POISSON_KERNEL
}

PoissonKernels::~PoissonKernels() = default;

const vk::Kernel& PoissonKernels::get(PoissonOp op, std::uint32_t flags, PoissonAddressing addressing) {
    const auto mode = static_cast<std::size_t>(addressing);
    auto& variants = variants_[mode][static_cast<std::size_t>(op)];
    auto it = variants.find(flags);
    if (it == variants.end()) {
        vk::KernelDesc d = descs_[mode][static_cast<std::size_t>(op)];
        d.specConstants.emplace_back(gpu::kSpecPoissonFlags, flags);
        auto kernel = std::make_unique<vk::Kernel>(ctx_, d);
        for (std::uint32_t b : d.bindings)
            if (bound_[mode][b]) kernel->bind(b, *bound_[mode][b]);
        it = variants.emplace(flags, std::move(kernel)).first;
    }
    return *it->second;
}

void PoissonKernels::bindAll(const Buffers& buffers, PoissonAddressing addressing) {
    const auto mode = static_cast<std::size_t>(addressing);
    bound_[mode] = buffers;
    for (std::size_t op = 0; op < variants_[mode].size(); ++op)
        for (auto& [flags, kernel] : variants_[mode][op])
            for (std::uint32_t b : descs_[mode][op].bindings)
                if (buffers[b]) kernel->bind(b, *buffers[b]);
}

std::size_t PoissonKernels::variantCount() const {
    std::size_t n = 0;
    for (const auto& mode : variants_)
        for (const auto& variants : mode) n += variants.size();
    return n;
}

PoissonGpuEngine::PoissonGpuEngine(const vk::Context& ctx, int width, int height, PoissonKernels* kernels,
                                   std::optional<PoissonAddressing> addressing)
    : ctx_(ctx) {
    if (width <= 0 || height <= 0)
        throw Error("Poisson solver: invalid size " + std::to_string(width) + "x" + std::to_string(height));
    if (kernels) {
        kernels_ = kernels;
    } else {
        ownKernels_ = std::make_unique<PoissonKernels>(ctx);
        kernels_ = ownKernels_.get();
    }
    // Levels: halve (rounding up) until the coarsest fits the one-workgroup solver.
    std::uint64_t offset = 0;
    int w = width, h = height;
    for (;;) {
        levels_.push_back({w, h, static_cast<std::uint32_t>(offset)});
        offset += 3ull * static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h);
        if (w <= static_cast<int>(gpu::kPoissonCoarsestMax) &&
            h <= static_cast<int>(gpu::kPoissonCoarsestMax))
            break;
        w = (w + 1) / 2;
        h = (h + 1) / 2;
    }
    const std::uint64_t fine = 3ull * pixels() * sizeof(float);
    const std::uint64_t all = offset * sizeof(float);
    const std::string what = "Poisson solve of " + std::to_string(width) + "x" + std::to_string(height);
    // Float offsets are 32-bit in the kernels. Fields beyond maxStorageBufferRange are read
    // through device addresses, whose limit is the allocation size.
    if (offset > 0xffffffffull)
        throw Error(what + ": the multigrid levels exceed 2^32 floats per field; use a smaller image");
    const std::uint64_t partialBytes = std::uint64_t{gpu::kPoissonSlotCount} * 3 * groups() * sizeof(float);
    const std::uint64_t largest = std::max({2 * fine, all, partialBytes});
    ctx.checkAllocationSize(largest, what + " (largest field)");
    // llvmpipe ends any loop nest after 65535 iterations (poisson_scalars.comp): the worst
    // scalar dispatch (Init) runs 9 sums of G / (256·unroll) iterations plus an 8-step tree.
    // The allocation limit keeps G far below this on lavapipe; devices without the cap pass.
    const std::uint64_t sumIterations =
        9ull * ((groups() + 256ull * gpu::kPoissonSumUnroll - 1) / (256ull * gpu::kPoissonSumUnroll) + 8);
    if (ctx.info().isCpu && sumIterations > 65535)
        throw Error(
            what +
            ": its reductions would exceed llvmpipe's 65535-iteration loop limit; use a smaller image");
    addressing_ =
        addressing.value_or(largest <= ctx.info().maxStorageBufferRange ? PoissonAddressing::Descriptors
                                                                        : PoissonAddressing::DeviceAddress);
    coef = vk::Buffer(ctx, all, "poissonCoef");
    x = vk::Buffer(ctx, all, "poissonX");
    b = vk::Buffer(ctx, all, "poissonB");
    r = vk::Buffer(ctx, all, "poissonR");
    p = vk::Buffer(ctx, 2 * fine, "poissonP");
    ap = vk::Buffer(ctx, fine, "poissonAp");
    sol = vk::Buffer(ctx, fine, "poissonSol");
    rhs = vk::Buffer(ctx, fine, "poissonRhs");
    primal = vk::Buffer(ctx, fine, "poissonPrimal");
    dx = vk::Buffer(ctx, fine, "poissonDx");
    dy = vk::Buffer(ctx, fine, "poissonDy");
    weights = vk::Buffer(ctx, fine, "poissonWeights");
    irls = vk::Buffer(ctx, fine, "poissonIrls");
    partials = vk::Buffer(ctx, partialBytes, "poissonPartials");
    scalars = vk::Buffer(ctx, sizeof(gpu::PoissonScalars) + 3ull * gpu::kPoissonMaxHistory * sizeof(float),
                         "poissonScalars");
    if (addressing_ == PoissonAddressing::DeviceAddress) {
        std::array<std::uint64_t, gpu::kPoissonFieldCount> addresses{};
        const auto fields = fieldBuffers();
        for (std::uint32_t f = 0; f < gpu::kPoissonFieldCount; ++f) addresses[f] = fields[f]->deviceAddress();
        fieldTable = vk::Buffer(ctx, sizeof(addresses), "poissonFields");
        fieldTable.upload(addresses.data(), sizeof(addresses));
    }
    // The gate: indirect group counts of every dispatch shape of an iteration (each level's
    // grid, its half-width smoothing grid, one workgroup), zeroed by poisson_scalars once
    // every channel has converged so that the rest of a recorded batch costs nothing.
    for (const PoissonLevel& l : levels_) {
        addGateShape(gridGroups(l.width, l.height));
        addGateShape(gridGroups((l.width + 1) / 2, l.height));
    }
    addGateShape({1u, 1u});
    gate = vk::Buffer(ctx, gateArgs_.size() * sizeof(std::uint32_t), "poissonGate");
    armGate();
    // Defined contents everywhere (no stale NaN can leak through a 0 coefficient).
    for (vk::Buffer* buf : {&coef, &x, &b, &r, &p, &ap, &sol, &rhs, &irls, &scalars, &partials}) buf->zero();
    bind();
}

std::pair<std::uint32_t, std::uint32_t> PoissonGpuEngine::gridGroups(int itemsX, int itemsY) const {
    return {(static_cast<std::uint32_t>(itemsX) + kernels_->groupX() - 1) / kernels_->groupX(),
            (static_cast<std::uint32_t>(itemsY) + kernels_->groupY() - 1) / kernels_->groupY()};
}

std::uint32_t PoissonGpuEngine::groups() const {
    const auto [gx, gy] = gridGroups(width(), height());
    // One partial sum per subgroup (poisson_common.glsl writePartials).
    const std::uint32_t sub = std::max(1u, ctx_.info().subgroupSize);
    const std::uint32_t perGroup = (kernels_->groupX() * kernels_->groupY() + sub - 1) / sub;
    return gx * gy * perGroup;
}

std::array<const vk::Buffer*, gpu::kPoissonFieldCount> PoissonGpuEngine::fieldBuffers() const {
    return {&coef, &x, &b, &r, &p, &ap, &sol, &rhs, &primal, &dx, &dy, &weights, &irls, &partials};
}

void PoissonGpuEngine::bind() {
    PoissonKernels::Buffers buffers{};
    buffers[gpu::kPoissonBindScalars] = &scalars;
    buffers[gpu::kPoissonBindGate] = &gate;
    if (addressing_ == PoissonAddressing::DeviceAddress) {
        buffers[gpu::kPoissonBindFields] = &fieldTable;
    } else {
        const auto fields = fieldBuffers();
        for (std::uint32_t f = 0; f < gpu::kPoissonFieldCount; ++f)
            buffers[gpu::kPoissonBindFieldBase + f] = fields[f];
    }
    kernels_->bindAll(buffers, addressing_);
}

void PoissonGpuEngine::dispatch(VkCommandBuffer cmd, const vk::Kernel& kernel, int itemsX, int itemsY,
                                const void* push, vk::GpuTimer* timer) {
    const auto [gx, gy] = gridGroups(itemsX, itemsY);
    dispatchGroups(cmd, kernel, gx, gy, push, timer);
}

void PoissonGpuEngine::dispatchGroups(VkCommandBuffer cmd, const vk::Kernel& kernel, std::uint32_t gx,
                                      std::uint32_t gy, const void* push, vk::GpuTimer* timer) {
    if (gated_) {
        const auto it = gateEntry_.find({gx, gy});
        GDPT_CHECK(it != gateEntry_.end());
        kernel.dispatchIndirect(cmd, gate, std::uint64_t{it->second} * 3 * sizeof(std::uint32_t), push,
                                timer);
    } else {
        kernel.dispatch(cmd, gx, gy, 1, push, timer);
    }
    vk::computeBarrier(cmd);
}

void PoissonGpuEngine::addGateShape(std::pair<std::uint32_t, std::uint32_t> groups) {
    if (gateEntry_.emplace(groups, static_cast<std::uint32_t>(gateArgs_.size() / 3)).second)
        gateArgs_.insert(gateArgs_.end(), {groups.first, groups.second, 1u});
}

void PoissonGpuEngine::armGate() {
    gate.upload(gateArgs_.data(), gateArgs_.size() * sizeof(std::uint32_t));
}

void PoissonGpuEngine::recordSetup(VkCommandBuffer cmd, float alpha2, bool irlsWeights, vk::GpuTimer* timer) {
    PoissonPush push = levelPush(levels_[0], groups());
    push.alpha2 = alpha2;
    push.flags = gpu::kPoissonFlagDot | (irlsWeights ? gpu::kPoissonFlagIrls : 0u);
    dispatch(cmd, kernel(PoissonOp::Setup, push.flags), width(), height(), &push, timer);
}

void PoissonGpuEngine::recordCoarsenAll(VkCommandBuffer cmd, vk::GpuTimer* timer) {
    for (std::size_t l = 0; l + 1 < levels_.size(); ++l) {
        PoissonPush push = levelPush(levels_[l], groups());
        withCoarse(push, levels_[l + 1]);
        dispatch(cmd, kernel(PoissonOp::Coarsen, 0u), levels_[l + 1].width, levels_[l + 1].height, &push,
                 timer);
    }
}

void PoissonGpuEngine::recordResidual(VkCommandBuffer cmd, int level, std::uint32_t flags,
                                      vk::GpuTimer* timer) {
    PoissonPush push = levelPush(levels_.at(static_cast<std::size_t>(level)), groups());
    push.flags = flags;
    dispatch(cmd, kernel(PoissonOp::Residual, flags), push.width, push.height, &push, timer);
}

void PoissonGpuEngine::recordSmooth(VkCommandBuffer cmd, int level, std::uint32_t flags, std::uint32_t colour,
                                    float omega, vk::GpuTimer* timer) {
    const std::size_t l = static_cast<std::size_t>(level);
    PoissonPush push = levelPush(levels_.at(l), groups());
    if (l + 1 < levels_.size()) withCoarse(push, levels_[l + 1]);
    push.flags = flags;
    push.colour = colour;
    push.omega = omega;
    // One invocation per horizontal pixel pair (see poisson_smooth.comp).
    dispatch(cmd, kernel(PoissonOp::Smooth, flags), (levels_[l].width + 1) / 2, push.height, &push, timer);
}

void PoissonGpuEngine::recordRestrict(VkCommandBuffer cmd, int level, std::uint32_t flags,
                                      vk::GpuTimer* timer) {
    const std::size_t l = static_cast<std::size_t>(level);
    PoissonPush push = levelPush(levels_.at(l), groups());
    withCoarse(push, levels_.at(l + 1));
    push.flags = flags;
    dispatch(cmd, kernel(PoissonOp::Restrict, flags), push.coarseWidth, push.coarseHeight, &push, timer);
}

void PoissonGpuEngine::recordProlong(VkCommandBuffer cmd, int level, vk::GpuTimer* timer) {
    const std::size_t l = static_cast<std::size_t>(level);
    PoissonPush push = levelPush(levels_.at(l), groups());
    withCoarse(push, levels_.at(l + 1));
    dispatch(cmd, kernel(PoissonOp::Prolong, 0u), push.width, push.height, &push, timer);
}

void PoissonGpuEngine::recordCoarsest(VkCommandBuffer cmd, bool zeroGuess, vk::GpuTimer* timer) {
    PoissonPush push = levelPush(levels_.back(), groups());
    push.flags = zeroGuess ? gpu::kPoissonFlagZeroGuess : 0u;
    dispatchGroups(cmd, kernel(PoissonOp::Coarsest, push.flags), 1, 1, &push, timer);
}

void PoissonGpuEngine::recordCgDirection(VkCommandBuffer cmd, std::uint32_t flags, std::uint32_t pOld,
                                         std::uint32_t pNew, vk::GpuTimer* timer) {
    PoissonPush push = levelPush(levels_[0], groups());
    push.flags = flags;
    push.pOld = pOld;
    push.pNew = pNew;
    dispatch(cmd, kernel(PoissonOp::CgDirection, flags), width(), height(), &push, timer);
}

void PoissonGpuEngine::recordCgUpdate(VkCommandBuffer cmd, std::uint32_t pNew, vk::GpuTimer* timer) {
    PoissonPush push = levelPush(levels_[0], groups());
    push.pNew = pNew;
    dispatch(cmd, kernel(PoissonOp::CgUpdate, 0u), width(), height(), &push, timer);
}

void PoissonGpuEngine::recordScalars(VkCommandBuffer cmd, std::uint32_t mode, std::uint32_t flags,
                                     std::uint32_t iteration, float tolerance, float value,
                                     vk::GpuTimer* timer) {
    PoissonPush push = levelPush(levels_[0], groups());
    push.mode = mode;
    push.flags = flags;
    push.iteration = iteration;
    push.tolerance = tolerance;
    push.value = value;
    push.groups = groups();
    dispatchGroups(cmd, kernel(PoissonOp::Scalars, flags), 1, 1, &push, timer);
}

void PoissonGpuEngine::recordIrlsWeights(VkCommandBuffer cmd, float alpha2, float reg, vk::GpuTimer* timer) {
    PoissonPush push = levelPush(levels_[0], groups());
    push.alpha2 = alpha2;
    push.reg = reg;
    dispatch(cmd, kernel(PoissonOp::IrlsWeights, 0u), width(), height(), &push, timer);
}

void PoissonGpuEngine::recordVcycle(VkCommandBuffer cmd, const VcycleParams& params, bool zeroGuess,
                                    bool dotOut, vk::GpuTimer* timer) {
    vcycleLevel(cmd, 0, params, zeroGuess, dotOut, timer);
}

void PoissonGpuEngine::vcycleLevel(VkCommandBuffer cmd, int level, const VcycleParams& params, bool zeroGuess,
                                   bool dotOut, vk::GpuTimer* timer) {
    using namespace gpu;
    const float omega = params.omega;
    if (level + 1 == static_cast<int>(levels_.size())) {
        recordCoarsest(cmd, zeroGuess, timer);
        // Colour 2 matches no pixel: a pure b·x reduction pass.
        if (dotOut) recordSmooth(cmd, level, kPoissonFlagDot, 2u, omega, timer);
        return;
    }
    if (params.jacobi) {
        // Ping-pong X -> R -> X: an even number of sweeps ends in X.
        const int pre = params.preSmooth + params.preSmooth % 2;
        for (int s = 0; s < pre; ++s)
            recordSmooth(cmd, level,
                         kPoissonFlagJacobi | (s % 2 == 0 ? kPoissonFlagToR : 0u) |
                             (s == 0 && zeroGuess ? kPoissonFlagZeroGuess : 0u),
                         0u, omega, timer);
        recordRestrict(cmd, level, 0u, timer);
        vcycleLevel(cmd, level + 1, params, true, false, timer);
        recordProlong(cmd, level, timer);
        const int post = params.postSmooth + params.postSmooth % 2;
        for (int s = 0; s < post; ++s)
            recordSmooth(cmd, level,
                         kPoissonFlagJacobi | (s % 2 == 0 ? kPoissonFlagToR : 0u) |
                             (s + 1 == post && dotOut ? kPoissonFlagDot : 0u),
                         0u, omega, timer);
        return;
    }
    // Red-black Gauss-Seidel: pre-sweeps red first, post-sweeps black first (symmetric).
    for (int s = 0; s < params.preSmooth; ++s) {
        recordSmooth(cmd, level, s == 0 && zeroGuess ? kPoissonFlagZeroGuess : 0u, 0u, omega, timer);
        recordSmooth(cmd, level, 0u, 1u, omega, timer);
    }
    if (params.preSmooth == 0 && zeroGuess) {
        // The restriction reads x: give it a defined zero without a separate clear pass.
        recordSmooth(cmd, level, kPoissonFlagJacobi | kPoissonFlagZeroGuess, 0u, 0.0f, timer);
    }
    recordRestrict(cmd, level, 0u, timer);
    vcycleLevel(cmd, level + 1, params, true, false, timer);
    const int post = params.postSmooth < 1 ? 1 : params.postSmooth;
    for (int s = 0; s < post; ++s) {
        recordSmooth(cmd, level, s == 0 ? kPoissonFlagCorrect : 0u, 1u, omega, timer);
        recordSmooth(cmd, level, s + 1 == post && dotOut ? kPoissonFlagDot : 0u, 0u, omega, timer);
    }
}

void PoissonGpuEngine::recordCopy(VkCommandBuffer cmd, const vk::Buffer& from, const vk::Buffer& to,
                                  std::uint64_t floats) {
    VkBufferCopy region{};
    region.size = floats * sizeof(float);
    vkCmdCopyBuffer(cmd, from.get(), to.get(), 1, &region);
    vk::computeBarrier(cmd);
}

}  // namespace gdpt
