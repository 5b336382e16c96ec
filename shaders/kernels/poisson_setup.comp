// poisson_setup.comp — fine-level operator and right-hand side of the screened Poisson
// problem (Kettunen et al. 2015, §4; src/poisson/poisson_cpu.h makeOperator/computeRhs).
// Per pixel i = (x, y), with row weights w = Wt·(IRLS weight · irlsScale if kPoissonFlagIrls):
//   cx_i = wdx_i (x < W−1, else 0),  cy_i = wdy_i (y < H−1, else 0),  cp_i = α² wp_i,
//   b_i  = α² wp_i t_i − wdx_i dx_i + wdx_{i−1} dx_{i−1} − wdy_i dy_i + wdy_{i−W} dy_{i−W}
// (b = Pᵀ W target gathered per pixel, so no atomics), written to Rhs; partial ‖b‖² sums
// go to slot BB and of Σ b to slot SUM when kPoissonFlagDot is set.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#include "poisson_shared.h"
layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;
#include "lib/poisson_common.glsl"

// Row weight of plane k (0 primal, 1 dx, 2 dy) at pixel j.
float rowWeight(uint k, uint j, uint n) {
    float w = Wt[k * n + j];
    if (flag(kPoissonFlagIrls)) w *= Irls[k * n + j] * sc.irlsScale;
    return w;
}

void main() {
    uint x = gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    uint w = pc.width, h = pc.height, n = w * h;
    vec3 bb = vec3(0.0), bsum = vec3(0.0);
    if (x < w && y < h) {
        uint i = y * w + x;
        float wp = rowWeight(0u, i, n);
        float wdx = x + 1u < w ? rowWeight(1u, i, n) : 0.0;
        float wdy = y + 1u < h ? rowWeight(2u, i, n) : 0.0;
        float wdxW = x > 0u ? rowWeight(1u, i - 1u, n) : 0.0;
        float wdyN = y > 0u ? rowWeight(2u, i - w, n) : 0.0;
        Coef[i] = wdx;
        Coef[n + i] = wdy;
        Coef[2u * n + i] = pc.alpha2 * wp;
        for (uint c = 0u; c < 3u; ++c) {
            uint o = c * n;
            float b = pc.alpha2 * wp * Primal[o + i];
            if (x + 1u < w) b -= wdx * Dx[o + i];
            if (x > 0u) b += wdxW * Dx[o + i - 1u];
            if (y + 1u < h) b -= wdy * Dy[o + i];
            if (y > 0u) b += wdyN * Dy[o + i - w];
            Rhs[o + i] = b;
            bb[c] = b * b;
            bsum[c] = b;
        }
    }
    if (flag(kPoissonFlagDot)) {
        writePartials(bb, kPoissonSlotBB);
        writePartials(bsum, kPoissonSlotSum);
    }
}
