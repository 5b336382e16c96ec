// sampling.glsl — warps from [0,1)^2 to common domains, their pdfs and inverses, shading
// frames and the MIS power heuristic. Shared by the kernels and the CPU tests.
//
// Conventions: local shading space is z-up (z = shading normal); "pdf" is with respect to
// solid angle (per steradian) for directions and to area on the unit disk for disk points.
#ifndef GDPT_LIB_SAMPLING
#define GDPT_LIB_SAMPLING

#include "common.glsl"

GDPT_NAMESPACE_BEGIN

// ---------------------------------------------------------------------------------------------
// Orthonormal basis
// ---------------------------------------------------------------------------------------------

// Right-handed basis (t, b, n) around unit n, branch-free except for the sign of n.z.
// Duff et al. 2017, "Building an Orthonormal Basis, Revisited" (JCGT 6(1)), Listing 3.
GDPT_INLINE void makeBasis(vec3 n, GDPT_OUT(vec3) t, GDPT_OUT(vec3) b) {
    float s = n.z >= 0.0f ? 1.0f : -1.0f;
    float a = -1.0f / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

// World -> local (t, b, n) and back; the basis is orthonormal so the inverse is the transpose.
GDPT_INLINE vec3 toLocal(vec3 v, vec3 t, vec3 b, vec3 n) {
    return vec3(dot(v, t), dot(v, b), dot(v, n));
}

GDPT_INLINE vec3 toWorld(vec3 v, vec3 t, vec3 b, vec3 n) {
    return t * v.x + b * v.y + n * v.z;
}

// ---------------------------------------------------------------------------------------------
// Disk
// ---------------------------------------------------------------------------------------------

// Shirley & Chiu 1997, "A Low Distortion Map Between Disk and Square": concentric squares
// map to concentric circles, area-preserving (pdf = 1/pi on the unit disk).
GDPT_INLINE vec2 sampleConcentricDisk(vec2 u) {
    float ox = 2.0f * u.x - 1.0f;
    float oy = 2.0f * u.y - 1.0f;
    if (ox == 0.0f && oy == 0.0f) {
        return vec2(0.0f);
    }
    float r;
    float theta;
    if (abs(ox) > abs(oy)) {
        r = ox;
        theta = kPiOver4 * (oy / ox);
    } else {
        r = oy;
        theta = kPiOver2 - kPiOver4 * (ox / oy);
    }
    return r * vec2(cos(theta), sin(theta));
}

// Inverse of sampleConcentricDisk. In the |x| >= |y| wedges the angle modulo pi is
// atan(y/x) = (pi/4) oy/ox; otherwise pi/2 - angle = atan(x/y) = (pi/4) ox/oy. The sign of
// the dominant coordinate recovers the signed radius.
GDPT_INLINE vec2 invertConcentricDisk(vec2 p) {
    float r = sqrt(p.x * p.x + p.y * p.y);
    float ox;
    float oy;
    if (r == 0.0f) {
        return vec2(0.5f);
    }
    if (abs(p.x) >= abs(p.y)) {
        ox = p.x >= 0.0f ? r : -r;
        oy = ox * atan(p.y / p.x) / kPiOver4;
    } else {
        oy = p.y >= 0.0f ? r : -r;
        ox = oy * atan(p.x / p.y) / kPiOver4;
    }
    return clamp(vec2(0.5f * (ox + 1.0f), 0.5f * (oy + 1.0f)), vec2(0.0f), vec2(kOneMinusEpsilon));
}

// ---------------------------------------------------------------------------------------------
// Hemisphere and sphere (local z-up)
// ---------------------------------------------------------------------------------------------

// Malley's method: project a uniform disk point up to the hemisphere; pdf = cos(theta)/pi.
GDPT_INLINE vec3 sampleCosineHemisphere(vec2 u) {
    vec2 d = sampleConcentricDisk(u);
    float z = safeSqrt(1.0f - d.x * d.x - d.y * d.y);
    return vec3(d.x, d.y, z);
}

GDPT_INLINE float cosineHemispherePdf(float cosTheta) {
    return cosTheta > 0.0f ? cosTheta * kInvPi : 0.0f;
}

GDPT_INLINE vec2 invertCosineHemisphere(vec3 w) {
    return invertConcentricDisk(vec2(w.x, w.y));
}

// Uniform on the unit sphere: z uniform in [-1,1] (Archimedes), phi uniform; pdf = 1/(4 pi).
GDPT_INLINE vec3 sampleUniformSphere(vec2 u) {
    float z = 1.0f - 2.0f * u.x;
    float r = safeSqrt(1.0f - z * z);
    float phi = kTwoPi * u.y;
    return vec3(r * cos(phi), r * sin(phi), z);
}

GDPT_INLINE float uniformSpherePdf() {
    return kInv4Pi;
}

GDPT_INLINE vec2 invertUniformSphere(vec3 w) {
    float phi = atan(w.y, w.x);
    phi = phi < 0.0f ? phi + kTwoPi : phi;
    return clamp(vec2(0.5f * (1.0f - w.z), phi * kInv2Pi), vec2(0.0f), vec2(kOneMinusEpsilon));
}

// Uniform on the upper hemisphere: z uniform in [0,1]; pdf = 1/(2 pi).
GDPT_INLINE vec3 sampleUniformHemisphere(vec2 u) {
    float z = u.x;
    float r = safeSqrt(1.0f - z * z);
    float phi = kTwoPi * u.y;
    return vec3(r * cos(phi), r * sin(phi), z);
}

GDPT_INLINE float uniformHemispherePdf() {
    return kInv2Pi;
}

// ---------------------------------------------------------------------------------------------
// Triangle
// ---------------------------------------------------------------------------------------------

// Uniform barycentrics (b0, b1, b2), p = b0 v0 + b1 v1 + b2 v2, by the square-root
// parameterisation (Osada et al. 2002, eq. 1; pbrt-v3 §13.6.5): b0 = 1 - sqrt(u0),
// b1 = u1 sqrt(u0). Chosen over Heitz 2019 because its inverse is closed-form and exact.
GDPT_INLINE vec3 sampleUniformTriangle(vec2 u) {
    float su = sqrt(u.x);
    // b2 computed directly (not as 1 - b0 - b1) so that b1 + b2 == sqrt(u0) to rounding and
    // the inverse stays accurate near the vertex v0.
    return vec3(1.0f - su, u.y * su, (1.0f - u.y) * su);
}

// Inverse of sampleUniformTriangle: sqrt(u0) = 1 - b0 = b1 + b2, u1 = b1 / (b1 + b2).
GDPT_INLINE vec2 invertUniformTriangle(vec3 bary) {
    float su = bary.y + bary.z;
    float u1 = su > 0.0f ? bary.y / su : 0.0f;
    return clamp(vec2(su * su, u1), vec2(0.0f), vec2(kOneMinusEpsilon));
}

// ---------------------------------------------------------------------------------------------
// Multiple importance sampling
// ---------------------------------------------------------------------------------------------

// Power heuristic with beta = 2 (Veach 1997, eq. 9.13): w_f = (nf fPdf)^2 / sum of squares.
// Evaluated in ratio form so that it neither overflows (pdfs of near-Dirac GGX lobes reach
// 1e20+, whose squares are Inf in float) nor underflows: the smaller term is divided by the
// larger, so the squared quantity is always in [0, 1]. Returns 0 when nf fPdf is 0 or NaN,
// 1 when ng gPdf is 0 and nf fPdf > 0.
GDPT_INLINE float powerHeuristic(float nf, float fPdf, float ng, float gPdf) {
    float f = nf * fPdf;
    float g = ng * gPdf;
    if (!(f > 0.0f)) {
        return 0.0f;
    }
    if (!(g > 0.0f)) {
        return 1.0f;
    }
    if (f >= g) {
        float r = g / f;  // in [0,1]; Inf/Inf cannot occur since f >= g and f may be Inf
        return isFinite(r) ? 1.0f / (1.0f + r * r) : 0.5f;
    }
    float r = f / g;
    return isFinite(r) ? r * r / (1.0f + r * r) : 0.5f;
}

// Power heuristic from the single ratio rho = (ng gPdf) / (nf fPdf) of the competing to the
// own weighted pdf: w = 1 / (1 + rho^2). Useful when only the ratio is known stably (e.g.
// the ratio of two pdfs that share a huge common factor). rho = +Inf gives 0 and
// rho = 0 gives 1; for rho > 2^64 the square is Inf and the result is 0, which is the
// correctly rounded float answer. NaN rho yields 0.
GDPT_INLINE float powerHeuristicRatio(float rho) {
    if (!(rho >= 0.0f)) {
        return 0.0f;
    }
    return 1.0f / (1.0f + rho * rho);
}

GDPT_NAMESPACE_END

#endif  // GDPT_LIB_SAMPLING
