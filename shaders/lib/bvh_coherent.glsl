// bvh_coherent.glsl — groups of nearby rays traced as one walk of the BVH (bvh_traverse.glsl):
// occlusion beams of up to four shadow or reconnection rays with one end or one direction, and
// bundles of up to five closest-hit rays a little apart (G-PT's camera fan and glossy offsets).
// Each ray gets the answer its own traversal would give. GLSL only; the including kernel sets
// up bvh_traverse.glsl's scene accessors.
#ifndef GDPT_LIB_BVH_COHERENT
#define GDPT_LIB_BVH_COHERENT

#include "bvh_traverse.glsl"

// ---- Occlusion beams: up to four occlusion rays with one end or one direction ----
//
// G-PT's offset paths connect their own vertices, about a pixel apart, to one point (the
// base's light point, the base's next vertex) or leave them in one direction (the
// environment): four occlusion rays that, traced one by one, walk nearly the same nodes. A
// beam walks them once. A node is entered if the beam's centre ray (from the centre c of the
// origins' bounding box, of half-width h) enters its box grown by h; a leaf's triangles are
// tested against every ray of the beam not yet occluded. At any parameter λ in [0, 1] a ray
// from o_i to the shared end T lies (1 - λ)(o_i - c) from the centre ray's point, within h on
// every axis (parallel rays: o_i - c), so every box that ray i enters, its grown box the centre
// ray enters; since a hit point lies in its leaf's box (padded by the builder), the beam tests
// every triangle that ray i's own traversal would find occluding, with the same triangle test
// on the same ray. Each answer is occludedTowards's (or traceAny's to infinity) bit for bit;
// the nodes are walked once, the stack and the loop run once, and on lavapipe, where every
// traversal call site is a loop that runs until its slowest lane ends, one loop replaces four.
const float kBvhInfinity = 1.0 / 0.0;

struct OcclusionBeam {
    vec3 o0, o1, o2, o3;  // the rays' origins ...
    vec3 d0, d1, d2, d3;  // ... unit directions (as towardsTarget gives them) ...
    vec4 tMax;            // ... and ends
    bvec4 want;           // rays to trace; the others are not occluded
    vec3 centre;          // the centre ray: from the origins' box centre ...
    vec3 centreDir;       // ... along this (to the shared end: length 1 in t) ...
    float centreTMax;
    vec3 grow;            // ... against boxes grown by the half-width, plus a rounding margin
};

// The centre and half-width of the wanted origins, and the rounding margin of the grown boxes:
// 2^-20 of the coordinates' magnitude, a few ulps of each quantity the node test combines
// (the builder's box padding covers the triangle test's own tolerance).
void beamSpan(inout OcclusionBeam b, float endMagnitude) {
    vec3 lo = vec3(kBvhInfinity), hi = vec3(-kBvhInfinity);
    if (b.want.x) lo = min(lo, b.o0), hi = max(hi, b.o0);
    if (b.want.y) lo = min(lo, b.o1), hi = max(hi, b.o1);
    if (b.want.z) lo = min(lo, b.o2), hi = max(hi, b.o2);
    if (b.want.w) lo = min(lo, b.o3), hi = max(hi, b.o3);
    bool some = any(b.want);
    b.centre = some ? 0.5 * (lo + hi) : vec3(0.0);
    vec3 halfWidth = some ? 0.5 * (hi - lo) : vec3(0.0);
    float margin = (maxComponent(abs(b.centre)) + maxComponent(halfWidth) + endMagnitude) * (1.0 / 1048576.0);
    b.grow = halfWidth + vec3(margin);
}

// Rays from o0..o3 (want) towards `target`, each as occludedTowards traces it (towardsTarget;
// a ray of zero or NaN length is not traced: nothing occludes it).
OcclusionBeam beamTowards(vec3 o0, vec3 o1, vec3 o2, vec3 o3, bvec4 want, vec3 target) {
    OcclusionBeam b;
    b.o0 = o0;
    b.o1 = o1;
    b.o2 = o2;
    b.o3 = o3;
    b.want.x = towardsTarget(o0, target, b.d0, b.tMax.x) && want.x;
    b.want.y = towardsTarget(o1, target, b.d1, b.tMax.y) && want.y;
    b.want.z = towardsTarget(o2, target, b.d2, b.tMax.z) && want.z;
    b.want.w = towardsTarget(o3, target, b.d3, b.tMax.w) && want.w;
    beamSpan(b, maxComponent(abs(target)));
    b.centreDir = target - b.centre;
    b.centreTMax = 1.0;
    return b;
}

