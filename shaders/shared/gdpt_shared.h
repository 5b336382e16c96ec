// gdpt_shared.h — THE host/shader interface of gdpt.
//
// This one file compiles as C++17 (included from src/) and as GLSL 460 (included from
// shaders/). Every struct that crosses the host/device boundary, every descriptor binding
// number and every specialisation-constant id is defined here or in the two headers that
// extend this one under the same rules (gpt_shared.h: gradient-domain path tracing;
// poisson_shared.h: the GPU Poisson solver), and nowhere else.
//
// Rules (see the README, Design notes, "Host/shader interface"):
//  * All storage blocks use layout(scalar) (GL_EXT_scalar_block_layout); glm's 12-byte vec3
//    then matches GLSL. Sizes and offsets are pinned by static_asserts in
//    tests/unit/util/test_shared_layout.cpp and by a GPU sentinel test
//    (tests/gpu/device_scene/test_layout_gpu.cpp).
//  * No bool in shared structs: use uint flags.
//  * Append-only: new fields go at the end of a struct. Every field says its units/space.
#ifndef GDPT_SHARED_H
#define GDPT_SHARED_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace gdpt::gpu {
using vec2 = glm::vec2;
using vec3 = glm::vec3;
using vec4 = glm::vec4;
using uvec2 = glm::uvec2;
using uvec4 = glm::uvec4;
using uint = std::uint32_t;
#define GDPT_CONST static constexpr
#define GDPT_ENUM_BEGIN(name) enum name : std::uint32_t {
#define GDPT_ENUM_END() }
#else
#define GDPT_CONST const
#define GDPT_ENUM_BEGIN(name) const uint
#define GDPT_ENUM_END()
#endif

// ---------------------------------------------------------------------------------------------
// Limits and sentinels
// ---------------------------------------------------------------------------------------------
GDPT_CONST uint kInvalidIndex = 0xFFFFFFFFu;
GDPT_CONST uint kBvhStackSize = 64u;  // traversal stack entries (max BVH depth is capped below)
GDPT_CONST uint kBvhMaxDepth = 60u;   // builder never exceeds this depth
// Traversal stack of the wide tree: nodes waiting to be visited (collapseToWide checks that
// its tree never needs more).
GDPT_CONST uint kBvhWideStackSize = 128u;
// The register traversal stack (kSpecBvhRegisterStack = its entries, 8 or 16): trees whose
// maxStack is at most that traverse with the stack in vector variables instead of an array.
GDPT_CONST uint kBvhRegisterStackMax = 16u;
GDPT_CONST uint kMaxLeafTriangles = 255u;  // leaf primitive count must fit in this

// ---------------------------------------------------------------------------------------------
// Geometry (world space, metres as given by the glTF file)
// ---------------------------------------------------------------------------------------------

// Intersection data of one triangle, in BVH leaf order. 48 bytes.
struct TriangleGeom {
    vec3 v0;  // world-space position of vertex 0
    float pad0;
    vec3 e1;  // v1 - v0 (world space)
    float pad1;
    vec3 e2;  // v2 - v0 (world space)
    float pad2;
};
GDPT_CONST uint kTriangleGeomTexels = 3u;  // 16-byte texels per TriangleGeom (scene_geometry.glsl)

// Shading data of one triangle, same index as TriangleGeom. 80 bytes.
struct TriangleShading {
    vec3 n0;        // world-space unit shading normal at vertex 0
    uint material;  // index into the material table
    vec3 n1;        // world-space unit shading normal at vertex 1
    float area;     // world-space area (m^2)
    vec3 n2;        // world-space unit shading normal at vertex 2
    uint flags;     // kTriFlag*
    vec2 uv0;       // texture coordinates (TEXCOORD_0) at vertex 0
    vec2 uv1;
    vec2 uv2;
    uint lightIndex;  // index into LightTriangle table, kInvalidIndex if not emissive
    uint pad3;
};
GDPT_CONST uint kTriangleShadingTexels = 5u;  // 16-byte texels per TriangleShading (scene_buffers.glsl)
GDPT_CONST uint kTriFlagHasNormals =
    1u;  // n0..n2 valid and not all the face normal; otherwise use the geometric normal

