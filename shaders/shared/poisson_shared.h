// poisson_shared.h — host/shader interface of the GPU screened-Poisson solver
// (src/poisson/poisson_gpu*.cpp, shaders/kernels/poisson_*.comp). Same rules as
// gdpt_shared.h: C++17 and GLSL 460 in one file, scalar layout, no bool, append-only.
//
// Data layout. Every RGB field is planar: channel c of a field stored at float offset `off`
// occupies [off + c·n, off + (c+1)·n) with n = width·height of its level, pixel
// i = y·width + x. All multigrid levels of one role (x, b, scratch r, coefficients) live in
// one buffer, level after level; kernels get the level's offsets in PoissonPush, so one
// pipeline serves every level and descriptor sets never change between dispatches.
// Coefficients of a level are three planes (cx, cy, cp) of the operator
//     (A x)_i = Σ_{j∈N(i)} c_ij (x_i − x_j) + cp_i x_i      (see src/poisson/poisson_problem.h)
// with cx_i the weight of edge (x,y)–(x+1,y) and cy_i of edge (x,y)–(x,y+1).
#ifndef GDPT_POISSON_SHARED_H
#define GDPT_POISSON_SHARED_H

#include "gdpt_shared.h"

#ifdef __cplusplus
namespace gdpt::gpu {
#endif

// The field buffers of the solver. Each kernel is built twice (shaders/CMakeLists.txt):
//   descriptors (default): field f is the storage buffer at binding kPoissonBindFieldBase + f;
//   device addresses (GDPT_POISSON_DEVICE_ADDRESS, kSpv_poisson_*_addr): the table at binding
//       kPoissonBindFields holds each field's 64-bit address (GL_EXT_buffer_reference).
// The second exists for fields beyond maxStorageBufferRange (a descriptor range limit; a
// 4096x4096 solve has 200-270 MB fields, lavapipe allows 128 MiB); it is only used then,
// because lavapipe 22.3 runs the address-based loads about 1.2x slower.
GDPT_ENUM_BEGIN(PoissonField)
kPoissonFieldCoef = 0u,           // float: per level cx, cy, cp planes
    kPoissonFieldX = 1u,          // float: per level x (V-cycle unknown; 3 planes)
    kPoissonFieldB = 2u,          // float: per level right-hand side (level 0: CG residual r)
    kPoissonFieldR = 3u,          // float: per level scratch (residual, Jacobi ping-pong)
    kPoissonFieldP = 4u,          // float: two fine RGB slots, CG search direction p (ping-pong)
    kPoissonFieldAp = 5u,         // float: fine RGB, A p
    kPoissonFieldSol = 6u,        // float: fine RGB, the solution image being reconstructed
    kPoissonFieldRhs = 7u,        // float: fine RGB, b = Pᵀ W target
    kPoissonFieldPrimal = 8u,     // float: fine RGB primal t (radiance)
    kPoissonFieldDx = 9u,         // float: fine RGB target of I(x+1,y) − I(x,y)
    kPoissonFieldDy = 10u,        // float: fine RGB target of I(x,y+1) − I(x,y)
    kPoissonFieldWeights = 11u,   // float: fine planes wp, wdx, wdy (input weights, ≥ 0)
    kPoissonFieldIrls = 12u,      // float: fine planes of IRLS row weights (primal, dx, dy)
    kPoissonFieldPartials = 13u,  // float: per-subgroup partial sums, see kPoissonSlot*
    kPoissonFieldCount = 14u GDPT_ENUM_END();

// Descriptor bindings of the poisson_* kernels (set 0).
GDPT_ENUM_BEGIN(PoissonBinding)
kPoissonBindFields = 0u,         // device-address variant: uint64 address per kPoissonField*
    kPoissonBindScalars = 1u,    // PoissonScalars followed by the residual history
    kPoissonBindFieldBase = 2u,  // descriptor variant: field f at binding 2 + f
    kPoissonBindGate = 16u,      // uint: indirect group counts (x, y, z) of gated dispatches
    kPoissonBindCount = 17u GDPT_ENUM_END();

// Partial-sum slots: a reduction kernel writes partials[(slot·3 + c)·G + g] for workgroup g
// of G and channel c; poisson_scalars sums them in a fixed order (deterministic).
GDPT_ENUM_BEGIN(PoissonSlot)
kPoissonSlotBB = 0u,          // ‖b‖²
    kPoissonSlotRR = 1u,      // ‖r‖²
    kPoissonSlotRZ = 2u,      // r·z (preconditioned)
    kPoissonSlotPAP = 3u,     // p·Ap
    kPoissonSlotWeight = 4u,  // Σ IRLS weights (channel 0 only meaningful)
    kPoissonSlotSum = 5u,     // Σ b (mean removal for singular systems)
    kPoissonSlotCount = 6u GDPT_ENUM_END();

// Flag bits of a poisson_* pipeline variant. They are the specialisation constant
// kSpecPoissonFlags, not a push constant: lavapipe executes both sides of every branch under
// lane masks (and still walks the lanes of masked-off loads), so a runtime flag paid for every
// path it did not take; specialised, the untaken paths are compiled out.
GDPT_CONST uint kPoissonFlagZeroGuess = 1u;   // smoother: the current x is 0 (not read)
GDPT_CONST uint kPoissonFlagCorrect = 2u;     // smoother: add the coarse correction P x_H first
GDPT_CONST uint kPoissonFlagJacobi = 4u;      // smoother: damped Jacobi instead of RB-GS
GDPT_CONST uint kPoissonFlagToR = 8u;         // Jacobi: read x from X, write to R (else R -> X)
GDPT_CONST uint kPoissonFlagDot = 16u;        // write partial sums (kernel-specific slot)
GDPT_CONST uint kPoissonFlagApplyOnly = 32u;  // residual kernel: R = A x instead of b − A x
GDPT_CONST uint kPoissonFlagPlain = 64u;      // restrict kernel: restrict R instead of b − A x
GDPT_CONST uint kPoissonFlagZIsR = 128u;      // CG: z = r (no preconditioner)
GDPT_CONST uint kPoissonFlagFirst = 256u;     // CG direction: p = z (ignore the old p)
GDPT_CONST uint kPoissonFlagIrls = 512u;      // setup: multiply by IRLS weights·scale
GDPT_CONST uint kPoissonFlagFromSol = 1024u;  // residual kernel: x = Sol, b = Rhs, r -> B
GDPT_CONST uint kPoissonFlagProject = 2048u;  // residual kernel: use b − mean(b) (singular A)

// poisson_scalars modes.
GDPT_ENUM_BEGIN(PoissonScalarMode)
kPoissonModeInit = 0u,        // bb, rr, rz from partials; β = 0; history[0]
    kPoissonModeAlpha = 1u,   // α = rz / pAp
    kPoissonModeBeta = 2u,    // history[k] = rr; convergence; β = rz_new / rz
    kPoissonModeRecord = 3u,  // stationary solvers: history[k] = rr; convergence
    kPoissonModeFinal = 4u,   // finalRr = rr (true residual)
    kPoissonModeIrls = 5u,    // irlsScale = value / Σ weights
    kPoissonModeMean = 6u     // bMean = Σ b / value (value = pixel count)
    GDPT_ENUM_END();

GDPT_CONST uint kPoissonMaxHistory = 4096u;    // residual history entries (per channel)
GDPT_CONST uint kPoissonSumUnroll = 16u;       // partials per loop iteration in poisson_scalars
GDPT_CONST uint kPoissonMaxGroupSize = 256u;   // reductions assume ≤ 256, a power of two
GDPT_CONST uint kPoissonCoarsestMax = 8u;      // coarsest level: width, height ≤ 8
GDPT_CONST uint kPoissonCoarsestSweeps = 48u;  // symmetric RB-GS sweep pairs on the coarsest

// Push constants of every poisson_* kernel. 92 bytes (≤ 128 on lavapipe).
struct PoissonPush {
    uint width;        // this level's width (pixels)
    uint height;       // this level's height
    uint xOff;         // float offset of this level's x in X (or R/Sol where stated)
    uint bOff;         // float offset of this level's b in B
    uint rOff;         // float offset of this level's scratch in R
    uint cOff;         // float offset of this level's cx plane in Coef (cy, cp follow)
    uint coarseWidth;  // next-coarser level's size (restriction, prolongation, coarsening)
    uint coarseHeight;
    uint coarseXOff;  // float offset of the coarser level's x in X
    uint coarseBOff;  // ... its b in B
    uint coarseCOff;  // ... its coefficients in Coef
    uint flags;       // copy of the variant's kPoissonFlag* (the kernels read kFlags)
    uint colour;      // RB-GS colour updated by this half-sweep: (x + y) mod 2
    uint mode;        // poisson_scalars: kPoissonMode*
    uint iteration;   // iteration number recorded by poisson_scalars
    uint groups;      // number of workgroups G that wrote partial sums
    uint pOld;        // float offset in P of the previous search direction
    uint pNew;        // float offset in P of the new search direction
    float omega;      // Jacobi damping
    float alpha2;     // α², energy weight of the primal rows
    float reg;        // IRLS regulariser ε_k (radiance units)
    float tolerance;  // relative residual tolerance
    float value;      // mode-specific scalar (IRLS: number of kept rows)
};

// Device-side solver state (binding kPoissonBindScalars), followed by the residual history
// history[k·3 + c] = ‖r_k‖² of channel c after iteration k. 136 bytes.
struct PoissonScalars {
    float bb[3];         // ‖b‖² per channel
    float rr[3];         // ‖r‖² of the latest iterate
    float rz[3];         // r·z
    float pap[3];        // p·Ap
    float alpha[3];      // CG step α_k
    float beta[3];       // CG β_k
    float finalRr[3];    // ‖b − A x‖² recomputed at the end
    uint done[3];        // 1 once channel c converged (or CG broke down)
    uint iterations[3];  // iterations until convergence (or performed)
    float irlsScale;     // IRLS normalisation: kept rows / Σ weights
    float bMean[3];      // mean of b per channel (projection onto range(A) when α = 0)
    float rrMin[3];      // smallest ‖r‖² so far (divergence guard for singular A)
};

#ifdef __cplusplus
}  // namespace gdpt::gpu
#endif
#endif  // GDPT_POISSON_SHARED_H