// Rays from o0..o3 (want) along `dir` to infinity, as traceAny(o, dir, 0, ∞).
OcclusionBeam beamAlong(vec3 o0, vec3 o1, vec3 o2, vec3 o3, bvec4 want, vec3 dir) {
    OcclusionBeam b;
    b.o0 = o0;
    b.o1 = o1;
    b.o2 = o2;
    b.o3 = o3;
    b.d0 = dir;
    b.d1 = dir;
    b.d2 = dir;
    b.d3 = dir;
    b.tMax = vec4(kBvhInfinity);
    b.want = want;
    beamSpan(b, 0.0);
    b.centreDir = dir;
    b.centreTMax = kBvhInfinity;
    return b;
}

// One ray of a beam against triangle g (anyHitAt's test).
bool beamRayHits(vec3 o, vec3 d, float tMax, TriangleGeom g, uint tri) {
    float tCand = tMax;
    float u;
    float v;
    return intersectTriangleGeom(o, d, g.v0, g.e1, g.e2, 0.0, tCand, u, v) && GDPT_ANYHIT_FILTER(tri, u, v);
}

// Triangle `tri` against every ray of the beam still unoccluded.
void beamTriangle(OcclusionBeam b, uint tri, inout bvec4 occluded) {
    TriangleGeom g = triangleGeom(tri);
    if (b.want.x && !occluded.x) occluded.x = beamRayHits(b.o0, b.d0, b.tMax.x, g, tri);
    if (b.want.y && !occluded.y) occluded.y = beamRayHits(b.o1, b.d1, b.tMax.y, g, tri);
    if (b.want.z && !occluded.z) occluded.z = beamRayHits(b.o2, b.d2, b.tMax.z, g, tri);
    if (b.want.w && !occluded.w) occluded.w = beamRayHits(b.o3, b.d3, b.tMax.w, g, tri);
}

// Every wanted ray is occluded: nothing left to find.
bool beamDone(OcclusionBeam b, bvec4 occluded) {
    return (occluded.x || !b.want.x) && (occluded.y || !b.want.y) && (occluded.z || !b.want.z) &&
           (occluded.w || !b.want.w);
}

// Per ray of the beam: occluded (false for a ray not wanted). traceAny's walk (both builds,
// GDPT_BVH_UNIT_STEPS as there) with the grown boxes and the beam's triangle test.
bvec4 traceAnyBeam(OcclusionBeam b) {
    bvec4 occluded = bvec4(false);
    if (!any(b.want)) return occluded;
    vec3 invDir = bvhSafeInverse(b.centreDir);
    GDPT_BVH_STACK_DECLARE();
    uint node = 0u;
#ifdef GDPT_BVH_UNIT_STEPS
    uvec4 leafFirst = uvec4(0u);
    uvec4 leafCount = uvec4(0u);
    uint k = 0u;
    uint kEnd = 0u;
    while (true) {
        while (k < kEnd) {
            beamTriangle(b, wideLeafTriangle(leafFirst, k, leafCount), occluded);
            ++k;
            if (kBvhRegisterStack == 0u) break;
        }
        if (beamDone(b, occluded)) break;
        if (k < kEnd) continue;
        if (node == kInvalidIndex) {
            if (stackSize == 0u) break;
            float unusedNear;
            GDPT_BVH_STACK_POP(node, unusedNear);
        }
        BvhWideNode n = bvhNode(node);
        vec4 tNear;
        bvec4 h;
        wideNodeBoxesGrown(n, b.grow, b.centre, invDir, 0.0, b.centreTMax, tNear, h);
        uvec4 count = wideCounts(n);
        leafFirst = n.child;
        leafCount = wideLeafCounts(count, h);
        k = 0u;
        kEnd = leafCount.x + leafCount.y + leafCount.z + leafCount.w;
        uint next = kInvalidIndex;
        GDPT_BVH_ANY_ORDER(n, h, count, next);
        node = next;
    }
#else
    while (true) {
        BvhWideNode n = bvhNode(node);
        vec4 tNear;
        bvec4 h;
        wideNodeBoxesGrown(n, b.grow, b.centre, invDir, 0.0, b.centreTMax, tNear, h);
        uvec4 count = wideCounts(n);
        uvec4 c = wideLeafCounts(count, h);
        for (uint k = 0u; k < c.x + c.y + c.z + c.w; ++k) beamTriangle(b, wideLeafTriangle(n.child, k, c), occluded);
        if (beamDone(b, occluded)) break;
        uint next = kInvalidIndex;
        GDPT_BVH_ANY_ORDER(n, h, count, next);
        if (next == kInvalidIndex) {
            if (stackSize == 0u) break;
            float unusedNear;
            GDPT_BVH_STACK_POP(next, unusedNear);
        }
        node = next;
    }
#endif
    return occluded;
}

