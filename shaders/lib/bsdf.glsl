// bsdf.glsl — glTF 2.0 metallic-roughness BSDF (+KHR_materials_specular) in a local shading
// frame, shared by the kernels and the CPU tests.
//
// Frame: z = shading normal; wo points to the viewer, wi to the light; both are unit vectors
// in local space. Only reflection is modelled: anything with wo.z <= 0 or wi.z <= 0 is zero.
//
// Model (glTF 2.0 spec Appendix B, with KHR_materials_specular's specular/specularColor):
//   f = (1-m) [ T_o T_i c/pi + s F_d D G / (4 |cos_o| |cos_i|) ]
//     +  m    F_m D G / (4 |cos_o| |cos_i|)
// with c = baseColor, m = metallic, s = specular, T_x = 1 - s maxComponent(F_d(cos_x)) (see
// diffuseWeight for why this replaces glTF's 1 - s maxComponent(F_d(v.h))),
//   F_d = Schlick(F0_d, v.h), F0_d = min(((ior-1)/(ior+1))^2 specularColor, 1),
//   F_m = Schlick(c, v.h), Schlick(F0, x) = F0 + (1 - F0)(1 - x)^5   (Schlick 1994),
//   D   = GGX / Trowbridge-Reitz (Walter et al. 2007, eq. 33),
//   G   = Smith height-correlated masking-shadowing (Heitz 2014, eq. 99), exact for GGX.
// Both specular terms share D and G, so they form ONE glossy lobe whose Fresnel colour is
// F_spec(h) = (1-m) s F_d(h) + m F_m(h); the diffuse lobe is the first bracketed term.
// With s = 0 and m = 0 the BSDF is exactly Lambertian c/pi.
// alpha < kDeltaAlpha turns the glossy lobe into a perfect mirror (Dirac) whose weight is
// F_spec evaluated at h = n (v.h = cos_o).
#ifndef GDPT_LIB_BSDF
#define GDPT_LIB_BSDF

#include "common.glsl"
#include "sampling.glsl"

// False where no material has a specular lobe (every metallic and specular factor is 0:
// scene_buffers.glsl defines it as the specialisation constant kHasSpecularLobe). The GGX
// code then compiles away; with m = s = 0 the results are the same bits. On lavapipe before
// Mesa 23, which runs every branch under lane masks, an untaken lobe still costs its time.
#ifndef GDPT_BSDF_SPECULAR
#define GDPT_BSDF_SPECULAR true
#endif

GDPT_NAMESPACE_BEGIN

GDPT_CONST uint kLobeDiffuse = 0u;   // Lambertian part
GDPT_CONST uint kLobeGlossy = 1u;    // GGX microfacet part (alpha >= kDeltaAlpha)
GDPT_CONST uint kLobeSpecular = 2u;  // Dirac mirror (alpha < kDeltaAlpha)

// GGX alpha below this is treated as a perfect mirror (perceptual roughness < 0.01). Above
// it, D stays well-conditioned in float because it is evaluated in the sin^2 form below.
GDPT_CONST float kDeltaAlpha = 1e-4f;
// Lobe-selection probabilities are kept in [kMinLobeProb, 1 - kMinLobeProb] whenever both
// lobes are present, so a lobe whose albedo estimate underrates it is still sampled.
GDPT_CONST float kMinLobeProb = 0.05f;

struct BsdfParams {
    vec3 baseColor;      // linear RGB albedo / metal F0, clamped to [0,1]
    float metallic;      // [0,1]
    float alpha;         // GGX alpha = roughness^2; exactly 0 means Dirac mirror
    float specular;      // KHR_materials_specular factor [0,1]
    vec3 specularColor;  // KHR_materials_specular colour (>= 0)
    float ior;           // index of refraction used for F0 of the dielectric part (>= 0)
};

struct BsdfSample {
    vec3 wi;      // sampled direction, local space
    vec3 weight;  // f |cos_i| / pdf (for kLobeSpecular: Dirac weight / selection probability)
    float pdf;    // solid-angle pdf of the whole non-Dirac mixture; for kLobeSpecular the
                  // discrete probability of choosing the mirror lobe
    uint lobe;    // kLobeDiffuse, kLobeGlossy or kLobeSpecular
};

GDPT_INLINE BsdfParams makeBsdfParams(vec3 baseColor, float metallic, float roughness,
                                      float specular, vec3 specularColor, float ior) {
    BsdfParams p;
    p.baseColor = clamp(baseColor, vec3(0.0f), vec3(1.0f));
    p.metallic = clamp(metallic, 0.0f, 1.0f);
    float r = clamp(roughness, 0.0f, 1.0f);
    p.alpha = r * r < kDeltaAlpha ? 0.0f : r * r;
    p.specular = clamp(specular, 0.0f, 1.0f);
    p.specularColor = max(specularColor, vec3(0.0f));
    p.ior = max(ior, 0.0f);
    return p;
}