// Two-wide BVH node, what the builder writes (builder.h): stores both children's boxes. The
// kernels traverse its four-wide collapse, BvhWideNode. 64 bytes.
// A child with count == 0 is an inner node whose index is `left`/`right`; with count > 0
// it is a leaf covering triangles [first, first + count) in TriangleGeom order. An absent
// child has count == 0, index kInvalidIndex and an empty box (min > max).
struct BvhNode {
    vec3 lmin;  // left child bounds, world space
    uint left;  // node index (count==0) or first triangle (count>0)
    vec3 lmax;
    uint leftCount;  // 0 = inner node, else triangle count (<= kMaxLeafTriangles)
    vec3 rmin;       // right child bounds
    uint right;
    vec3 rmax;
    uint rightCount;
};

// Four-wide BVH node, what the kernels traverse (src/bvh/wide_bvh.h collapses the binary
// BvhNode tree into it; root = node 0), with its children's boxes quantised to 8 bits per
// coordinate against the node's own box (after Ylitie et al. 2017, "Efficient incoherent ray
// traversal on GPUs through compressed wide BVHs"). On axis a, child k's box is
//   origin[a] + q * 2^(e_a - 127)  for q = byte k of qMin<a> .. byte k of qMax<a>,
// e_a = byte a of `exponents`. The power-of-two scale makes q·2^e exact, so a decoded bound
// is one rounding of origin + q·2^e whichever way a compiler evaluates it; the builder picks
// each q so that the decoded box contains the child's exact box (wideQuantise in
// wide_bvh.cpp). 64 bytes instead of 128 (bench/RESULTS.md, quantised BVH nodes: G-PT 7-15 %
// faster per sample on Mesa 25, neutral to 4 % on Mesa 22.3).
struct BvhWideNode {
    vec3 origin;     // lower corner of the node's box (world space)
    uint exponents;  // bytes 0..2: biased float exponents of the x, y, z scales; byte 3: 0
    uvec4 qMin;      // xyz: byte k = child k's lower bound in scale steps above origin; w: counts
    uvec4 qMax;      // xyz: byte k = child k's upper bound (rounded up); w: 0
    uvec4 child;     // node index (count 0) or first triangle (count > 0); kInvalidIndex = empty slot
};
GDPT_CONST uint kBvhWideNodeTexels = 4u;  // 16-byte texels per BvhWideNode (scene_geometry.glsl)
// Four 16-byte vectors, so that a node is four texel fetches (scene_geometry.glsl); qMin.w
// holds the children's triangle counts, byte k for child k (0 = inner node or empty slot,
// <= kMaxLeafTriangles).

// ---------------------------------------------------------------------------------------------
// Materials and textures
// ---------------------------------------------------------------------------------------------

// glTF metallic-roughness material (+KHR_materials_specular, emissive_strength). 80 bytes.
struct Material {
    vec4 baseColor;            // linear RGBA factor (alpha used for cutout only)
    vec3 emissive;             // emitted radiance factor, W/(m^2 sr): emissiveFactor * strength
    float metallic;            // [0,1]
    vec3 specularColor;        // KHR_materials_specular specularColorFactor (linear)
    float roughness;           // perceptual roughness [0,1]; GGX alpha = roughness^2
    float specular;            // KHR_materials_specular specularFactor; 0 = pure Lambertian
    float ior;                 // index of refraction for dielectric F0 (default 1.5)
    float alphaCutoff;         // cutout threshold, used when flags & kMatFlagAlphaMask
    uint flags;                // kMatFlag*
    int baseColorTex;          // texture index or -1
    int metallicRoughnessTex;  // texture index or -1 (G = roughness, B = metallic)
    int emissiveTex;           // texture index or -1
    int normalTex;             // texture index or -1 (currently unused by kernels; warned)
};
GDPT_CONST uint kMaterialTexels = 5u;  // 16-byte texels per Material (scene_buffers.glsl)
GDPT_CONST uint kMatFlagDoubleSided = 1u;
GDPT_CONST uint kMatFlagAlphaMask = 2u;
GDPT_CONST uint kMatFlagEmissive = 4u;

// A texture inside the shared texel buffer. Texels are linear RGBA stored as two uints
// each (packHalf2x16(r,g), packHalf2x16(b,a)); sRGB textures are decoded on the host.
struct TextureInfo {
    uint offset;  // first texel (in texels) in the texel buffer
    uint width;
    uint height;
    uint flags;
};

// ---------------------------------------------------------------------------------------------
// Lights
// ---------------------------------------------------------------------------------------------

// Emissive triangle, sampled in proportion to power = area * luminance(emission) * pi.
struct LightTriangle {
    uint triangle;  // index into TriangleGeom
    float cdf;      // inclusive CDF of the selection (last entry == 1; light_table.h)
    float pmf;      // probability of choosing this triangle
    float pad;
};

