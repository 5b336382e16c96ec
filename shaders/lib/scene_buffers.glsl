// scene_buffers.glsl — declarations of the scene's buffers (storage buffers, and the
// geometry's texel buffers of scene_geometry.glsl) and the feature specialisation
// constants, shared by every path-sampling kernel. Binding numbers and
// constant ids come from gdpt_shared.h only.
#ifndef GDPT_LIB_SCENE_BUFFERS
#define GDPT_LIB_SCENE_BUFFERS

layout(constant_id = kSpecHasTextures) const bool kHasTextures = true;
layout(constant_id = kSpecHasPunctual) const bool kHasPunctual = true;
layout(constant_id = kSpecHasLightTris) const bool kHasLightTris = true;
layout(constant_id = kSpecHasEnv) const bool kHasEnv = true;
layout(constant_id = kSpecHasGlossy) const bool kHasGlossy = true;
layout(constant_id = kSpecHasAlphaMask) const bool kHasAlphaMask = true;
layout(constant_id = kSpecMaxDepth) const uint kMaxDepth = 1024u;
layout(constant_id = kSpecHasShadingNormals) const bool kHasShadingNormals = true;

#include "scene_geometry.glsl"

layout(set = 0, binding = kBindTriShading, scalar) readonly buffer TriShadingBuf { TriangleShading triShading[]; };
layout(set = 0, binding = kBindMaterials, scalar) readonly buffer MaterialBuf { Material materials[]; };
layout(set = 0, binding = kBindTexInfo, scalar) readonly buffer TexInfoBuf { TextureInfo texInfos[]; };
layout(set = 0, binding = kBindTexels, scalar) readonly buffer TexelBuf { uvec2 texels[]; };
layout(set = 0, binding = kBindLightTris, scalar) readonly buffer LightTriBuf { LightTriangle lightTris[]; };
layout(set = 0, binding = kBindPunctual, scalar) readonly buffer PunctualBuf { PunctualLight punctual[]; };
layout(set = 0, binding = kBindSceneConst, scalar) readonly buffer SceneConstBuf { SceneConstants sceneStored; };

// The scene constants as a private copy that every kernel's main() fills first (loadScene),
// so that later reads are registers: lavapipe before Mesa 23 loads a storage-buffer value
// lane by lane, in a loop with a branch per lane and component, at every read, even at a
// uniform address (bench/RESULTS.md, sixth session).
SceneConstants scene;
void loadScene() { scene = sceneStored; }

#endif  // GDPT_LIB_SCENE_BUFFERS
