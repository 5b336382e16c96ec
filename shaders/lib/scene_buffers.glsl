// scene_buffers.glsl — declarations of the scene's buffers (its tables as texel buffers with
// accessors, here and in scene_geometry.glsl; the scene constants as a storage buffer) and
// the feature specialisation constants, shared by every path-sampling kernel. Binding numbers and
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
layout(constant_id = kSpecHasSpecularLobe) const bool kHasSpecularLobe = true;
// bsdf.glsl compiles its GGX lobe only where some material has one (every material of the
// scene is Lambertian otherwise); a kernel must include this file before bsdf.glsl for that.
#define GDPT_BSDF_SPECULAR kHasSpecularLobe

#include "scene_geometry.glsl"

// The read-only tables, as uniform texel buffers like the geometry (scene_geometry.glsl says
// why); the accessors below return the gdpt_shared.h structs. Fetches whose fields a caller
// does not use are removed by the compiler like unused loads.
layout(set = 0, binding = kBindTriShading) uniform utextureBuffer triShadingTexels;
layout(set = 0, binding = kBindMaterials) uniform utextureBuffer materialTexels;
layout(set = 0, binding = kBindTexInfo) uniform utextureBuffer texInfoTexels;
layout(set = 0, binding = kBindTexels) uniform utextureBuffer imageTexels;  // RG32UI: two packed halves
layout(set = 0, binding = kBindLightTris) uniform utextureBuffer lightTriTexels;
layout(set = 0, binding = kBindPunctual) uniform utextureBuffer punctualTexels;

// Two frames (scene_geometry.glsl): each frame's light tables follow each other as its
// triangles do.
#ifdef GDPT_TWO_FRAMES
uint frameLightBase = 0u;
uint framePunctualBase = 0u;
#define GDPT_FRAME_LIGHT(i) ((i) + frameLightBase)
#define GDPT_FRAME_PUNCTUAL(i) ((i) + framePunctualBase)
#else
#define GDPT_FRAME_LIGHT(i) (i)
#define GDPT_FRAME_PUNCTUAL(i) (i)
#endif

TriangleShading triangleShading(uint i) {
    int at = int(GDPT_FRAME_TRIANGLE(i) * kTriangleShadingTexels);
    uvec4 a = texelFetch(triShadingTexels, at);
    uvec4 b = texelFetch(triShadingTexels, at + 1);
    uvec4 c = texelFetch(triShadingTexels, at + 2);
    uvec4 d = texelFetch(triShadingTexels, at + 3);
    uvec4 e = texelFetch(triShadingTexels, at + 4);
    TriangleShading s;
    s.n0 = uintBitsToFloat(a.xyz);
    s.material = a.w;
    s.n1 = uintBitsToFloat(b.xyz);
    s.area = uintBitsToFloat(b.w);
    s.n2 = uintBitsToFloat(c.xyz);
    s.flags = c.w;
    s.uv0 = uintBitsToFloat(d.xy);
    s.uv1 = uintBitsToFloat(d.zw);
    s.uv2 = uintBitsToFloat(e.xy);
    s.lightIndex = e.z;
    s.pad3 = e.w;
    return s;
}

Material material(uint i) {
    int at = int(i * kMaterialTexels);
    uvec4 a = texelFetch(materialTexels, at);
    uvec4 b = texelFetch(materialTexels, at + 1);
    uvec4 c = texelFetch(materialTexels, at + 2);
    uvec4 d = texelFetch(materialTexels, at + 3);
    ivec4 e = ivec4(texelFetch(materialTexels, at + 4));
    Material m;
    m.baseColor = uintBitsToFloat(a);
    m.emissive = uintBitsToFloat(b.xyz);
    m.metallic = uintBitsToFloat(b.w);
    m.specularColor = uintBitsToFloat(c.xyz);
    m.roughness = uintBitsToFloat(c.w);
    m.specular = uintBitsToFloat(d.x);
    m.ior = uintBitsToFloat(d.y);
    m.alphaCutoff = uintBitsToFloat(d.z);
    m.flags = d.w;
    m.baseColorTex = e.x;
    m.metallicRoughnessTex = e.y;
    m.emissiveTex = e.z;
    m.normalTex = e.w;
    return m;
}

TextureInfo textureInfo(uint i) {
    uvec4 a = texelFetch(texInfoTexels, int(i));
    TextureInfo t;
    t.offset = a.x;
    t.width = a.y;
    t.height = a.z;
    t.flags = a.w;
    return t;
}

// Texel i of the shared image table: linear RGBA (two packHalf2x16 words).
vec4 imageTexel(uint i) {
    uvec2 packed = texelFetch(imageTexels, int(i)).xy;
    return vec4(unpackHalf2x16(packed.x), unpackHalf2x16(packed.y));
}

LightTriangle lightTriangle(uint i) {
    uvec4 a = texelFetch(lightTriTexels, int(GDPT_FRAME_LIGHT(i)));
    LightTriangle l;
    l.triangle = a.x;
    l.cdf = uintBitsToFloat(a.y);
    l.pmf = uintBitsToFloat(a.z);
    l.pad = uintBitsToFloat(a.w);
    return l;
}

PunctualLight punctualLight(uint i) {
    int at = int(GDPT_FRAME_PUNCTUAL(i) * kPunctualLightTexels);
    uvec4 a = texelFetch(punctualTexels, at);
    uvec4 b = texelFetch(punctualTexels, at + 1);
    uvec4 c = texelFetch(punctualTexels, at + 2);
    PunctualLight l;
    l.position = uintBitsToFloat(a.xyz);
    l.type = a.w;
    l.intensity = uintBitsToFloat(b.xyz);
    l.cosInner = uintBitsToFloat(b.w);
    l.direction = uintBitsToFloat(c.xyz);
    l.cosOuter = uintBitsToFloat(c.w);
    return l;
}

// The scene constants as a private copy that every kernel's main() fills first (loadScene),
// so that later reads are registers: lavapipe before Mesa 23 loads a storage-buffer value
// lane by lane, in a loop with a branch per lane and component, at every read, even at a
// uniform address (bench/RESULTS.md, scene constants).
#ifdef GDPT_TWO_FRAMES
// Each frame's constants (its camera, light counts and powers); `scene` is the selected one's.
layout(set = 0, binding = kBindSceneConst, scalar) readonly buffer SceneConstBuf { SceneConstants sceneStored[2]; };
SceneConstants scene;
SceneConstants frameScenes[2];
void loadScene() {
    frameScenes[0] = sceneStored[0];
    frameScenes[1] = sceneStored[1];
    scene = frameScenes[0];
}
// Makes every scene access (triangles, lights, camera, constants) read frame f (0 or 1).
void selectFrame(uint f) {
    scene = f == 0u ? frameScenes[0] : frameScenes[1];
    frameTriangleBase = f * scene.numTriangles;
    frameLightBase = f * scene.numLightTriangles;
    framePunctualBase = f * scene.numPunctualLights;
}
#else
layout(set = 0, binding = kBindSceneConst, scalar) readonly buffer SceneConstBuf { SceneConstants sceneStored; };
SceneConstants scene;
void loadScene() { scene = sceneStored; }
#endif

#endif  // GDPT_LIB_SCENE_BUFFERS