GDPT_ENUM_BEGIN(PunctualType)
kPunctualPoint = 0u, kPunctualSpot = 1u GDPT_ENUM_END();

// KHR_lights_punctual point/spot light. Intensity in W/sr (glTF candela treated as
// radiometric). Sampled uniformly among punctual lights.
struct PunctualLight {
    vec3 position;   // world space
    uint type;       // PunctualType
    vec3 intensity;  // colour * intensity, W/sr
    float cosInner;  // spot: cos(innerConeAngle)
    vec3 direction;  // spot: world-space unit direction the light points to
    float cosOuter;  // spot: cos(outerConeAngle)
};
GDPT_CONST uint kPunctualLightTexels = 3u;  // 16-byte texels per PunctualLight (scene_buffers.glsl)

// ---------------------------------------------------------------------------------------------
// Per-scene constants (one storage buffer, read-only)
// ---------------------------------------------------------------------------------------------
struct SceneConstants {
    vec3 camPosition;   // world space
    float tanHalfFovY;  // tan(yfov / 2)
    vec3 camRight;      // unit, world space (+x on the image)
    float aspect;       // width / height
    vec3 camUp;         // unit, world space (+y on the image, i.e. towards row 0)
    uint width;         // image width in pixels
    vec3 camForward;    // unit view direction
    uint height;        // image height in pixels
    vec3 envRadiance;   // constant environment radiance, W/(m^2 sr)
    uint numLightTriangles;
    uint numPunctualLights;
    float lightTrianglePower;  // total power of emissive triangles (selection weight)
    float punctualPower;       // total selection weight of punctual lights
    uint maxDepth;             // maximum number of path segments (>= 1)
    float sceneRadius;         // bounding-sphere radius, metres (for ray offsets / env)
    uint rrDepth;              // Russian roulette starts after this many segments
    uint numTriangles;
    uint pad;
};

// ---------------------------------------------------------------------------------------------
// Per-batch push constants (<= 128 bytes)
// ---------------------------------------------------------------------------------------------
struct FrameParams {
    uint sampleBase;       // index of the first sample of this batch (per pixel)
    uint samplesPerPixel;  // samples taken per pixel in this batch
    uint seed;             // user seed
    uint rowOffset;        // first image row handled by this dispatch (dispatch tiling)
    uint rowCount;         // rows handled by this dispatch
    uint pad0;
    uint pad1;
    uint pad2;
};

// Push constants of emitter_supersampling.comp (emitter supersampling).
struct VisibleParams {
    uint phase;            // kVisiblePhase*
    uint sampleBase;       // refine: first camera sample of this batch (per pixel)
    uint samplesPerPixel;  // refine: camera samples of this batch; each gets samplesPerSpp rays
    uint seed;             // user seed
    uint samplesPerSpp;    // supersampling factor requested (rays per camera sample, >= 1)
    uint rayBudget;        // cap on refine rays per camera sample over the whole image
    uint pad0;
    uint pad1;
};
GDPT_CONST uint kVisiblePhaseProbe = 0u;   // 4 stratified rays per pixel -> signature
GDPT_CONST uint kVisiblePhaseCount = 1u;   // list the pixels to supersample
GDPT_CONST uint kVisiblePhaseRefine = 2u;  // supersample them (one batch), one invocation per listed pixel
GDPT_CONST uint kVisiblePhaseArgs = 3u;    // the refine dispatch's group counts and rays per sample

// Written by emitter_supersampling.comp's count and args phases. 32 bytes.
struct VisibleCounter {
    uint refinedPixels;  // pixels whose neighbourhood sees an emission edge
    uint raysPerSample;  // refine rays per camera sample in them (after the ray budget)
    uint pad1;
    uint pad2;
    uint groupsX;  // the refine phase's indirect dispatch (VkDispatchIndirectCommand): enough
    uint groupsY;  // workgroups for one invocation per refined pixel, in rows of at most
    uint groupsZ;  // 65,535 groups; 1
    uint pad3;
};

// Per-pixel running statistics of one estimator (Welford/Chan merge). 32 bytes.
// mean and m2 stay bounded as samples grow, so float32 is accurate over 10^5 samples
// (each merge adds a correction of relative size 1/n to a bounded value).
struct PixelStats {
    vec3 mean;   // running mean radiance
    uint count;  // number of samples merged
    vec3 m2;     // sum of squared deviations from the mean (per channel)
    uint pad;
};

