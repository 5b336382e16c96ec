// gpt_light.glsl — next-event estimation of an offset path with the base's light point
// (Kettunen et al. 2015 §4.2). GLSL only: needs the scene buffers and
// scene_access.glsl. Kept out of scene_access.glsl, which the PT kernel shares.
#ifndef GDPT_LIB_GPT_LIGHT
#define GDPT_LIB_GPT_LIGHT

// Punctual light chosen by sampleLight for the uniform ul.x (the same mapping, which
// LightSample does not record).
uint gptPunctualIndex(float ux) {
    float pTri = lightTriangleSelectProb();
    float uu = (ux - pTri) / (1.0 - pTri);
    return min(uint(uu * float(scene.numPunctualLights)), scene.numPunctualLights - 1u);
}

// The offset vertex at pOffset reconnects to the base's light sample `ls` (drawn with the
// uniforms ul from the base vertex pBase): radiance arriving at the offset along wiOffset
// (unit, towards the light, distance distOffset) and the Jacobian of the light vertex
// shift. Area light: the same point, so Li is unchanged (same uv) and
//   J = (|cos θ'_light| / |cos θ_light|) (d² / d'²)    (shift.glsl reconnectionJacobian);
// punctual light: the point has no degree of freedom (J = 1) and Li' = I·falloff'/d'².
// Returns false where the base sampler would have rejected the offset's sample (light
// facing away from a one-sided emitter, grazing), i.e. the offset has zero density.
bool gptOffsetLight(LightSample ls, vec3 ul, vec3 pBase, vec3 pOffset, vec3 wiOffset, float distOffset,
                    out vec3 liOffset, out float jacobianLight) {
    liOffset = vec3(0.0);
    jacobianLight = 0.0;
    if (ls.isDelta == 0u) {
        float cosL = dot(ls.nLight, -wiOffset);
        bool twoSided = (material(triangleShading(ls.triangle).material).flags & kMatFlagDoubleSided) != 0u;
        if ((cosL <= 0.0 && !twoSided) || abs(cosL) <= 1e-7) return false;
        jacobianLight = reconnectionJacobian(pBase, pOffset, ls.pLight, ls.nLight);
        liOffset = ls.Li;
        return jacobianLight > 0.0;
    }
    if (!kHasPunctual) return false;
    PunctualLight l = punctualLight(gptPunctualIndex(ul.x));
    float falloff = 1.0;
    if (l.type == kPunctualSpot) {
        // glTF KHR_lights_punctual smooth cone falloff, as sampleLight.
        float c = dot(-wiOffset, l.direction);
        falloff = clamp((c - l.cosOuter) / max(l.cosInner - l.cosOuter, 1e-4), 0.0, 1.0);
        falloff *= falloff;
    }
    liOffset = l.intensity * falloff / (distOffset * distOffset);
    jacobianLight = 1.0;
    return true;
}

#endif  // GDPT_LIB_GPT_LIGHT