#ifndef GDPT_BVH_UNIT_STEPS
// ---- Ray bundles: up to five closest-hit rays a little apart ----
//
// G-PT traces groups of rays that start and point nearly alike: a camera sample's base
// primary ray and its four offsets' (one origin, directions about a pixel's angle apart), and
// in a glossy bounce the four offsets' own next rays (origins about a pixel apart, directions
// near the base's), each a closest-hit query that lavapipe runs as a traversal loop until its
// slowest lane ends. A bundle walks the tree once for up to five. A node is entered if the
// bundle's centre ray (c, d_c) enters the node's box grown by `grow`: ray i's point at
// parameter t lies within |o_i − c| + t·|d_i − d_c| of the centre ray's point at the same t on
// every axis, and no ray goes farther than `reach` (the distance from c to the farthest corner
// of the root's bounds plus the origins' spread, or the longest tMax if shorter) before
// leaving every box, so every box that ray i enters, the centre ray enters grown by
// max|o_i − c| + reach·max|d_i − d_c| (plus a rounding margin). Its entry distance along the
// centre ray is then at most ray i's, so a node is skipped only when the centre ray enters it
// beyond every ray's closest hit so far. Each leaf triangle is tested against every ray with
// closerHit's test, so each ray gets the closest accepted hit of its own traversal: the same
// t, u, v and triangle, except where two triangles are hit at exactly the same t (duplicated
// or coplanar-overlapping triangles), where either may be reported, as the single ray's own
// visiting order decides.
struct RayBundle {
    vec3 o0, o1, o2, o3, o4;  // the rays' origins ...
    vec3 d0, d1, d2, d3, d4;  // ... unit directions ...
    float tMax0;              // ... and ends: traceClosest(o_i, d_i, 0, tMax_i); 0 = not traced
    vec4 tMax;                // (rays 1..4)
    vec3 centre;              // the centre ray ...
    vec3 centreDir;
    vec3 grow;                // ... and the node boxes' growth (bundleSpan)
};

// The scene's bounds: the union of the root's child boxes.
void bvhRootBounds(out vec3 lo, out vec3 hi) {
    BvhWideNode n = bvhNode(0u);
    float sx = wideAxisScale(n.exponents, 0u);
    float sy = wideAxisScale(n.exponents, 1u);
    float sz = wideAxisScale(n.exponents, 2u);
    vec4 loX = wideDecodeAxis(n.origin.x, n.qMin.x, sx), hiX = wideDecodeAxis(n.origin.x, n.qMax.x, sx);
    vec4 loY = wideDecodeAxis(n.origin.y, n.qMin.y, sy), hiY = wideDecodeAxis(n.origin.y, n.qMax.y, sy);
    vec4 loZ = wideDecodeAxis(n.origin.z, n.qMin.z, sz), hiZ = wideDecodeAxis(n.origin.z, n.qMax.z, sz);
    lo = vec3(kBvhInfinity);
    hi = vec3(-kBvhInfinity);
    [[unroll]] for (uint j = 0u; j < 4u; ++j) {
        if (n.child[j] != kInvalidIndex) {
            lo = min(lo, vec3(loX[j], loY[j], loZ[j]));
            hi = max(hi, vec3(hiX[j], hiY[j], hiZ[j]));
        }
    }
}

// Ray i's share of the bundle's spreads (if it is traced).
void bundleSpread(vec3 o, vec3 d, float tMax, vec3 centre, vec3 centreDir, inout vec3 originSpread,
                  inout vec3 dirSpread, inout float tFar) {
    if (tMax > 0.0) {
        originSpread = max(originSpread, abs(o - centre));
        dirSpread = max(dirSpread, abs(d - centreDir));
        tFar = max(tFar, tMax);
    }
}

