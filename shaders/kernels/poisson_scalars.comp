// poisson_scalars.comp — the solver's scalar work, on the device so that a whole batch of
// iterations is one command buffer with no host round trip (one workgroup of 256).
// Every sum is over the G per-workgroup partials of one slot in a fixed order (strided
// per-invocation sums, then a shared-memory tree), so results are bit-reproducible.
// Per channel c, with tolerance τ (relative residual) and iteration k = pc.iteration:
//   Init:   bb = Σ BB, rr = Σ RR, rz = Σ RZ (or rr without preconditioner), β = 0,
//           history[0] = rr, done = (rr ≤ τ² bb)
//   Alpha:  pAp = Σ PAP, α = rz / pAp (0 if done; pAp ≤ 0 means breakdown: done)
//   Beta:   rr = Σ RR, history[k] = rr, rz' = Σ RZ (or rr), convergence test, β = rz'/rz
//   Record: rr = Σ RR, history[k] = rr, convergence test (stationary solvers)
//   Final:  finalRr = Σ RR (true residual of the returned x)
//   Irls:   irlsScale = value / Σ WEIGHT (IRLS weights renormalised to mean 1)
//   Mean:   bMean = Σ SUM / value (value = pixel count)
// CG recurrences: Shewchuk, "CG without the agonizing pain", §B2 (preconditioned: §B3).
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "poisson_shared.h"
layout(local_size_x = 256, local_size_y = 1) in;
#include "lib/poisson_common.glsl"

// Indirect group counts of the gated dispatches (PoissonGpuEngine::setGated).
layout(set = 0, binding = kPoissonBindGate, scalar) buffer GateBuf { uint gateArgs[]; };

shared float sSum[256];

// The strided per-invocation sum reads kPoissonSumUnroll entries per loop iteration, and
// main() has no loop around the sums. llvmpipe stops any outermost loop after 65535
// iterations, counting the iterations of loops nested in it (LP_MAX_TGSI_LOOP_ITERATIONS),
// silently: with one entry per iteration inside main()'s channel loop, Init's nine sums over
// G ≈ 1.9M partials (3900x3900) crossed that cap and MG-PCG diverged. The engine checks the
// bound (PoissonGpuEngine, kPoissonSumUnroll).
#define SUM_AT(k) if (j + (k) * 256u < g) s += PARTIAL(slot, base + j + (k) * 256u);
#define SUM_4(k) SUM_AT(k) SUM_AT(k + 1u) SUM_AT(k + 2u) SUM_AT(k + 3u)
float sumSlot(uint slot, uint c) {
    uint l = gl_LocalInvocationIndex;
    uint g = pc.groups, base = c * g;
    float s = 0.0;
    for (uint j = l; j < g; j += 256u * kPoissonSumUnroll) {
        SUM_4(0u) SUM_4(4u) SUM_4(8u) SUM_4(12u)
    }
    sSum[l] = s;
    barrier();
    for (uint k = 128u; k > 0u; k >>= 1u) {
        if (l < k) sSum[l] += sSum[l + k];
        barrier();
    }
    float total = sSum[0];
    barrier();
    return total;
}

bool converged(float rr, float bb) { return rr <= pc.tolerance * pc.tolerance * bb; }

void recordHistory(uint c, float rr) {
    uint k = min(pc.iteration, kPoissonMaxHistory - 1u);
    history[k * 3u + c] = rr;
}

void main() {
    bool lead = gl_LocalInvocationIndex == 0u;
    bool precond = !flag(kPoissonFlagZIsR);
    [[unroll]] for (uint c = 0u; c < 3u; ++c) {
        if (pc.mode == kPoissonModeInit) {
            float bb = sumSlot(kPoissonSlotBB, c);
            float rr = sumSlot(kPoissonSlotRR, c);
            float rz = precond ? sumSlot(kPoissonSlotRZ, c) : rr;
            if (lead) {
                sc.bb[c] = bb;
                sc.rr[c] = rr;
                sc.rz[c] = rz;
                sc.beta[c] = 0.0;
                sc.alpha[c] = 0.0;
                sc.done[c] = converged(rr, bb) ? 1u : 0u;
                sc.iterations[c] = 0u;
                sc.rrMin[c] = rr;
                recordHistory(c, rr);
            }
        } else if (pc.mode == kPoissonModeAlpha) {
            float pap = sumSlot(kPoissonSlotPAP, c);
            if (lead) {
                sc.pap[c] = pap;
                bool ok = sc.done[c] == 0u && pap > 0.0;
                if (sc.done[c] == 0u && !(pap > 0.0)) sc.done[c] = 1u;
                sc.alpha[c] = ok ? sc.rz[c] / pap : 0.0;
            }
        } else if (pc.mode == kPoissonModeBeta || pc.mode == kPoissonModeRecord) {
            float rr = sumSlot(kPoissonSlotRR, c);
            float rz = (precond && pc.mode == kPoissonModeBeta) ? sumSlot(kPoissonSlotRZ, c) : rr;
            if (lead) {
                recordHistory(c, rr);
                sc.rr[c] = rr;
                if (sc.done[c] == 0u) {
                    sc.iterations[c] = pc.iteration;
                    if (converged(rr, sc.bb[c])) sc.done[c] = 1u;
                    // Singular A at the float32 floor: rounding leaves a component CG cannot
                    // remove and the recurrences lose conjugacy; stop once the residual has
                    // grown 10x past its best instead of diverging.
                    if (flag(kPoissonFlagProject) && rr > 100.0 * sc.rrMin[c]) sc.done[c] = 1u;
                }
                sc.rrMin[c] = min(sc.rrMin[c], rr);
                if (pc.mode == kPoissonModeBeta) {
                    sc.beta[c] = sc.done[c] == 0u && sc.rz[c] > 0.0 ? rz / sc.rz[c] : 0.0;
                    sc.rz[c] = rz;
                }
            }
        } else if (pc.mode == kPoissonModeFinal) {
            float rr = sumSlot(kPoissonSlotRR, c);
            if (lead) sc.finalRr[c] = rr;
        }
    }
    if (pc.mode == kPoissonModeMean)
        [[unroll]] for (uint c = 0u; c < 3u; ++c) {
            float sum = sumSlot(kPoissonSlotSum, c);
            if (lead) sc.bMean[c] = sum / pc.value;
        }
    // Every channel converged: the rest of the recorded batch becomes empty dispatches.
    bool testsConvergence =
        pc.mode == kPoissonModeInit || pc.mode == kPoissonModeBeta || pc.mode == kPoissonModeRecord;
    if (lead && testsConvergence && sc.done[0] != 0u && sc.done[1] != 0u && sc.done[2] != 0u)
        for (uint i = 0u; i < gateArgs.length(); ++i) gateArgs[i] = 0u;
    if (pc.mode == kPoissonModeIrls) {
        float sum = sumSlot(kPoissonSlotWeight, 0u);
        if (lead) sc.irlsScale = sum > 0.0 ? pc.value / sum : 1.0;
    }
}