// ---------------------------------------------------------------------------------------------
// Building blocks
// ---------------------------------------------------------------------------------------------

GDPT_INLINE vec3 schlickFresnel(vec3 f0, float cosTheta) {
    float x = 1.0f - clamp(cosTheta, 0.0f, 1.0f);
    float x2 = x * x;
    return f0 + (vec3(1.0f) - f0) * (x2 * x2 * x);
}

// F0 of the dielectric part before the specular factor (KHR_materials_specular).
GDPT_INLINE vec3 dielectricF0(BsdfParams m) {
    float r = (m.ior - 1.0f) / max(m.ior + 1.0f, 1e-6f);
    return min(r * r * m.specularColor, vec3(1.0f));
}

// GGX normal distribution for a unit local half vector (Walter et al. 2007, eq. 33), written
// as alpha^2 / (pi (sin^2 + alpha^2 cos^2)^2) so small alpha does not cancel catastrophically.
GDPT_INLINE float ggxD(float alpha, vec3 h) {
    float d = 0.0f;
    if (!(h.z <= 0.0f)) {
        float a2 = alpha * alpha;
        float den = h.x * h.x + h.y * h.y + a2 * h.z * h.z;
        d = a2 / max(kPi * den * den, 1e-30f);
    }
    return d;
}

// Smith Lambda for GGX (Heitz 2014, eq. 72): (-1 + sqrt(1 + alpha^2 tan^2)) / 2.
GDPT_INLINE float ggxLambda(float alpha, vec3 w) {
    float cos2 = w.z * w.z;
    float lambda = 1e30f;
    if (!(cos2 <= 0.0f)) {
        float a2tan2 = alpha * alpha * (w.x * w.x + w.y * w.y) / cos2;
        lambda = 0.5f * (sqrt(1.0f + a2tan2) - 1.0f);
    }
    return lambda;
}

GDPT_INLINE float ggxG1(float alpha, vec3 w) {
    return 1.0f / (1.0f + ggxLambda(alpha, w));
}

// Height-correlated masking-shadowing (Heitz 2014, eq. 99).
GDPT_INLINE float ggxG2(float alpha, vec3 wo, vec3 wi) {
    return 1.0f / (1.0f + ggxLambda(alpha, wo) + ggxLambda(alpha, wi));
}

// Visible-normal sampling of GGX (Heitz 2018, "Sampling the GGX Distribution of Visible
// Normals", JCGT 7(4), Listing 1), isotropic alpha. Returns h with pdf
// D_wo(h) = G1(wo) max(0, wo.h) D(h) / cos_o. Chosen over D cos sampling because the
// resulting weight F G2 / G1(wo) is bounded by F (no spikes at grazing wo) and it never
// produces back-facing microfacets.
GDPT_INLINE vec3 sampleGgxVisibleNormal(float alpha, vec3 wo, vec2 u) {
    vec3 vh = normalize(vec3(alpha * wo.x, alpha * wo.y, wo.z));  // stretch to alpha = 1
    float lensq = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = lensq > 0.0f ? vec3(-vh.y, vh.x, 0.0f) * inversesqrt(lensq) : vec3(1.0f, 0.0f, 0.0f);
    vec3 t2 = cross(vh, t1);
    float r = sqrt(u.x);
    float phi = kTwoPi * u.y;
    float p1 = r * cos(phi);
    float p2 = r * sin(phi);
    float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * safeSqrt(1.0f - p1 * p1) + s * p2;  // warp to the projected hemisphere
    vec3 nh = p1 * t1 + p2 * t2 + safeSqrt(1.0f - p1 * p1 - p2 * p2) * vh;
    return normalize(vec3(alpha * nh.x, alpha * nh.y, max(nh.z, 1e-7f)));  // unstretch
}

// Fresnel colour of the glossy/mirror lobe, F_spec = (1-m) s F_d + m F_m, at v.h = cosVh.
GDPT_INLINE vec3 glossyFresnel(BsdfParams m, float cosVh) {
    return (1.0f - m.metallic) * m.specular * schlickFresnel(dielectricF0(m), cosVh) +
           m.metallic * schlickFresnel(m.baseColor, cosVh);
}

