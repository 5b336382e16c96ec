// ray.glsl — robust spawning of secondary rays (GLSL/C++ common subset).
//
// Self-intersection is avoided by moving the ray origin off the surface along the geometric
// normal by a few float ulps of the hit position (Wächter & Binder, "A Fast and Robust
// Method for Avoiding Self-Intersection", Ray Tracing Gems ch. 6, 2019), instead of a fixed
// epsilon: the offset scales with the magnitude of the coordinates, so it works for scenes
// from 1e-4 to 1e5 units alike.
#ifndef GDPT_LIB_RAY
#define GDPT_LIB_RAY

#include "common.glsl"

GDPT_NAMESPACE_BEGIN

GDPT_CONST float kRayOrigin = 1.0f / 32.0f;     // below this magnitude use a fixed offset
GDPT_CONST float kRayFloatScale = 1.0f / 65536.0f;
GDPT_CONST float kRayIntScale = 256.0f;          // ulps moved per unit of normal

// Offsets component c of p by `ulps` units in the last place in the direction of sign(n).
// Near the origin, where ulps are tiny, a fixed offset is used instead; Wächter & Binder's
// constants assume scenes of unit size, so that fixed offset and its threshold are scaled
// by the scene's size (found by the stress suite: a Cornell box scaled to 0.2 mm was
// visibly wrong with a fixed 1/65536 offset).
GDPT_INLINE float offsetComponent(float p, float n, float sceneScale) {
    int ulps = int(kRayIntScale * n);
    float moved = intBitsToFloat(floatBitsToInt(p) + (p < 0.0f ? -ulps : ulps));
    return abs(p) < kRayOrigin * sceneScale ? p + kRayFloatScale * sceneScale * n : moved;
}

// Origin for a ray leaving the surface at p on the side of the (unit) geometric normal n,
// in a scene of about `sceneScale` units (e.g. its bounding radius; 1 = the published
// constants). Callers pass n flipped towards the side the new ray travels into.
GDPT_INLINE vec3 offsetRayOriginScaled(vec3 p, vec3 n, float sceneScale) {
    return vec3(offsetComponent(p.x, n.x, sceneScale), offsetComponent(p.y, n.y, sceneScale),
                offsetComponent(p.z, n.z, sceneScale));
}

GDPT_INLINE vec3 offsetRayOrigin(vec3 p, vec3 n) {
    return offsetRayOriginScaled(p, n, 1.0f);
}

GDPT_NAMESPACE_END

#endif  // GDPT_LIB_RAY
