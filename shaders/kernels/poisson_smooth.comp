// poisson_smooth.comp — one smoothing step for A x = b on one level (Briggs et al., "A
// Multigrid Tutorial", ch. 2; CPU: jacobiSweep, gaussSeidelRedBlackSweep):
//   RB-GS half-sweep (default): pixels with (x + y) mod 2 == colour get
//       x_i ← (b_i + Σ_j c_ij x_j) / D_i,   D_i = Σ_j c_ij + cp_i  (in place; the other colour
//       is only read, so one half-sweep is an exact parallel block update);
//   damped Jacobi (kPoissonFlagJacobi): x_i ← x_i + ω (b − A x)_i / D_i, from X to R
//       (kPoissonFlagToR) or from R to X (ping-pong).
// Rows with D_i = 0 keep their value. Fusions that save whole passes over memory:
//   kPoissonFlagZeroGuess: the current x is 0 (first pre-sweep after a zero initial guess),
//       so it is neither read nor cleared beforehand;
//   kPoissonFlagCorrect: the values read are x + P x_H (piecewise-constant prolongation of
//       the coarse correction, CPU prolongate); an RB-GS half-sweep never reads the values
//       it overwrites, so the first post-sweep applies the correction on the fly;
//   kPoissonFlagDot: partial sums of b·x_new to slot RZ (level 0 in PCG: r·z).
// Colour 2 matches no pixel: with kPoissonFlagDot that is a pure b·x reduction.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#include "poisson_shared.h"
layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;
#include "lib/poisson_common.glsl"

bool flag(uint f) { return (pc.flags & f) != 0u; }

// Current value of x at pixel (px, py), channel c, as the flags define it.
float current(uint px, uint py, uint c) {
    if (flag(kPoissonFlagZeroGuess)) return 0.0;
    uint n = pc.width * pc.height;
    uint j = c * n + py * pc.width + px;
    float v = flag(kPoissonFlagJacobi) && !flag(kPoissonFlagToR) ? R[pc.rOff + j] : X[pc.xOff + j];
    if (flag(kPoissonFlagCorrect)) {
        uint cn = pc.coarseWidth * pc.coarseHeight;
        v += X[pc.coarseXOff + c * cn + (py / 2u) * pc.coarseWidth + px / 2u];
    }
    return v;
}

// One invocation per horizontal pixel pair (2·gx, 2·gx + 1) of row y: exactly one of the
// two has the colour being updated, and which one depends on y only, so SIMD lanes along a
// row never diverge and a half-sweep launches half the invocations.
void main() {
    uint gx = gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    uint w = pc.width, h = pc.height, n = w * h;
    bool jacobi = flag(kPoissonFlagJacobi);
    vec3 dotv = vec3(0.0);
    if (2u * gx < w && y < h) {
        for (uint k = 0u; k < 2u; ++k) {
            uint x = 2u * gx + k;
            if (x >= w) break;
            bool mine = ((x + y) & 1u) == pc.colour;
            uint i = y * w + x;
            if (!jacobi && !mine) {
                // The other colour is only read (its final value for the dot product).
                if (flag(kPoissonFlagDot))
                    for (uint c = 0u; c < 3u; ++c) dotv[c] += B[pc.bOff + c * n + i] * X[pc.xOff + c * n + i];
                continue;
            }
            Stencil s = loadStencil(x, y, w, h, pc.cOff);
            float d = stencilDiag(s);
            uint xW = x > 0u ? x - 1u : x, xE = x + 1u < w ? x + 1u : x;
            uint yN = y > 0u ? y - 1u : y, yS = y + 1u < h ? y + 1u : y;
            for (uint c = 0u; c < 3u; ++c) {
                float b = B[pc.bOff + c * n + i];
                float xNew;
                if (jacobi) {
                    float xi = current(x, y, c);
                    float r = b - applyStencil(s, xi, current(xW, y, c), current(xE, y, c),
                                               current(x, yN, c), current(x, yS, c));
                    xNew = d > 0.0 ? xi + pc.omega * r / d : xi;
                    if (flag(kPoissonFlagToR))
                        R[pc.rOff + c * n + i] = xNew;
                    else
                        X[pc.xOff + c * n + i] = xNew;
                } else {
                    float sum = b + s.cW * current(xW, y, c) + s.cE * current(xE, y, c) +
                                s.cN * current(x, yN, c) + s.cS * current(x, yS, c);
                    xNew = d > 0.0 ? sum / d : current(x, y, c);
                    X[pc.xOff + c * n + i] = xNew;
                }
                dotv[c] += b * xNew;
            }
        }
    }
    if (flag(kPoissonFlagDot)) writePartials(dotv, kPoissonSlotRZ);
}