// Weight of the diffuse lobe: (1-m) (1 - s max F_d(cos_o)) (1 - s max F_d(cos_i)).
// Deliberate deviation from glTF Appendix B, which uses (1 - s max F_d(v.h)): with the half
// vector the white-furnace albedo of a smooth coated diffuse reaches 1.85 at 89 degrees
// (mirror F(cos_o) -> 1 while the diffuse directions keep v.h ~ 0.7). The product of the
// two directional transmittances is reciprocal, equals glTF's weight to first order at
// normal incidence, is exact for s = 0 (pure Lambertian), and bounds the albedo by
// F(cos_o) + (1 - F(cos_o)) = 1 for the mirror case (Ashikhmin & Shirley 2000 use the same
// kind of coupling).
GDPT_INLINE float diffuseWeight(BsdfParams m, float cosO, float cosI) {
    float w = 1.0f - m.metallic;  // s = 0: T_o = T_i = 1
    if (GDPT_BSDF_SPECULAR) {
        vec3 f0 = dielectricF0(m);
        float to = 1.0f - m.specular * maxComponent(schlickFresnel(f0, cosO));
        float ti = 1.0f - m.specular * maxComponent(schlickFresnel(f0, cosI));
        w = (1.0f - m.metallic) * to * ti;
    }
    return w;
}

// Structural presence of each lobe (independent of wo).
GDPT_INLINE bool bsdfHasDiffuse(BsdfParams m) {
    return m.metallic < 1.0f && maxComponent(m.baseColor) > 0.0f;
}

GDPT_INLINE bool bsdfHasGlossyOrMirror(BsdfParams m) {
    return GDPT_BSDF_SPECULAR && (m.metallic > 0.0f || m.specular > 0.0f);
}

GDPT_INLINE bool bsdfHasDelta(BsdfParams m) {
    return m.alpha < kDeltaAlpha && bsdfHasGlossyOrMirror(m);
}

GDPT_INLINE bool bsdfIsDeltaOnly(BsdfParams m) {
    return bsdfHasDelta(m) && !bsdfHasDiffuse(m);
}

// Probability of choosing the glossy/mirror lobe for this wo. Each lobe's albedo is estimated
// by replacing v.h with cos_o in the Fresnel terms (exact at normal incidence and for the
// mirror): diffuse ~ (1-m)(1 - s max F_d) lum(c), glossy ~ lum(F_spec). The ratio is then
// clamped to [kMinLobeProb, 1-kMinLobeProb] if both lobes exist. Depends on wo only, so
// bsdfPdf and bsdfSample agree.
GDPT_INLINE float glossySelectProb(BsdfParams m, vec3 wo) {
    bool hasDiffuse = bsdfHasDiffuse(m);
    bool hasGlossy = bsdfHasGlossyOrMirror(m);
    float p = hasGlossy ? 1.0f : 0.0f;
    if (hasGlossy && hasDiffuse) {
        float cosO = clamp(wo.z, 0.0f, 1.0f);
        // The (1 - s max F(cos_i)) factor of the diffuse weight averages to about 0.9 for
        // F0 = 0.04; it is left out (overestimating diffuse slightly is harmless).
        float wDiffuse = (1.0f - m.metallic) * (1.0f - m.specular * maxComponent(
                         schlickFresnel(dielectricF0(m), cosO))) * luminance(m.baseColor);
        float wGlossy = luminance(glossyFresnel(m, cosO));
        float sum = wDiffuse + wGlossy;
        p = clamp(sum > 0.0f ? wGlossy / sum : 0.5f, kMinLobeProb, 1.0f - kMinLobeProb);
    }
    return p;
}

// ---------------------------------------------------------------------------------------------
// Public API
// ---------------------------------------------------------------------------------------------

// f(wo, wi) |cos_i| of the non-Dirac lobes; zero unless both directions are in the upper
// hemisphere. The diffuse weight uses v.h of the actual half vector, which keeps f reciprocal.
// (Both functions have a single exit, so that spirv-opt inlines their many call sites before
// the driver instead of lavapipe: bench/RESULTS.md, "Offset loops unrolled before the driver".)
GDPT_INLINE vec3 bsdfEval(BsdfParams m, vec3 wo, vec3 wi) {
    vec3 result = vec3(0.0f);
    vec3 h = wo + wi;
    float hLen2 = dot(h, h);
    if (wo.z > 0.0f && wi.z > 0.0f && isFinite(wo) && isFinite(wi) && hLen2 > 1e-20f) {
        h = h * inversesqrt(hLen2);
        float cosVh = max(dot(wo, h), 0.0f);
        result = diffuseWeight(m, wo.z, wi.z) * m.baseColor * (kInvPi * wi.z);
        if (m.alpha >= kDeltaAlpha && bsdfHasGlossyOrMirror(m)) {
            // F D G2 / (4 cos_o cos_i) * cos_i
            float dg = ggxD(m.alpha, h) * ggxG2(m.alpha, wo, wi) / (4.0f * wo.z);
            result += glossyFresnel(m, cosVh) * dg;
        }
        if (!isFinite(result)) result = vec3(0.0f);
    }
    return result;
}

