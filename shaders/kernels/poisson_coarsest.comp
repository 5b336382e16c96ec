// poisson_coarsest.comp — approximate solve on the coarsest level (width, height ≤ 8): one
// workgroup of 64 invocations keeps x in shared memory and runs kPoissonCoarsestSweeps
// red-then-black Gauss-Seidel sweeps followed by as many black-then-red sweeps, so the
// result is a fixed symmetric linear function of b (usable inside a CG preconditioner,
// Briggs et al. ch. 3). Starts from 0 with kPoissonFlagZeroGuess, else from X. A singular
// level (α = 0) leaves its constant mode alone, which the Laplacian ignores anyway.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#include "poisson_shared.h"
layout(local_size_x = 64, local_size_y = 1) in;
#include "lib/poisson_common.glsl"

shared float sX[3u * 64u];

void sweep(uint colour, bool inside, uint px, uint py, Stencil s, vec3 b, float d) {
    if (inside && ((px + py) & 1u) == colour && d > 0.0) {
        for (uint c = 0u; c < 3u; ++c) {
            uint o = c * 64u;
            sX[o + s.i] = (b[c] + s.cW * sX[o + s.iW] + s.cE * sX[o + s.iE] + s.cN * sX[o + s.iN] +
                           s.cS * sX[o + s.iS]) / d;
        }
    }
    barrier();
}

void main() {
    uint l = gl_LocalInvocationIndex;
    uint w = pc.width, h = pc.height, n = w * h;
    bool inside = l < n;
    uint px = inside ? l % w : 0u, py = inside ? l / w : 0u;
    Stencil s = loadStencil(px, py, w, h, pc.cOff);
    float d = inside ? stencilDiag(s) : 0.0;
    vec3 b = vec3(0.0);
    bool zero = flag(kPoissonFlagZeroGuess) || !inside;
    for (uint c = 0u; c < 3u; ++c) {
        b[c] = inside ? B[pc.bOff + c * n + l] : 0.0;
        sX[c * 64u + l] = zero ? 0.0 : X[pc.xOff + c * n + l];
    }
    barrier();
    for (uint k = 0u; k < kPoissonCoarsestSweeps; ++k) {
        sweep(0u, inside, px, py, s, b, d);
        sweep(1u, inside, px, py, s, b, d);
    }
    for (uint k = 0u; k < kPoissonCoarsestSweeps; ++k) {
        sweep(1u, inside, px, py, s, b, d);
        sweep(0u, inside, px, py, s, b, d);
    }
    if (inside)
        for (uint c = 0u; c < 3u; ++c) X[pc.xOff + c * n + l] = sX[c * 64u + l];
}
