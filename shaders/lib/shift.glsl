// shift.glsl — the pure mathematics of the gradient-domain shift mapping (Kettunen et al.
// 2015, "Gradient-Domain Path Tracing", §4; Lehtinen et al. 2013, "Gradient-Domain
// Metropolis Light Transport", §5), in the GLSL/C++ common subset so the CPU unit tests run
// exactly the code gpt.comp runs.
//
// Conventions (as bsdf.glsl): local shading space is z-up; `wo` points from a vertex back
// towards the previous vertex (the camera side), `wi` is the direction the path continues
// in (the sampled direction). All pdfs are per steradian (pdfSolidAngle) unless the name
// says otherwise; Dirac lobes use their discrete selection probability.
//
// Ratio form (gdpt's own formulation of the same weights): a path's pdf product can
// underflow float32 after a few bounces, so gpt.comp never forms it. It carries, per
// offset, the throughput f'/p (offset measurement contribution divided by the BASE path's
// pdf, Jacobians included) and the ratio r = J·p'/p of the offset path's density (in the
// base's measure) to the base's. MIS weights are written in terms of per-segment pdfs and
// that ratio.
#ifndef GDPT_LIB_SHIFT
#define GDPT_LIB_SHIFT

#include "common.glsl"
#include "sampling.glsl"
#include "bsdf.glsl"

GDPT_NAMESPACE_BEGIN

// Connection status of an offset path (Kettunen et al. 2015 §4.2, as in the authors'
// Mitsuba implementation).
GDPT_CONST uint kShiftNotConnected = 0u;       // offset has its own vertices so far
GDPT_CONST uint kShiftRecentlyConnected = 1u;  // offset reconnected to the base's current vertex
GDPT_CONST uint kShiftConnected = 2u;          // offset shares every later vertex with the base

// ---------------------------------------------------------------------------------------------
// Vertex classification (Kettunen et al. 2015 §4.2)
// ---------------------------------------------------------------------------------------------

// Lowest roughness over all components present (Mitsuba's BSDF::EAll): gpt.comp's
// classification of every vertex (see roughAll in gpt_path.glsl for why not the sampled
// component's). A Dirac layer counts as 0. A BSDF with
// no lobe at all (a black emitter) is rough: nothing can be half-vector shifted through it.
GDPT_INLINE float shiftRoughnessAll(BsdfParams m) {
    float roughness = 1.0f;
    if (bsdfHasGlossyOrMirror(m)) roughness = m.alpha < kDeltaAlpha ? 0.0f : sqrt(m.alpha);
    return roughness;
}

// "Diffuse" (reconnectable) iff roughness > threshold (threshold: GptFrameParams::shiftThreshold).
GDPT_INLINE bool shiftIsRough(float roughness, float threshold) {
    return roughness > threshold;
}

// Reconnection shift iff base current, base next and offset current vertices are all rough
// (Kettunen et al. 2015 §4.2); otherwise the half-vector copy shift.
GDPT_INLINE bool shiftUseReconnection(bool baseCurRough, bool baseNextRough, bool offsetCurRough) {
    return baseCurRough && baseNextRough && offsetCurRough;
}

// Invertibility of a half-vector step: the reverse shift (offset path as base) reconnects iff
// its current vertex (the offset's), its next vertex (the offset's new one) and its offset
// vertex (the base's current one) are all rough. Then the forward half-vector step has no
// inverse and must fail (Kettunen et al. 2015 §4.2: a shift must be
// invertible for the pair's weights to sum to one).
GDPT_INLINE bool shiftHalfVectorInvertible(bool baseCurRough, bool offsetCurRough, bool offsetNextRough) {
    return !(baseCurRough && offsetCurRough && offsetNextRough);
}

// ---------------------------------------------------------------------------------------------
// Jacobians (Kettunen et al. 2015 §4.2, eqs. 11–12)
// ---------------------------------------------------------------------------------------------