// Solid-angle pdf with which bsdfSample returns wi through a non-Dirac lobe, including the
// lobe-selection probabilities: (1-pG) cos_i/pi + pG G1(wo) D(h) / (4 cos_o)  (VNDF pdf of
// wi = D_wo(h) / (4 wo.h), Heitz 2018 eq. 17). Zero for wi below the surface.
GDPT_INLINE float bsdfPdf(BsdfParams m, vec3 wo, vec3 wi) {
    float pdf = 0.0f;
    if (wo.z > 0.0f && wi.z > 0.0f && isFinite(wo) && isFinite(wi)) {
        float pGlossy = glossySelectProb(m, wo);
        pdf = (1.0f - pGlossy) * wi.z * kInvPi;
        if (m.alpha >= kDeltaAlpha && pGlossy > 0.0f) {
            vec3 h = wo + wi;
            float hLen2 = dot(h, h);
            if (hLen2 > 1e-20f) {
                h = h * inversesqrt(hLen2);
                pdf += pGlossy * ggxG1(m.alpha, wo) * ggxD(m.alpha, h) / (4.0f * wo.z);
            }
        }
        if (!isFinite(pdf)) pdf = 0.0f;
    }
    return pdf;
}

// Samples wi given wo and three uniform numbers: u.x selects the lobe, u.y/u.z drive the
// warp. For non-Dirac lobes weight = bsdfEval / bsdfPdf (one-sample MIS over the lobes, so
// the weight does not depend on which lobe produced wi). Returns false (with a zero weight)
// if wo is below the surface or the sampled direction is below the surface.
GDPT_INLINE bool bsdfSample(BsdfParams m, vec3 wo, vec3 u, GDPT_OUT(BsdfSample) s) {
    s.wi = vec3(0.0f, 0.0f, 1.0f);
    s.weight = vec3(0.0f);
    s.pdf = 0.0f;
    s.lobe = kLobeDiffuse;
    if (!(wo.z > 0.0f) || !isFinite(wo)) {
        return false;
    }
    float pGlossy = glossySelectProb(m, wo);
    if (GDPT_BSDF_SPECULAR && u.x < pGlossy) {  // pGlossy = 0 without the lobe
        if (m.alpha < kDeltaAlpha) {
            // Perfect mirror: h = n, so v.h = cos_o; Dirac weight F_spec / P(select).
            s.wi = vec3(-wo.x, -wo.y, wo.z);
            s.lobe = kLobeSpecular;
            s.pdf = pGlossy;
            s.weight = glossyFresnel(m, wo.z) / pGlossy;
            return true;
        }
        vec3 h = sampleGgxVisibleNormal(m.alpha, wo, vec2(u.y, u.z));
        s.wi = 2.0f * dot(wo, h) * h - wo;  // reflect wo about h
        s.lobe = kLobeGlossy;
    } else {
        s.wi = sampleCosineHemisphere(vec2(u.y, u.z));
        s.lobe = kLobeDiffuse;
    }
    if (!(s.wi.z > 0.0f)) {
        return false;
    }
    s.pdf = bsdfPdf(m, wo, s.wi);
    if (!(s.pdf > 0.0f)) {
        return false;
    }
    s.weight = bsdfEval(m, wo, s.wi) / s.pdf;
    if (!isFinite(s.weight)) {
        s.weight = vec3(0.0f);
        return false;
    }
    return true;
}

// Roughness used by gradient-domain shift mappings to classify the vertex by the lobe that
// the base path sampled (Kettunen et al. 2015, §4.2 / Manzi et al. 2015): a diffuse vertex
// counts as fully rough (1), a mirror vertex as smooth (0), a glossy vertex by its
// perceptual roughness sqrt(alpha).
GDPT_INLINE float bsdfRoughnessForShift(BsdfParams m, uint sampledLobe) {
    if (sampledLobe == kLobeDiffuse) {
        return 1.0f;
    }
    if (sampledLobe == kLobeSpecular || m.alpha < kDeltaAlpha) {
        return 0.0f;
    }
    return sqrt(m.alpha);
}

GDPT_NAMESPACE_END

#endif  // GDPT_LIB_BSDF
