// emitter_supersampling.comp — emitter supersampling: a separate estimate of the emission that
// the camera sees at its first hit (the environment for a ray that misses), in the pixels
// where that emission changes within the pixel's neighbourhood (the edges of lights seen
// directly, of the sky, of emissive texture detail). Elsewhere the path kernels estimate it
// as part of their samples.
//
// Why: with a box filter, a pixel that a bright emitter covers by a fraction c gets, per
// camera sample, the emitter's radiance L with probability c and 0 otherwise: variance
// c(1−c)L² per sample, large against the pixel's own value. G-PT's reconstruction does not
// touch this term (it is added to the reconstructed indirect image, Kettunen et al. 2015 §5),
// so at low sample counts these few pixels hold most of a G-PT image's relMSE (the Cornell
// box at 5 spp: the light's rim, 0.1 % of the pixels, gave 60 %; bench/RESULTS.md, emitter
// supersampling). Here each such pixel gets samplesPerSpp first-hit rays per camera sample,
// at scrambled Sobol' positions (sobol.glsl), which stratify the pixel as they accumulate.
//
// Phases (push constant `phase`):
//   probe   over the image: 4 rays per pixel (the first four scrambled Sobol' points: one
//           per quarter); probe[p] = a hash of the emission if the four agree, else 1
//           ("mixed").
//   count   over the image: a pixel is refined if it is mixed or a neighbour's (3x3)
//           signature differs from its own; counts them and lists them after the
//           signatures (probe[pixels + i], in the order the atomic counter hands out).
//   args    one invocation: k = samplesPerSpp, reduced so that k × refined pixels stays
//           within rayBudget when the edges are many, and the refine dispatch's group counts
//           (rows of groups; the last row's surplus invocations return at once).
//   refine  over the list (dispatched indirectly): per camera sample of the batch, k rays
//           per refined pixel, merged into visibleStats[p]. One invocation per listed pixel
//           keeps every lane of a SIMD vector on a refined pixel: over the image, a vector
//           of eight neighbours that an edge crosses in one or two of them ran their rays
//           with the rest idle. A pixel's estimate depends on its own rays alone, so the
//           list's order (which the atomic makes vary) changes no bit of it.
// Unbiased: which pixels are refined depends only on the probe's rays; the refined estimate
// uses other, independent rays, and each scrambled point is uniform over the pixel, so the
// pixel's estimate is unbiased given the choice, hence unbiased. Both PT and G-PT use it.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "gdpt_shared.h"
#include "lib/common.glsl"
#include "lib/rng.glsl"
#include "lib/ray.glsl"
#include "lib/sobol.glsl"

layout(local_size_x_id = kSpecWorkgroupX, local_size_y_id = kSpecWorkgroupY) in;

#include "lib/scene_buffers.glsl"
layout(set = 0, binding = kBindCounters, scalar) buffer CounterBuf { Counters counters; };
#include "lib/pixel_buffers.glsl"
GDPT_PIXEL_BUFFER(kBindVisibleStats, PixelStatsArray, visibleStats);
#define visibleStats visibleStats_.v
GDPT_PIXEL_BUFFER(kBindVisibleProbe, UintArray, probe);
#define probe probe_.v
layout(set = 0, binding = kBindVisibleCounter, scalar) buffer VisibleCounterBuf { VisibleCounter visibleCounter; };
layout(push_constant, scalar) uniform Push { VisibleParams params; };

#include "lib/scene_access.glsl"
#define GDPT_ANYHIT_FILTER(tri, u, v) alphaPasses(tri, u, v)
#include "lib/bvh_traverse.glsl"
#include "lib/camera.glsl"
#include "lib/pixel_stats.glsl"

const uint kProbeMixed = 1u;  // signatures of agreeing probes have bit 0 clear

// Emission seen along the camera ray through pixelPos (what the path kernels count at the
// first hit: the front-facing emission of the surface, or the environment on a miss).
vec3 firstHitEmission(vec2 pixelPos) {
    vec3 d = cameraRay(pixelPos);
    Hit hit = traceClosest(scene.camPosition, d, 0.0, 1.0 / 0.0);
    if (hit.triangle == kInvalidIndex) return kHasEnv ? scene.envRadiance : vec3(0.0);
    if (!kHasLightTris) return vec3(0.0);
    return surfaceEmission(makeSurfaceHit(hit.triangle, hit.u, hit.v, d));
}