// Sets b.grow from the rays and the centre ray the caller filled in.
void bundleSpan(inout RayBundle b) {
    vec3 originSpread = vec3(0.0);
    vec3 dirSpread = vec3(0.0);
    float tFar = 0.0;
    bundleSpread(b.o0, b.d0, b.tMax0, b.centre, b.centreDir, originSpread, dirSpread, tFar);
    bundleSpread(b.o1, b.d1, b.tMax.x, b.centre, b.centreDir, originSpread, dirSpread, tFar);
    bundleSpread(b.o2, b.d2, b.tMax.y, b.centre, b.centreDir, originSpread, dirSpread, tFar);
    bundleSpread(b.o3, b.d3, b.tMax.z, b.centre, b.centreDir, originSpread, dirSpread, tFar);
    bundleSpread(b.o4, b.d4, b.tMax.w, b.centre, b.centreDir, originSpread, dirSpread, tFar);
    vec3 lo;
    vec3 hi;
    bvhRootBounds(lo, hi);
    float reach = min(length(max(abs(lo - b.centre), abs(hi - b.centre))) + length(originSpread), tFar);
    float margin = (maxComponent(abs(b.centre)) + reach) * (1.0 / 1048576.0);
    b.grow = originSpread + dirSpread * reach + vec3(margin);
}

// The bundle of rays o_i + t d_i, t < tMax_i (0: not traced), about the centre ray (c, dc).
RayBundle bundleAbout(vec3 c, vec3 dc, vec3 o0, vec3 d0, float tMax0, vec3 o1, vec3 d1, vec3 o2, vec3 d2, vec3 o3,
                      vec3 d3, vec3 o4, vec3 d4, vec4 tMax) {
    RayBundle b;
    b.o0 = o0;
    b.o1 = o1;
    b.o2 = o2;
    b.o3 = o3;
    b.o4 = o4;
    b.d0 = d0;
    b.d1 = d1;
    b.d2 = d2;
    b.d3 = d3;
    b.d4 = d4;
    b.tMax0 = tMax0;
    b.tMax = tMax;
    b.centre = c;
    b.centreDir = dc;
    bundleSpan(b);
    return b;
}

// A camera sample's primary rays: the base's (d0, the centre ray, always traced) and the
// offsets' d1..d4 where `want`, all from the camera at o, to infinity.
RayBundle fanFrom(vec3 o, vec3 d0, vec3 d1, vec3 d2, vec3 d3, vec3 d4, bvec4 want) {
    vec4 tMax = mix(vec4(0.0), vec4(kBvhInfinity), want);
    return bundleAbout(o, d0, o, d0, kBvhInfinity, o, d1, o, d2, o, d3, o, d4, tMax);
}

// Four rays o_i + t d_i, t < tMax_i (tMax_i = 0: not traced), about the centre ray (c, d_c),
// in slots 1..4 (slot 0 is not traced).
RayBundle bundleOfFour(vec3 c, vec3 dc, vec3 o1, vec3 d1, vec3 o2, vec3 d2, vec3 o3, vec3 d3, vec3 o4, vec3 d4,
                       vec4 tMax) {
    return bundleAbout(c, dc, c, dc, 0.0, o1, d1, o2, d2, o3, d3, o4, d4, tMax);
}

// Per ray of the bundle: traceClosest(o_i, d_i, 0, tMax_i) (a miss at t = 0 for a ray not
// traced). traceClosest's walk (node steps) with the grown boxes, the centre ray's order and
// every ray's triangle test; nodes are skipped beyond the farthest closest hit so far.
void traceClosestBundle(RayBundle b, out Hit h0, out Hit h1, out Hit h2, out Hit h3, out Hit h4) {
    h0 = missHit(b.tMax0);
    h1 = missHit(b.tMax.x);
    h2 = missHit(b.tMax.y);
    h3 = missHit(b.tMax.z);
    h4 = missHit(b.tMax.w);
    vec3 invDir = bvhSafeInverse(b.centreDir);
    GDPT_BVH_STACK_DECLARE();
    uint node = 0u;
    // The farthest closest hit so far: set here and after each node's triangles, the only
    // place the hits change.
    float limit = max(max(h0.t, h1.t), max(max(h2.t, h3.t), h4.t));
    while (true) {
        BvhWideNode n = bvhNode(node);
        vec4 tNear;
        bvec4 h;
        wideNodeBoxesGrown(n, b.grow, b.centre, invDir, 0.0, limit, tNear, h);
        uvec4 count = wideCounts(n);
        uvec4 c = wideLeafCounts(count, h);
        for (uint k = 0u; k < c.x + c.y + c.z + c.w; ++k) {
            uint tri = wideLeafTriangle(n.child, k, c);
            TriangleGeom g = triangleGeom(tri);
            closerHitGeom(b.o0, b.d0, g, tri, 0.0, h0);
            closerHitGeom(b.o1, b.d1, g, tri, 0.0, h1);
            closerHitGeom(b.o2, b.d2, g, tri, 0.0, h2);
            closerHitGeom(b.o3, b.d3, g, tri, 0.0, h3);
            closerHitGeom(b.o4, b.d4, g, tri, 0.0, h4);
        }
        limit = max(max(h0.t, h1.t), max(max(h2.t, h3.t), h4.t));
        WideOrder o = wideSortInner(n, count, h, tNear, limit);
        uint next = o.child.x;
        GDPT_BVH_PUSH_FARTHER(o);
        while (next == kInvalidIndex && stackSize > 0u) {
            uint popped;
            float poppedNear;
            GDPT_BVH_STACK_POP(popped, poppedNear);
            if (poppedNear <= limit) next = popped;
        }
        if (next == kInvalidIndex) break;
        node = next;
    }
}

