// poisson_cg_direction.comp — CG search direction and its image under A, fused (Shewchuk,
// "An Introduction to the Conjugate Gradient Method Without the Agonizing Pain", §B2/B3):
//   p_new = z + β p_old            (β = 0 with kPoissonFlagFirst; z = r with kPoissonFlagZIsR)
//   Ap    = A p_new                (neighbours' p_new recomputed on the fly from z and p_old,
//                                   so p needs no separate pass; p_old and p_new are two slots)
//   partial sums of p_new·Ap to slot PAP (α_k = rz / pAp in poisson_scalars).
// Fine level only: z in X (offset 0), r in B (offset 0), per-channel β in PoissonScalars.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#include "poisson_shared.h"
layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;
#include "lib/poisson_common.glsl"

float direction(uint j, float beta) {
    float z = flag(kPoissonFlagZIsR) ? B[j] : X[j];
    return flag(kPoissonFlagFirst) ? z : z + beta * P[pc.pOld + j];
}

void main() {
    uint x = gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    uint w = pc.width, h = pc.height, n = w * h;
    vec3 pap = vec3(0.0);
    if (x < w && y < h) {
        Stencil s = loadStencil(x, y, w, h, pc.cOff);
        // All loads before the stores (lavapipe must assume storage buffers alias).
        vec3 p, ap;
        for (uint c = 0u; c < 3u; ++c) {
            uint o = c * n;
            float beta = sc.beta[c];
            p[c] = direction(o + s.i, beta);
            ap[c] = applyStencil(s, p[c], direction(o + s.iW, beta), direction(o + s.iE, beta),
                                 direction(o + s.iN, beta), direction(o + s.iS, beta));
        }
        for (uint c = 0u; c < 3u; ++c) {
            P[pc.pNew + c * n + s.i] = p[c];
            Ap[c * n + s.i] = ap[c];
        }
        pap = p * ap;
    }
    writePartials(pap, kPoissonSlotPAP);
}
