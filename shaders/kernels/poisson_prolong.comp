// poisson_prolong.comp — coarse-grid correction x += P x_H with piecewise-constant P: each
// fine cell adds its aggregate's value (Briggs et al. ch. 3; CPU: prolongate). Used after a
// Jacobi-smoothed level; the RB-GS smoother fuses it into its first post-sweep instead.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#include "poisson_shared.h"
layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;
#include "lib/poisson_common.glsl"

void main() {
    uint x = gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    uint w = pc.width, h = pc.height, n = w * h;
    if (x >= w || y >= h) return;
    uint cn = pc.coarseWidth * pc.coarseHeight;
    uint i = y * w + x, ci = (y / 2u) * pc.coarseWidth + x / 2u;
    for (uint c = 0u; c < 3u; ++c) X[pc.xOff + c * n + i] += X[pc.coarseXOff + c * cn + ci];
}
