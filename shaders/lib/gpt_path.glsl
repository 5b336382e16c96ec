// gpt_path.glsl — per-path state and small helpers of gpt.comp: the offset path record,
// pair existence at image borders, the vertex classification used by the shift, the pair
// accumulation, and the Welford/Chan statistics (pixel_stats.glsl). GLSL only: expects the
// kernel's scene buffers, `frame` (GptFrameParams) and kOffsetDelta to be declared.
#ifndef GDPT_LIB_GPT_PATH
#define GDPT_LIB_GPT_PATH

#include "lib/pixel_stats.glsl"

// One offset path. For kShiftNotConnected `hit` is the offset's own current vertex; after
// reconnection the offset's vertex is the base's and only woWorld (its own incoming
// direction at that shared vertex) differs.
struct OffsetPath {
    SurfaceHit hit;   // current vertex (NOT_CONNECTED only)
    vec3 woWorld;     // unit, from the current vertex back towards the previous one
    vec3 beta;        // f'/p: offset throughput over the base path's pdf (Jacobians included)
    float r;          // J·p'/p: offset density in the base's measure over the base's density
    float rLight;     // ratio applying to the light strategy of the current vertex's emission
    float countRatio; // n_q / n_p: samples of the offset's pixel q over the base's pixel p, per
                      // camera sample of the image; scales the offset's densities in every
                      // MIS weight of the pair (shift.glsl, "sample counts")
    uint state;       // kShiftNotConnected / kShiftRecentlyConnected / kShiftConnected
    bool alive;       // false: pair absent (image border) or shift failed -> base-only weights
    bool shifted;     // the pair exists and the base's primary ray hit: a shift was attempted
    vec3 baseSum;     // Σ w·f_base over this pair (part of central)
    vec3 offSum;      // Σ w·f_offset over this pair (neighbor_i)
    vec3 modulation;  // first-hit demodulation factor of the offset (1 = none; gpt.comp)
};

// The pair (p, p + δ_i) exists only inside the image; at borders p has fewer pairs.
bool gptPairExists(uint px, uint py, uint i) {
    ivec2 q = ivec2(px, py) + kOffsetDelta[i];
    return q.x >= 0 && q.y >= 0 && q.x < int(scene.width) && q.y < int(scene.height);
}

// The index (y·width + x) of pixel p + δ_i, the other end of pair i; only for a pair that
// exists (gptPairExists).
uint gptPairPixel(uint px, uint py, uint i) {
    ivec2 q = ivec2(px, py) + kOffsetDelta[i];
    return uint(q.y) * scene.width + uint(q.x);
}

// Whether the base path accumulates the pair (p, p + δ_i): every existing pair, and in a 1x1
// image, which has none, the right one as a pair whose shift always fails (its offset is never
// alive, gpt.comp). Its weights are then the lone base's, the path tracer's (MIS of NEE and
// BSDF sampling alone), so central(p) is PT's estimate of I(p) and gpt_resolve.comp's primal
// is unbiased there too; without it a 1x1 primal is zero. Images one pixel wide or high need
// no such pair: each pixel has one or two real ones.
bool gptPairCounted(uint px, uint py, uint i) {
    return gptPairExists(px, py, i) || (scene.width == 1u && scene.height == 1u && i == kGptRight);
}

// Vertex classification; a scene without glossy/specular vertices (kHasGlossy false) has
// every vertex rough, which the compiler folds away with the half-vector branch.
//
// Deviation from the authors' Mitsuba implementation of Kettunen et al. 2015, which classifies
// the base's current vertex by the component it sampled and the offset's by that same
// component: the sampled component is not a function of the path (a mixture reaches one
// direction through several lobes), and an offset may lack the component altogether (base
// samples the diffuse lobe of a wall, the offset sits on a metal), so the forward and the
// reverse shift of one pair can pick different shift types and the pair's MIS weights stop
// summing to one. Here every vertex is classified by its lowest roughness over all components
// (shiftRoughnessAll), a property of the vertex alone, so the rule is symmetric. Cost: a
// diffuse lobe under a smooth coat never reconnects (half-vector copies instead). On the test
// scenes (metals and Lambertian walls) both rules pass the same tests; the difference is
// argued, not measured.
bool roughAll(BsdfParams m) {
    return !kHasGlossy || shiftIsRough(shiftRoughnessAll(m), frame.shiftThreshold);
}

bool oneSidedBack(SurfaceHit h) {
    return !h.frontFace && (material(h.material).flags & kMatFlagDoubleSided) == 0u;
}

// Adds one estimator sample of a pair with MIS weight w: Σ w·f over the pair's
// strategies (base and offset, each by its own techniques) estimates the pair's integral.
void addPair(inout OffsetPath op, float w, vec3 fBase, vec3 fOffset) {
    op.baseSum += w * fBase;
    op.offSum += w * fOffset;
}

#endif  // GDPT_LIB_GPT_PATH
