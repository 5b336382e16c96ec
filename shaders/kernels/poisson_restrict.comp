// poisson_restrict.comp — residual restriction b_H = R (b − A x) with R = ¼ Pᵀ, the
// cell-centred average of each coarse cell's ≤ 4 children (Briggs et al. ch. 3; CPU:
// residual + restrictFullWeighting). Fused: the fine residual is computed on the fly and
// never stored. kPoissonFlagPlain restricts the stored field R (this level) instead.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#include "poisson_shared.h"
layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;
#include "lib/poisson_common.glsl"

void main() {
    uint cx = gl_GlobalInvocationID.x, cy = gl_GlobalInvocationID.y;
    uint cw = pc.coarseWidth, ch = pc.coarseHeight;
    if (cx >= cw || cy >= ch) return;
    uint w = pc.width, h = pc.height, n = w * h, cn = cw * ch;
    bool plain = flag(kPoissonFlagPlain);
    vec3 sum = vec3(0.0);
    for (uint dy = 0u; dy < 2u; ++dy)
        for (uint dx = 0u; dx < 2u; ++dx) {
            uint fx = 2u * cx + dx, fy = 2u * cy + dy;
            if (fx >= w || fy >= h) continue;
            if (plain) {
                uint i = fy * w + fx;
                for (uint c = 0u; c < 3u; ++c) sum[c] += R[pc.rOff + c * n + i];
                continue;
            }
            Stencil s = loadStencil(fx, fy, w, h, pc.cOff);
            for (uint c = 0u; c < 3u; ++c) {
                uint o = pc.xOff + c * n;
                float ax = applyStencil(s, X[o + s.i], X[o + s.iW], X[o + s.iE], X[o + s.iN],
                                        X[o + s.iS]);
                sum[c] += B[pc.bOff + c * n + s.i] - ax;
            }
        }
    uint ci = cy * cw + cx;
    for (uint c = 0u; c < 3u; ++c) B[pc.coarseBOff + c * cn + ci] = 0.25 * sum[c];
}
