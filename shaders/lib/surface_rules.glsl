// surface_rules.glsl — the two rules behind G-PT's first-hit demodulation, shared by the
// kernels and the host (C++ view in gdpt::gpu, as common.glsl explains):
//   probeHitsAgree: two probe hits lie on one surface (edge.comp's test between the probe
//       points of a pixel; demodulationMask's between two pixels' first probes);
//   modulatesLambertian: a material's BSDF is its base-colour texture times the rest, so a
//       first hit there can be demodulated (gpt.comp's firstHitModulation;
//       demodulationApplies on the host).
#ifndef GDPT_LIB_SURFACE_RULES
#define GDPT_LIB_SURFACE_RULES

#include "../shared/gpt_shared.h"
#include "common.glsl"

GDPT_NAMESPACE_BEGIN

// Same material, normals within kEdgeNormalCos, and b no further off a's tangent plane than
// kEdgeTangentSlope times its distance within that plane (a step in depth between parallel
// faces fails this).
GDPT_INLINE bool probeHitsAgree(uint materialA, vec3 pA, vec3 nA, uint materialB, vec3 pB, vec3 nB) {
    if (materialA != materialB || dot(nB, nA) < kEdgeNormalCos) return false;
    vec3 e = pB - pA;
    return abs(dot(nA, e)) <= kEdgeTangentSlope * length(e - dot(nA, e) * nA);
}

// A base-colour texture on a Lambertian-only BSDF: no metal, no specular layer, no texture
// that could make it metallic.
GDPT_INLINE bool modulatesLambertian(Material m) {
    return m.baseColorTex >= 0 && m.metallic == 0.0f && m.specular == 0.0f && m.metallicRoughnessTex < 0;
}

GDPT_NAMESPACE_END

#endif  // GDPT_LIB_SURFACE_RULES
