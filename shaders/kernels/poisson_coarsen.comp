// poisson_coarsen.comp — Galerkin coarse operator A_H = R A P for piecewise-constant
// prolongation P and restriction R = ¼ Pᵀ (Briggs et al., "A Multigrid Tutorial", ch. 8;
// src/poisson/poisson_multigrid.cpp coarsenOperator). One invocation per coarse cell
// (X, Y) gathers its ≤ 4 children {2X, 2X+1} × {2Y, 2Y+1}:
//   cp_H = ¼ Σ_children cp,
//   cx_H = ¼ Σ_{children with x = 2X+1 < W−1} cx   (fine edges crossing to the next aggregate),
//   cy_H = ¼ Σ_{children with y = 2Y+1 < H−1} cy.
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
    float sx = 0.0, sy = 0.0, sp = 0.0;
    for (uint dy = 0u; dy < 2u; ++dy)
        for (uint dx = 0u; dx < 2u; ++dx) {
            uint fx = 2u * cx + dx, fy = 2u * cy + dy;
            if (fx >= w || fy >= h) continue;
            uint i = fy * w + fx;
            sp += Coef[pc.cOff + 2u * n + i];
            if (dx == 1u && fx + 1u < w) sx += Coef[pc.cOff + i];
            if (dy == 1u && fy + 1u < h) sy += Coef[pc.cOff + n + i];
        }
    uint ci = cy * cw + cx;
    Coef[pc.coarseCOff + ci] = 0.25 * sx;
    Coef[pc.coarseCOff + cn + ci] = 0.25 * sy;
    Coef[pc.coarseCOff + 2u * cn + ci] = 0.25 * sp;
}