uint emissionSignature(vec3 e) {
    // Any zero (±0) hashes as +0; bit 0 is kept clear for kProbeMixed.
    uvec3 b = floatBitsToUint(e);
    b = mix(b, uvec3(0u), equal(e, vec3(0.0)));
    return pcgHash(b.x + pcgHash(b.y + pcgHash(b.z))) & ~kProbeMixed;
}

bool refined(uint x, uint y) {
    uint own = probe[y * scene.width + x];
    if ((own & kProbeMixed) != 0u) return true;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            int nx = int(x) + dx, ny = int(y) + dy;
            if (nx < 0 || ny < 0 || nx >= int(scene.width) || ny >= int(scene.height)) continue;
            if (probe[uint(ny) * scene.width + uint(nx)] != own) return true;
        }
    }
    return false;
}

void main() {
    loadScene();
    uint pixels = scene.width * scene.height;
    uint pixel;
    if (params.phase == kVisiblePhaseRefine) {
        uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
        uint item = group * (gl_WorkGroupSize.x * gl_WorkGroupSize.y) + gl_LocalInvocationIndex;
        if (item >= visibleCounter.refinedPixels) return;
        pixel = probe[pixels + item];
    } else {
        if (gl_GlobalInvocationID.x >= scene.width || gl_GlobalInvocationID.y >= scene.height) return;
        pixel = gl_GlobalInvocationID.y * scene.width + gl_GlobalInvocationID.x;
    }
    uint x = pixel % scene.width;
    uint y = pixel / scene.width;

    if (params.phase == kVisiblePhaseCount) {
        if (refined(x, y)) probe[pixels + atomicAdd(visibleCounter.refinedPixels, 1u)] = pixel;
        return;
    }
    if (params.phase == kVisiblePhaseArgs) {
        if (pixel != 0u) return;
        uint refinedPixels = visibleCounter.refinedPixels;
        visibleCounter.raysPerSample = clamp(params.rayBudget / max(refinedPixels, 1u), 1u, params.samplesPerSpp);
        // Rows of at most 65,535 groups, the least maxComputeWorkGroupCount a device has (a
        // 4K image whose every pixel is refined needs 130,000 groups of 64).
        uint groupSize = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
        uint groups = (refinedPixels + groupSize - 1u) / groupSize;
        visibleCounter.groupsX = min(groups, 65535u);
        visibleCounter.groupsY = (groups + 65534u) / 65535u;
        visibleCounter.groupsZ = 1u;
        return;
    }
    // Probe: one "sample" of four rays; refine: the batch's camera samples of k rays each.
    uint samples = 1u, raysPerSample = 4u, sampleBase = 0u;
    uint salt = 0x70726f62u;  // "prob"
    if (params.phase == kVisiblePhaseRefine) {
        raysPerSample = visibleCounter.raysPerSample;
        samples = params.samplesPerPixel;
        sampleBase = params.sampleBase;
        salt = 0x76697369u;  // "visi"
    }
    // One scramble per pixel and phase, the same in every batch, so that the refine rays of
    // successive batches continue one sequence (camera sample s owns its indices s·k ..).
    uint seedX = pcgHash(pixel + pcgHash(salt + pcgHash(params.seed)));
    uint seedY = pcgHash(seedX ^ 0x9e3779b9u);

    // Welford over the camera samples, each the mean of its k rays (so that the statistics
    // count camera samples, like every other per-pixel estimate).
    Welford acc = welfordInit();
    uint nan = 0u;
    vec3 firstValue = vec3(0.0);
    bool agree = true;
    for (uint s = 0u; s < samples; ++s) {
        vec3 sum = vec3(0.0);
        for (uint i = 0u; i < raysPerSample; ++i) {
            uint index = (sampleBase + s) * raysPerSample + i;
            vec3 e = firstHitEmission(vec2(x, y) + sobolScrambled2(index, seedX, seedY));
            if (i == 0u) firstValue = e;
            agree = agree && all(equal(e, firstValue));
            sum += e;
        }
        vec3 value = sum / float(raysPerSample);
        bool finite = isFinite(value);
        if (!finite) nan++;
        welfordAdd(acc, statsSample(value, finite), s + 1u);
    }
    atomicAdd(counters.raysTraced, samples * raysPerSample);
    if (params.phase == kVisiblePhaseProbe) {
        probe[pixel] = agree ? emissionSignature(firstValue) : kProbeMixed;
        return;
    }
    visibleStats[pixel] = chanMerge(visibleStats[pixel], acc, samples);
    if (nan > 0u) atomicAdd(counters.nanSamples, nan);
}
