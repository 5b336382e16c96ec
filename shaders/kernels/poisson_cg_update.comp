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
        vec3 a = vec3(sc.alpha[0], sc.alpha[1], sc.alpha[2]);
        vec3 xs, p, r, ap;
        for (uint c = 0u; c < 3u; ++c) {
            uint j = c * n + i;
            xs[c] = Sol[j];
            p[c] = P[pc.pNew + j];
            r[c] = B[j];
            ap[c] = Ap[j];
        }
        xs += a * p;
        r -= a * ap;
        for (uint c = 0u; c < 3u; ++c) {
            Sol[c * n + i] = xs[c];
            B[c * n + i] = r[c];
        }
        rr = r * r;
    }
    writePartials(rr, kPoissonSlotRR);
}
