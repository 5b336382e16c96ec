// poisson_irls_weights.comp — IRLS row weights for L1 reconstruction (Kettunen et al. 2015,
// §4; CPU: computeIrlsWeights). For every kept row j with RGB residual e_j of the current
// estimate x = Sol,
//   primal row i:  e = α (x_i − t_i),   dx row: e = x_{i+1} − x_i − dx_i,   dy row likewise,
//   w_j = 1 / (‖e_j‖₂ + ε_k)     (shared by R, G, B; dropped rows get 0),
// written to Irls (planes primal, dx, dy); rows whose input weight is 0 (non-finite input)
// are left out of the normalisation sum, partial Σ w to slot WEIGHT (channel 0).
// poisson_scalars (mode Irls) turns the sum into the mean-1 scale applied by poisson_setup.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#include "poisson_shared.h"
layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;
#include "lib/poisson_common.glsl"

void main() {
    uint x = gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    uint w = pc.width, h = pc.height, n = w * h;
    float alpha = sqrt(pc.alpha2);
    vec3 sum = vec3(0.0);
    if (x < w && y < h) {
        uint i = y * w + x;
        vec3 ep, ex = vec3(0.0), ey = vec3(0.0);
        for (uint c = 0u; c < 3u; ++c) {
            uint o = c * n;
            ep[c] = alpha * (Sol[o + i] - Primal[o + i]);
            if (x + 1u < w) ex[c] = Sol[o + i + 1u] - Sol[o + i] - Dx[o + i];
            if (y + 1u < h) ey[c] = Sol[o + i + w] - Sol[o + i] - Dy[o + i];
        }
        float wp = 1.0 / (length(ep) + pc.reg);
        float wx = x + 1u < w ? 1.0 / (length(ex) + pc.reg) : 0.0;
        float wy = y + 1u < h ? 1.0 / (length(ey) + pc.reg) : 0.0;
        Irls[i] = wp;
        Irls[n + i] = wx;
        Irls[2u * n + i] = wy;
        sum.x = (Wt[i] > 0.0 ? wp : 0.0) + (Wt[n + i] > 0.0 ? wx : 0.0) +
                (Wt[2u * n + i] > 0.0 ? wy : 0.0);
    }
    writePartials(sum, kPoissonSlotWeight);
}