// Reconnection shift: the base continues from baseFrom to `target` (geometric normal
// targetNormal); the offset connects offsetFrom to the same target. The Jacobian of the map
// from the base's sampled direction to the offset's (both per steradian) is
//   |dω'/dω| = (|cos θ'_target| / |cos θ_target|) · (|target − baseFrom|² / |target − offsetFrom|²),
// i.e. the ratio of the two solid-angle-to-area conversions (Veach 1997 eq. 8.10).
// Returns 0 for a degenerate configuration (grazing base edge, coincident points).
GDPT_INLINE float reconnectionJacobian(vec3 baseFrom, vec3 offsetFrom, vec3 target, vec3 targetNormal) {
    vec3 eBase = baseFrom - target;
    vec3 eOffset = offsetFrom - target;
    float dist2Base = dot(eBase, eBase);
    float dist2Offset = dot(eOffset, eOffset);
    if (!(dist2Base > 0.0f) || !(dist2Offset > 0.0f)) {
        return 0.0f;
    }
    // |cos| = |n·e| / |e|, so the ratio is |n·e'| |e| / (|n·e| |e'|); with d² / d'² this is
    // |n·e'| |e|³ / (|n·e| |e'|³).
    float cosBaseTimesLen = abs(dot(targetNormal, eBase));
    float cosOffsetTimesLen = abs(dot(targetNormal, eOffset));
    if (!(cosBaseTimesLen > 0.0f)) {
        return 0.0f;
    }
    float lenRatio = sqrt(dist2Base / dist2Offset);  // |e| / |e'|
    float jacobianShift = (cosOffsetTimesLen / cosBaseTimesLen) * lenRatio * lenRatio * lenRatio;
    return isFinite(jacobianShift) ? jacobianShift : 0.0f;
}

// Half-vector copy shift for reflection (Kettunen et al. 2015 §4.2; Lehtinen et al. 2013
// §5.2): the base's local half vector h = normalize(woBase + wiBase) is reused at the
// offset vertex, wiOffset = reflect(-woOffset, h) = 2 (woOffset·h) h − woOffset. All vectors
// are in the respective vertex's local shading frame. Since dω_i = 4 |ω_i·h| dh for
// reflection, the Jacobian of ω_i → ω_i' at fixed h is
//   |dω_i'/dω_i| = |wiOffset·h| / |wiBase·h|            (= |ω_o'·h| / |ω_o·h| in Mitsuba's names).
// For a Dirac (mirror) lobe h = n and the Jacobian is 1 (the caller sets it; point
// evaluation). Returns false when h is undefined (wo = −wi) or the Jacobian degenerates.
GDPT_INLINE bool halfVectorReflect(vec3 woBase, vec3 wiBase, vec3 woOffset, GDPT_OUT(vec3) wiOffset,
                                   GDPT_OUT(float) jacobianShift) {
    wiOffset = vec3(0.0f, 0.0f, 1.0f);
    jacobianShift = 0.0f;
    vec3 h = woBase + wiBase;
    float hLen2 = dot(h, h);
    if (!(hLen2 > 1e-12f)) {
        return false;
    }
    h = h * inversesqrt(hLen2);
    float cosBase = abs(dot(wiBase, h));
    float woOffsetDotH = dot(woOffset, h);
    wiOffset = 2.0f * woOffsetDotH * h - woOffset;
    // Reflection about h preserves the angle: |wiOffset·h| = |woOffset·h|.
    float cosOffset = abs(woOffsetDotH);
    if (!(cosBase > 0.0f) || !(cosOffset > 0.0f)) {
        return false;
    }
    jacobianShift = cosOffset / cosBase;
    return isFinite(jacobianShift);
}

// ---------------------------------------------------------------------------------------------
// The shift mappings of one path segment (Kettunen et al. 2015 §4.2)
// ---------------------------------------------------------------------------------------------

// Where a reconnection (or environment) shift sends the offset's segment. wi: world-space
// unit direction from the offset vertex; dist: distance to the target (0 for the environment,
// which has no vertex); jacobian: |dω'/dω| of the segment's direction; ok: false where the
// shift fails (the offset path has zero density and the pair falls back to the base alone).
struct ConnectionShift {
    vec3 wi;
    float dist;
    float jacobian;
    bool ok;
};