// Ray j of four (j < 4) by a constant-free select (no dynamically indexed array).
vec3 pickOfFour(vec3 a, vec3 b, vec3 c, vec3 d, uint j) { return j == 0u ? a : (j == 1u ? b : (j == 2u ? c : d)); }

// Whether ray (o, d), up to tMax, widens a bundle about (c, dc) by at most maxGrow on every
// axis (the reach bounded by tMax and by `extent`, an upper bound on a ray's path through the
// scene): a cost rule, not a correctness one (bundleSpan computes the growth the rays need).
bool bundleFits(vec3 o, vec3 d, float tMax, vec3 c, vec3 dc, float extent, float maxGrow) {
    return maxComponent(abs(o - c)) + min(tMax, extent) * maxComponent(abs(d - dc)) <= maxGrow;
}

// Four closest-hit rays o_i + t d_i, t < tMax_i (tMax_i = 0: not traced, a miss at t = 0), in
// as few bundles as their spread allows: each pass takes the first ray not yet traced as its
// centre ray and bundles the rays not yet traced that fit about it (bundleFits). Rays that
// start and point nearly alike (G-PT's offsets following the base) take one pass; rays far
// apart (offsets on either side of a silhouette) pass alone, rather than bundled into a beam so
// wide that it walks the whole tree. One traversal call site, in a loop of at most four passes.
void traceClosestFour(vec3 o1, vec3 d1, vec3 o2, vec3 d2, vec3 o3, vec3 d3, vec3 o4, vec3 d4, vec4 tMax,
                      float extent, float maxGrow, out Hit h1, out Hit h2, out Hit h3, out Hit h4) {
    h1 = missHit(0.0);
    h2 = h1;
    h3 = h1;
    h4 = h1;
    vec4 left = tMax;
    while (any(greaterThan(left, vec4(0.0)))) {
        uint j = left.x > 0.0 ? 0u : (left.y > 0.0 ? 1u : (left.z > 0.0 ? 2u : 3u));
        vec3 c = pickOfFour(o1, o2, o3, o4, j);
        vec3 dc = pickOfFour(d1, d2, d3, d4, j);
        bvec4 take = bvec4(left.x > 0.0 && bundleFits(o1, d1, left.x, c, dc, extent, maxGrow),
                           left.y > 0.0 && bundleFits(o2, d2, left.y, c, dc, extent, maxGrow),
                           left.z > 0.0 && bundleFits(o3, d3, left.z, c, dc, extent, maxGrow),
                           left.w > 0.0 && bundleFits(o4, d4, left.w, c, dc, extent, maxGrow));
        take[j] = true;
        vec4 pass = mix(vec4(0.0), left, take);
        Hit unused;
        Hit a1;
        Hit a2;
        Hit a3;
        Hit a4;
        traceClosestBundle(bundleOfFour(c, dc, o1, d1, o2, d2, o3, d3, o4, d4, pass), unused, a1, a2, a3, a4);
        if (take.x) h1 = a1;
        if (take.y) h2 = a2;
        if (take.z) h3 = a3;
        if (take.w) h4 = a4;
        left = mix(left, vec4(0.0), take);
    }
}
#endif  // !GDPT_BVH_UNIT_STEPS

#endif  // GDPT_LIB_BVH_COHERENT
