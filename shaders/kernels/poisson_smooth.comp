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

// Value of x at level index j (channel offset included) plus, with kPoissonFlagCorrect, the
// coarse correction of pixel (px, py); `src` selects X (0) or R (1). Only for the Jacobi
// path; the RB-GS path below is written out per flag combination, because lavapipe's
// SIMD code was ~5x slower with this generic accessor on every neighbour read.
float jacobiValue(uint j, uint px, uint py, uint c, bool fromR) {
    if (flag(kPoissonFlagZeroGuess)) return 0.0;
    float v = fromR ? R[pc.rOff + j] : X[pc.xOff + j];
    if (flag(kPoissonFlagCorrect)) {
        uint cn = pc.coarseWidth * pc.coarseHeight;
        v += X[pc.coarseXOff + c * cn + (py / 2u) * pc.coarseWidth + px / 2u];
    }
    return v;
}

// RB-GS half-sweep of the pixel (x, y) of colour pc.colour; loads everything before the
// stores (lavapipe must assume that storage buffers alias).
vec3 gaussSeidel(uint x, uint y, uint w, uint h, uint n, bool zero, bool correct) {
    uint i = y * w + x;
    Stencil s = loadStencil(x, y, w, h, pc.cOff);
    float d = stencilDiag(s);
    vec3 b, sum;
    for (uint c = 0u; c < 3u; ++c) b[c] = B[pc.bOff + c * n + i];
    sum = b;
    if (!zero) {
        uint cw = pc.coarseWidth, cn = pc.coarseWidth * pc.coarseHeight;
        uint cy = y / 2u, cx = x / 2u;
        // Coarse cells of the neighbours (for the fused correction).
        uint kW = cy * cw + (x > 0u ? (x - 1u) / 2u : cx), kE = cy * cw + (x + 1u < w ? (x + 1u) / 2u : cx);
        uint kN = (y > 0u ? (y - 1u) / 2u : cy) * cw + cx, kS = (y + 1u < h ? (y + 1u) / 2u : cy) * cw + cx;
        for (uint c = 0u; c < 3u; ++c) {
            uint xo = pc.xOff + c * n;
            float vW = X[xo + s.iW], vE = X[xo + s.iE], vN = X[xo + s.iN], vS = X[xo + s.iS];
            if (correct) {
                uint co = pc.coarseXOff + c * cn;
                vW += X[co + kW];
                vE += X[co + kE];
                vN += X[co + kN];
                vS += X[co + kS];
            }
            sum[c] += s.cW * vW + s.cE * vE + s.cN * vN + s.cS * vS;
        }
    }
    vec3 xNew;
    if (d > 0.0)
        xNew = sum / d;
    else
        for (uint c = 0u; c < 3u; ++c) xNew[c] = zero ? 0.0 : X[pc.xOff + c * n + i];
    for (uint c = 0u; c < 3u; ++c) X[pc.xOff + c * n + i] = xNew[c];
    return b * xNew;
}

// One invocation per horizontal pixel pair (2·gx, 2·gx + 1) of row y: exactly one of the
// two has the colour being updated (x ≡ colour − y mod 2), so a half-sweep launches half
// the invocations and SIMD lanes along a row never diverge.
void main() {
    uint gx = gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    uint w = pc.width, h = pc.height, n = w * h;
    bool dot = flag(kPoissonFlagDot);
    vec3 dotv = vec3(0.0);
    if (2u * gx < w && y < h) {
        if (!flag(kPoissonFlagJacobi)) {
            uint x = 2u * gx + ((pc.colour + y) & 1u);
            if (pc.colour < 2u && x < w)
                dotv = gaussSeidel(x, y, w, h, n, flag(kPoissonFlagZeroGuess), flag(kPoissonFlagCorrect));
            if (dot) {
                // The other colour is only read (its final value for the dot product).
                uint xo = 2u * gx + 1u - ((pc.colour + y) & 1u);
                if (pc.colour >= 2u) xo = 2u * gx;
                for (uint t = 0u; t < (pc.colour >= 2u ? 2u : 1u); ++t, ++xo)
                    if (xo < w)
                        for (uint c = 0u; c < 3u; ++c)
                            dotv[c] += B[pc.bOff + c * n + y * w + xo] * X[pc.xOff + c * n + y * w + xo];
            }
        } else {
            for (uint k = 0u; k < 2u; ++k) {
                uint x = 2u * gx + k;
                if (x >= w) break;
                uint i = y * w + x;
                Stencil s = loadStencil(x, y, w, h, pc.cOff);
                float d = stencilDiag(s);
                float invD = d > 0.0 ? 1.0 / d : 0.0;
                bool fromR = !flag(kPoissonFlagToR);
                uint xW = x > 0u ? x - 1u : x, xE = x + 1u < w ? x + 1u : x;
                uint yN = y > 0u ? y - 1u : y, yS = y + 1u < h ? y + 1u : y;
                for (uint c = 0u; c < 3u; ++c) {
                    uint o = c * n;
                    float b = B[pc.bOff + o + i];
                    float xi = jacobiValue(o + i, x, y, c, fromR);
                    float r = b - applyStencil(s, xi, jacobiValue(o + s.iW, xW, y, c, fromR),
                                               jacobiValue(o + s.iE, xE, y, c, fromR),
                                               jacobiValue(o + s.iN, x, yN, c, fromR),
                                               jacobiValue(o + s.iS, x, yS, c, fromR));
                    float xNew = xi + pc.omega * r * invD;
                    if (flag(kPoissonFlagToR))
                        R[pc.rOff + o + i] = xNew;
                    else
                        X[pc.xOff + o + i] = xNew;
                    dotv[c] += b * xNew;
                }
            }
        }
    }
    if (dot) writePartials(dotv, kPoissonSlotRZ);
}