// Reconnection shift (Kettunen et al. 2015 §4.2; Lehtinen et al. 2013 §5.1): the offset
// vertex offsetFrom (geometric normal offsetNormal) connects to the base's next vertex
// `target` (geometric normal targetNormal), which the base reached from baseFrom. It fails
// where the connection leaves below the offset's geometric surface, arrives at the other
// side of the target than the base's (another surface point for the BSDF and the emission)
// or degenerates (jacobian 0). Visibility is the caller's (a ray query).
GDPT_INLINE ConnectionShift shiftReconnect(vec3 baseFrom, vec3 offsetFrom, vec3 offsetNormal, vec3 target,
                                           vec3 targetNormal) {
    ConnectionShift c;
    vec3 e = target - offsetFrom;
    c.dist = length(e);
    c.wi = e / c.dist;
    c.jacobian = reconnectionJacobian(baseFrom, offsetFrom, target, targetNormal);
    c.ok = c.dist > 0.0f && c.jacobian > 0.0f && dot(c.wi, offsetNormal) > 0.0f &&
           dot(c.wi, targetNormal) < 0.0f;
    return c;
}

// Environment (escape) shift: the base left the scene in direction wiBase; the offset leaves
// in the same direction. The environment is a function of direction alone, so the map is the
// identity (jacobian 1); it fails where wiBase points below the offset's geometric surface.
GDPT_INLINE ConnectionShift shiftEnvironment(vec3 wiBase, vec3 offsetNormal) {
    ConnectionShift c;
    c.wi = wiBase;
    c.dist = 0.0f;
    c.jacobian = 1.0f;
    c.ok = dot(wiBase, offsetNormal) > 0.0f;
    return c;
}

// Half-vector copy shift of one sampled BSDF direction (Kettunen et al. 2015 §4.2; Lehtinen
// et al. 2013 §5.2), in the offset vertex's local frame. A base Dirac (mirror) sample maps to
// the offset's mirror direction with its Dirac weight F(cos θ_o) and discrete selection
// probability (jacobian 1); a smooth sample keeps the base's half vector (halfVectorReflect).
// Dirac and smooth never shift into each other: a base Dirac sample needs a Dirac lobe at the
// offset, a smooth one a smooth lobe. wiLocal, f (BSDF value or Dirac weight along wiLocal)
// and pdf (the offset's density of sampling wiLocal) are valid where ok.
struct HalfVectorShift {
    vec3 wiLocal;
    vec3 f;
    float pdf;
    float jacobian;
    bool ok;
};

GDPT_INLINE HalfVectorShift shiftHalfVector(BsdfParams offsetBsdf, vec3 woBase, vec3 wiBase, bool baseDirac,
                                            vec3 woOffset) {
    HalfVectorShift h;
    h.wiLocal = vec3(0.0f, 0.0f, 1.0f);
    h.f = vec3(0.0f);
    h.pdf = 0.0f;
    h.jacobian = 1.0f;
    h.ok = baseDirac ? bsdfHasDelta(offsetBsdf) : !bsdfIsDeltaOnly(offsetBsdf);
    if (h.ok && baseDirac) {
        h.wiLocal = vec3(-woOffset.x, -woOffset.y, woOffset.z);
        h.f = glossyFresnel(offsetBsdf, woOffset.z);
        h.pdf = woOffset.z > 0.0f ? glossySelectProb(offsetBsdf, woOffset) : 0.0f;
    } else if (h.ok) {
        h.ok = halfVectorReflect(woBase, wiBase, woOffset, h.wiLocal, h.jacobian);
        if (h.ok) {
            h.f = bsdfEval(offsetBsdf, woOffset, h.wiLocal);
            h.pdf = bsdfPdf(offsetBsdf, woOffset, h.wiLocal);
        }
    }
    h.ok = h.ok && h.pdf > 0.0f && h.wiLocal.z > 0.0f;
    return h;
}