// Device-side counters, reduced per batch (uints; no float atomics anywhere).
struct Counters {
    uint raysTraced;  // low 32 bits; host accumulates into 64-bit per batch
    uint pathsCompleted;
    uint nanSamples;     // samples dropped because they were NaN/Inf
    uint pad;            // unused (keeps the struct's layout)
    uint shiftPairs;     // G-PT: offsets inside the image whose base's primary ray hit
    uint shiftFailures;  // G-PT: of those, offsets whose shift failed (pair fell back to the base)
};

// ---------------------------------------------------------------------------------------------
// Descriptor bindings of the path-tracing pipelines (set 0)
// ---------------------------------------------------------------------------------------------
GDPT_ENUM_BEGIN(SceneBinding)
kBindTriGeom = 0u,
    kBindTriShading = 1u, kBindBvh = 2u, kBindMaterials = 3u, kBindTexInfo = 4u, kBindTexels = 5u,
    kBindLightTris = 6u, kBindPunctual = 7u, kBindSceneConst = 8u, kBindAccum = 9u, kBindCounters = 10u,
    kBindCount = 11u,
    // emitter supersampling (emitter_supersampling.comp, render/passes/emitter_supersampling_pass.h): the
    // supersampled estimate of the emission seen at the camera's first hit (PixelStats; a
    // count > 0 tells the path kernels to leave that term to it), the probe signature
    // per pixel (uint) followed by the list of refined pixels (uint each, as many as the
    // image's pixels) and the pass's counter (VisibleCounter).
    kBindVisibleStats = 14u, kBindVisibleProbe = 15u, kBindVisibleCounter = 16u GDPT_ENUM_END();

// Bindings used only by test kernels (tests/gpu/kernels), kept here so no number repeats.
GDPT_ENUM_BEGIN(TestBinding)
kBindTestInput = 32u, kBindTestOutput = 33u, kBindTestOutput2 = 34u GDPT_ENUM_END();

// Specialisation-constant ids (scene features compiled in or out per scene).
GDPT_ENUM_BEGIN(SpecId)
kSpecWorkgroupX = 0u,
    kSpecWorkgroupY = 1u, kSpecHasTextures = 2u, kSpecHasPunctual = 3u, kSpecHasLightTris = 4u,
    kSpecHasEnv = 5u, kSpecHasGlossy = 6u, kSpecHasAlphaMask = 7u, kSpecMaxDepth = 8u,
    kSpecPoissonFlags = 9u,        // poisson_*.comp: the kPoissonFlag* bits of this pipeline variant
    kSpecVisibleEmission = 10u,    // path kernels: emitter supersampling is on (visible_emission.glsl)
    kSpecHasShadingNormals = 11u,  // some triangle carries kTriFlagHasNormals (features.h)
    kSpecHasSpecularLobe = 12u,    // some material has a metal/dielectric lobe (features.h hasSpecularLayer)
    kSpecBvhRegisterStack =
        13u,  // entries of the register traversal stack (8, 16), 0 = in memory (bvh_traverse.glsl)
    kSpecGptDemodulate =
        14u  // gpt.comp: first-hit texture demodulation is on (gpt_shared.h kBindGptDemodMask)
    GDPT_ENUM_END();

// A ray of the BVH tests (tests/gpu/device_scene/test_bvh_gpu.cpp). 32 bytes.
struct TestRay {
    vec3 origin;  // world space
    float tMin;
    vec3 dir;  // world space, not necessarily unit
    float tMax;
};

// State of one path between bounces of pt.comp (pt_core.glsl), kept in registers. 80 bytes.
struct PathState {
    vec3 origin;       // world-space origin of the next segment
    uint pixel;        // y * width + x
    vec3 dir;          // unit direction of the next segment
    float prevPdf;     // solid-angle pdf of the BSDF sample that chose dir
    vec3 beta;         // path throughput f/p so far
    uint flags;        // kPathFlag*
    vec3 radiance;     // radiance gathered so far
    uint rng;          // Rng state
    vec3 prevP;        // position of the vertex that spawned the segment (for MIS)
    uint depth;        // index of the vertex the next hit will be (0 = first hit)
    uint rays;         // rays traced by this path so far
    uint ldSeed;       // the pixel's LdSample seed (sampler.glsl)
    uint sampleIndex;  // this camera sample's index in its pixel
    uint pad0;
};
GDPT_CONST uint kPathFlagAlive = 1u;
GDPT_CONST uint kPathFlagPrevSpecular = 2u;  // camera ray or Dirac bounce: no MIS on emission

#ifdef __cplusplus
}  // namespace gdpt::gpu
#endif
#endif  // GDPT_SHARED_H
