// poisson_residual.comp — r = b − A x on one level (or r = A x with kPoissonFlagApplyOnly),
// A the weighted 5-point Laplacian + screening (poisson_shared.h). Default operands: x in X,
// b in B, r to R at this level's offsets. With kPoissonFlagFromSol: x = Sol, b = Rhs and r
// goes to B (level 0), which is how CG starts and how the true final residual is computed.
// kPoissonFlagDot: partial ‖r‖² to slot RR. kPoissonFlagProject (singular A, α = 0): b is
// replaced by b − mean(b), its projection onto range(A), so float rounding in Σ b cannot
// leave CG chasing an unreachable constant component.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#include "poisson_shared.h"
layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;
#include "lib/poisson_common.glsl"

float loadX(uint j) { return flag(kPoissonFlagFromSol) ? Sol[j] : X[pc.xOff + j]; }

void main() {
    uint x = gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    uint w = pc.width, h = pc.height, n = w * h;
    vec3 rr = vec3(0.0);
    if (x < w && y < h) {
        Stencil s = loadStencil(x, y, w, h, pc.cOff);
        bool fromSol = flag(kPoissonFlagFromSol);
        vec3 r;
        for (uint c = 0u; c < 3u; ++c) {
            uint o = c * n;
            float ax = applyStencil(s, loadX(o + s.i), loadX(o + s.iW), loadX(o + s.iE),
                                    loadX(o + s.iN), loadX(o + s.iS));
            if (flag(kPoissonFlagApplyOnly))
                r[c] = ax;
            else
                r[c] = (fromSol ? Rhs[o + s.i] : B[pc.bOff + o + s.i]) - ax;
            if (flag(kPoissonFlagProject)) r[c] -= sc.bMean[c];
        }
        // Stores after all loads (lavapipe must assume storage buffers alias).
        for (uint c = 0u; c < 3u; ++c) {
            if (fromSol)
                B[c * n + s.i] = r[c];
            else
                R[pc.rOff + c * n + s.i] = r[c];
        }
        rr = r * r;
    }
    if (flag(kPoissonFlagDot)) writePartials(rr, kPoissonSlotRR);
}