// What one shifted segment does to the offset's ratio-form state (see the top of this file;
// a path's contribution, density and Jacobian are products over its segments, Kettunen et
// al. 2015 §4): with the base's density pdfBase of the sampled segment, the offset's density
// pdfOffset of its shifted segment, its BSDF value f and the segment's Jacobian J,
//   β' ← β' · f·J·rrInv / pdfBase      (offset contribution over the base's density)
//   r  ← r  · pdfOffset·J / pdfBase     (offset density in the base's measure over the base's)
// rrInv = 1/q of the base's Russian roulette, shared by the offsets.
struct SegmentShift {
    vec3 throughput;  // factor of β'
    float pdfRatio;   // factor of r
};

GDPT_INLINE SegmentShift shiftSegment(vec3 f, float pdfOffset, float jacobian, float rrInv, float pdfBase) {
    SegmentShift s;
    s.throughput = f * (jacobian * rrInv / pdfBase);
    s.pdfRatio = pdfOffset * jacobian / pdfBase;
    return s;
}

// ---------------------------------------------------------------------------------------------
// MIS between base and offset (Kettunen et al. 2015 §4; Veach 1997 ch. 9), ratio form
// ---------------------------------------------------------------------------------------------

// Power heuristic over the four strategies {own technique, other technique} × {base, offset}
// (Veach 1997 eq. 9.13 with the path-prefix pdf divided out):
//   w = pOwn² / (pOwn² + pOther² + qOwn² + qOther²)
// pOwn/pOther: the base's last-segment pdfs (e.g. BSDF and light, solid angle at the base
// vertex); qOwn/qOther: the offset's, multiplied by the prefix ratio r = J·p'/p and by the
// last segment's Jacobian, i.e. already in the base's measure. The sum is normalised by its
// largest term first, so no square overflows or underflows (GGX pdfs reach 1e20). A zero
// pOther/qOther removes that strategy. Returns 0 for pOwn <= 0 or any NaN.
//
// Sample counts: where the pair's two pixels take different numbers of samples (n_p at the
// base's pixel, n_q at the offset's: G-PT's edge samples), the caller multiplies qOwn and
// qOther (and r in gptMisWeightPair) by c = n_q / n_p, which is Veach's multi-sample power
// heuristic w_i = (n_i p_i)² / Σ_k (n_k p_k)² (Veach 1997 eq. 9.13 with n_i) divided by n_p².
// The reverse shift, sampled at q, uses 1/c, so a pair's weights still sum to 1 for any fixed
// c: the estimate stays unbiased whatever the counts are, and the better-sampled pixel carries
// more of the pair. With c = 3 and equal densities the weights are 0.9 / 0.1 instead of
// 0.5 / 0.5, and the pair's variance σ²(0.81 / 3 + 0.01) instead of σ²(0.25 / 3 + 0.25).
GDPT_INLINE float gptMisWeight(float pOwn, float pOther, float qOwn, float qOther) {
    if (!(pOwn > 0.0f) || !(pOther >= 0.0f) || !(qOwn >= 0.0f) || !(qOther >= 0.0f)) {
        return 0.0f;
    }
    float m = max(max(pOwn, pOther), max(qOwn, qOther));
    if (!isFinite(m)) {
        // Only the own pdf can win against an infinite competitor if it is the infinite one.
        return isFinite(pOwn) ? 0.0f : 1.0f;
    }
    float a = pOwn / m;
    float b = pOther / m;
    float c = qOwn / m;
    float d = qOther / m;
    // The largest term is exactly 1, so the denominator is in [1, 4].
    return a * a / (a * a + b * b + c * c + d * d);
}

// Two strategies {base, offset} of one technique (half-vector branch, environment, Dirac):
// w = p² / (p² + (J p')²) = 1 / (1 + r²) with r = J·p'/p of the whole path.
GDPT_INLINE float gptMisWeightPair(float ratioOffsetToBase) {
    return powerHeuristicRatio(ratioOffsetToBase);
}

GDPT_NAMESPACE_END

#endif  // GDPT_LIB_SHIFT
