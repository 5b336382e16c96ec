// poisson_cg_update.comp — CG iterate and residual update (Shewchuk §B2):
//   x ← x + α_k p,   r ← r − α_k Ap,   partial sums of r·r to slot RR,
// with per-channel α_k from PoissonScalars (0 once a channel has converged, which freezes
// it). x is Sol, r is B level 0, p is P at pNew.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#include "poisson_shared.h"
layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;
#include "lib/poisson_common.glsl"

void main() {
    uint x = gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    uint w = pc.width, h = pc.height, n = w * h;
    vec3 rr = vec3(0.0);
    if (x < w && y < h) {
        uint i = y * w + x;
        for (uint c = 0u; c < 3u; ++c) {
            uint j = c * n + i;
            float a = sc.alpha[c];
            Sol[j] += a * P[pc.pNew + j];
            float r = B[j] - a * Ap[j];
            B[j] = r;
            rr[c] = r * r;
        }
    }
    writePartials(rr, kPoissonSlotRR);
}
