// bvh_traverse.glsl — ray traversal of the four-wide BVH of gdpt_shared.h (BvhWideNode) over
// the leaf-ordered TriangleGeom array, and the ray/triangle test it uses.
//
// Two parts:
//  * The pure part (ray/box slab test, safe inverse direction, Möller–Trumbore triangle
//    test, struct Hit) is written in the GLSL/C++ common subset of common.glsl, so that
//    src/bvh/traverse_cpu.cpp runs the very same arithmetic on the host.
//  * The traversal loops (traceClosest, traceAny) read the scene's texel buffers and exist in
//    GLSL only. src/bvh/traverse_cpu.cpp mirrors them statement for statement; change both.
//
// The including kernel must include scene_geometry.glsl (the accessors bvhNode(i) and
// triangleGeom(i)) before this file; scene_buffers.glsl does. Triangle indices are
// positions in TriangleGeom (leaf) order.
//
// Cutout (alpha-masked) triangles: define GDPT_ANYHIT_FILTER(tri, u, v) before including
// this file; a hit for which it is false is ignored by both traceClosest and traceAny.
//
// Units: ray origins and triangles in world space (metres); t is in units of |dir|
// (the direction need not be normalised).
#ifndef GDPT_LIB_BVH_TRAVERSE
#define GDPT_LIB_BVH_TRAVERSE

#include "common.glsl"

// `precise` forbids the compiler from contracting a*b+c into an FMA or reassociating, so the
// device rounds the intersection arithmetic like the host does (GLSL 4.60 §4.7.1). The host
// is built without FMA contraction (ISO mode, -std=c++17), which matches.
#ifndef GDPT_PRECISE
#ifdef __cplusplus
#define GDPT_PRECISE
#else
#define GDPT_PRECISE precise
#endif
#endif

GDPT_NAMESPACE_BEGIN

// Result of a closest-hit query. triangle == kInvalidIndex on a miss (t then is the tMax the
// query was called with). (u, v) are the barycentrics of vertices 1 and 2 (hit point
// v0 + u * e1 + v * e2).
struct Hit {
    float t;
    float u;
    float v;
    uint triangle;
};

// Direction components smaller than this in magnitude are replaced by ±kBvhMinDirComponent
// before inverting, so invDir is finite and the slab products (b - o) * invDir can never be
// 0 * inf = NaN (Williams et al. 2005 use IEEE infinities instead, which yields NaN for
// origins on a slab plane). 1e-20 keeps |(b - o) * invDir| below FLT_MAX for |b - o| < 1e18.
GDPT_CONST float kBvhMinDirComponent = 1e-20f;

// Conservative slab test: the far distance is enlarged by 1 + 2 * gamma(3) (gamma(n) =
// n * eps / (1 - n * eps), eps = 2^-24), which bounds the rounding error of
// (b - o) * invDir (Ize 2013, "Robust BVH Ray Traversal", JCGT 2(2); pbrt-v3 §3.9.2).
GDPT_CONST float kBvhSlabFarScale = 1.0000005f;  // 1 + 4 * 2^-23 >= 1 + 2 * gamma(3)

GDPT_INLINE float bvhSafeComponent(float d) {
    return abs(d) < kBvhMinDirComponent ? (d >= 0.0f ? kBvhMinDirComponent : -kBvhMinDirComponent)
                                        : d;
}

// Reciprocal of the ray direction with zero components made finite (see kBvhMinDirComponent).
GDPT_INLINE vec3 bvhSafeInverse(vec3 dir) {
    return vec3(1.0f / bvhSafeComponent(dir.x), 1.0f / bvhSafeComponent(dir.y),
                1.0f / bvhSafeComponent(dir.z));
}

// Ray/AABB slab test (Kay & Kajiya 1986) for the parametric interval (tMin, tMax).
// Returns true and the entry distance tNear if the ray overlaps the box. NaN handling: any NaN
// reaching the final comparison makes it false, so a NaN ray rejects every box (and the
// traversal ends) instead of looping. An empty box (min > max) is NOT rejected by this test
// (the min/max swap hides it); absent children are skipped by their kInvalidIndex instead.
GDPT_INLINE bool intersectBox(vec3 orig, vec3 invDir, vec3 bmin, vec3 bmax, float tMin,
                              float tMax, GDPT_OUT(float) tNear) {
    vec3 t0 = (bmin - orig) * invDir;
    vec3 t1 = (bmax - orig) * invDir;
    vec3 tSmall = min(t0, t1);
    vec3 tLarge = max(t0, t1);
    tNear = max(max(tSmall.x, tSmall.y), max(tSmall.z, tMin));
    float tFar = min(min(tLarge.x, tLarge.y), min(tLarge.z, tMax)) * kBvhSlabFarScale;
    return tNear <= tFar;
}

// Smallest |det| accepted, relative to maxAbs(dir) * maxAbs(e1) * maxAbs(e2). det is
// computed with an absolute error of a few eps * |dir| |e1| |e2| (two products and a sum for
// the cross product, three for the dot; eps = 2^-24), i.e. below about 32 eps = 2^-19 in
// these max-norm units. A zero-area (collinear) triangle has det made of rounding noise
// only and, without this bound, returns garbage u, v, t far from the triangle. 2^-18 keeps a
// factor 2 of margin; it also rejects rays within ~4e-6 rad of grazing a triangle.
GDPT_CONST float kMinRelativeDet = 1.0f / 262144.0f;

// Relative tolerance of the edge tests, in units of the rounding-error scale of the
// barycentric numerators: u * det = dot(tvec, pvec) is computed with an error below a few
// eps * dot(|tvec|, |pvec|) (eps = 2^-24). Plain Möller–Trumbore evaluates a shared edge
// differently in its two triangles (different v0), so rays through the edge can miss both
// (measured: ~10% of rays aimed exactly at edges/vertices of an icosphere). Widening each
// triangle by 16 eps times that scale closes the gap (a ray may then hit both neighbours,
// which is harmless); the widening is ~1e-6 of the distance to v0, and the builder pads the
// boxes by more than that (kBoundsPad in builder.cpp).
GDPT_CONST float kEdgeTolerance = 1.0f / 1048576.0f;  // 2^-20 = 16 eps

// Möller & Trumbore 1997, "Fast, Minimum Storage Ray/Triangle Intersection", double-sided,
// on the triangle (v0, v0 + e1, v0 + e2), edges widened by kEdgeTolerance. Accepts
// tMin < t < tMax; on success stores t in tMax and the barycentrics, clamped to >= 0, in
// (u, v). All rejections are written as !(accept) so that a NaN anywhere rejects. Zero-area
// triangles never hit (see kMinRelativeDet).
GDPT_INLINE bool intersectTriangleGeom(vec3 orig, vec3 dir, vec3 v0, vec3 e1, vec3 e2,
                                       float tMin, GDPT_INOUT(float) tMax, GDPT_OUT(float) u,
                                       GDPT_OUT(float) v) {
    u = 0.0f;
    v = 0.0f;
    GDPT_PRECISE vec3 pvec = cross(dir, e2);
    GDPT_PRECISE float det = dot(e1, pvec);
    GDPT_PRECISE float detScale =
        maxComponent(abs(dir)) * maxComponent(abs(e1)) * maxComponent(abs(e2));
    if (!(abs(det) > kMinRelativeDet * detScale)) {
        return false;
    }
    GDPT_PRECISE float invDet = 1.0f / det;
    GDPT_PRECISE vec3 tvec = orig - v0;
    GDPT_PRECISE float uHit = dot(tvec, pvec) * invDet;
    GDPT_PRECISE float uTol = kEdgeTolerance * dot(abs(tvec), abs(pvec)) * abs(invDet);
    if (!(uHit >= -uTol && uHit <= 1.0f + uTol)) {
        return false;
    }
    GDPT_PRECISE vec3 qvec = cross(tvec, e1);
    GDPT_PRECISE float vHit = dot(dir, qvec) * invDet;
    GDPT_PRECISE float vTol = kEdgeTolerance * dot(abs(dir), abs(qvec)) * abs(invDet);
    if (!(vHit >= -vTol && uHit + vHit <= 1.0f + (uTol + vTol))) {
        return false;
    }
    GDPT_PRECISE float t = dot(e2, qvec) * invDet;
    if (!(t > tMin && t < tMax)) {
        return false;
    }
    tMax = t;
    u = max(uHit, 0.0f);
    v = max(vHit, 0.0f);
    return true;
}

// The result of a closest-hit query before any triangle is accepted: a miss at tMax.
GDPT_INLINE Hit missHit(float tMax) {
    Hit h;
    h.t = tMax;
    h.u = 0.0f;
    h.v = 0.0f;
    h.triangle = kInvalidIndex;
    return h;
}

// The four bytes of q as floats (exact small integers), byte k -> component k.
GDPT_INLINE vec4 wideUnpackBytes(uint q) {
    return vec4(float(q & 255u), float((q >> 8u) & 255u), float((q >> 16u) & 255u), float(q >> 24u));
}

// Scale of axis `axis` (0..2) of a wide node: 2^(e - 127), e = byte `axis` of exponents.
GDPT_INLINE float wideAxisScale(uint exponents, uint axis) {
    return uintBitsToFloat(((exponents >> (8u * axis)) & 255u) << 23u);
}

// Decoded bound of one axis for the four children: origin + q·scale (q·scale is exact, so
// this is one rounding however it is evaluated; BvhWideNode).
GDPT_INLINE vec4 wideDecodeAxis(float origin, uint q, float scale) {
    return vec4(origin) + wideUnpackBytes(q) * scale;
}

// Children's triangle counts (0 = inner node or empty slot).
GDPT_INLINE uvec4 wideCounts(BvhWideNode n) {
    uint c = n.qMin.w;
    return uvec4(c & 255u, (c >> 8u) & 255u, (c >> 16u) & 255u, c >> 24u);
}

// Slab tests of four boxes, given per axis as their lower and upper bounds (one vec4 component
// per child slot), for (tMin, tFarLimit): intersectBox, four at once; hit[k] is false for an
// empty slot (child[k] = kInvalidIndex).
GDPT_INLINE void wideSlabs(vec4 loX, vec4 hiX, vec4 loY, vec4 hiY, vec4 loZ, vec4 hiZ, uvec4 child, vec3 orig,
                           vec3 invDir, float tMin, float tFarLimit, GDPT_OUT(vec4) tNear, GDPT_OUT(bvec4) hit) {
    vec4 t0x = (loX - orig.x) * invDir.x;
    vec4 t1x = (hiX - orig.x) * invDir.x;
    vec4 t0y = (loY - orig.y) * invDir.y;
    vec4 t1y = (hiY - orig.y) * invDir.y;
    vec4 t0z = (loZ - orig.z) * invDir.z;
    vec4 t1z = (hiZ - orig.z) * invDir.z;
    tNear = max(max(min(t0x, t1x), min(t0y, t1y)), max(min(t0z, t1z), vec4(tMin)));
    vec4 tFar = min(min(max(t0x, t1x), max(t0y, t1y)), min(max(t0z, t1z), vec4(tFarLimit))) * kBvhSlabFarScale;
    hit = bvec4(tNear.x <= tFar.x && child.x != kInvalidIndex, tNear.y <= tFar.y && child.y != kInvalidIndex,
                tNear.z <= tFar.z && child.z != kInvalidIndex, tNear.w <= tFar.w && child.w != kInvalidIndex);
}

// Slab tests of a wide node's four children (their decoded boxes) for (tMin, tFarLimit):
// intersectBox, four at once; hit[k] is false for empty slots.
GDPT_INLINE void wideNodeBoxes(BvhWideNode n, vec3 orig, vec3 invDir, float tMin, float tFarLimit,
                               GDPT_OUT(vec4) tNear, GDPT_OUT(bvec4) hit) {
    float sx = wideAxisScale(n.exponents, 0u);
    float sy = wideAxisScale(n.exponents, 1u);
    float sz = wideAxisScale(n.exponents, 2u);
    wideSlabs(wideDecodeAxis(n.origin.x, n.qMin.x, sx), wideDecodeAxis(n.origin.x, n.qMax.x, sx),
              wideDecodeAxis(n.origin.y, n.qMin.y, sy), wideDecodeAxis(n.origin.y, n.qMax.y, sy),
              wideDecodeAxis(n.origin.z, n.qMin.z, sz), wideDecodeAxis(n.origin.z, n.qMax.z, sz), n.child, orig,
              invDir, tMin, tFarLimit, tNear, hit);
}

// The same for the children's boxes grown by `pad` (>= 0) on every side (a beam's node test).
GDPT_INLINE void wideNodeBoxesGrown(BvhWideNode n, vec3 pad, vec3 orig, vec3 invDir, float tMin, float tFarLimit,
                                    GDPT_OUT(vec4) tNear, GDPT_OUT(bvec4) hit) {
    float sx = wideAxisScale(n.exponents, 0u);
    float sy = wideAxisScale(n.exponents, 1u);
    float sz = wideAxisScale(n.exponents, 2u);
    wideSlabs(wideDecodeAxis(n.origin.x, n.qMin.x, sx) - pad.x, wideDecodeAxis(n.origin.x, n.qMax.x, sx) + pad.x,
              wideDecodeAxis(n.origin.y, n.qMin.y, sy) - pad.y, wideDecodeAxis(n.origin.y, n.qMax.y, sy) + pad.y,
              wideDecodeAxis(n.origin.z, n.qMin.z, sz) - pad.z, wideDecodeAxis(n.origin.z, n.qMax.z, sz) + pad.z,
              n.child, orig, invDir, tMin, tFarLimit, tNear, hit);
}

// Triangle counts of the hit leaf children (0 for a slot that is not a hit leaf).
GDPT_INLINE uvec4 wideLeafCounts(uvec4 count, bvec4 hit) {
    return uvec4(hit.x ? count.x : 0u, hit.y ? count.y : 0u, hit.z ? count.z : 0u, hit.w ? count.w : 0u);
}

// Triangle k of the hit leaf children taken in slot order, with counts c (wideLeafCounts):
// one loop over c.x + c.y + c.z + c.w tests them all, so a kernel holds one inlined
// triangle test per traversal (on llvmpipe every copy costs its code).
GDPT_INLINE uint wideLeafTriangle(uvec4 first, uint k, uvec4 c) {
    uint a = c.x;
    uint b = a + c.y;
    uint d = b + c.z;
    return k < a ? first.x + k : (k < b ? first.y + (k - a) : (k < d ? first.z + (k - b) : first.w + (k - d)));
}

// Entry distance of an absent child in wideSortInner (sorts after every real one).
GDPT_CONST float kBvhNoEntry = 3.0e38f;

// Inner children of a wide node in near-to-far order: child[k] = kInvalidIndex for absent.
struct WideOrder {
    uvec4 child;
    vec4 t;
};

GDPT_INLINE void wideCompareSwap(GDPT_INOUT(uint) ca, GDPT_INOUT(float) ta, GDPT_INOUT(uint) cb,
                                 GDPT_INOUT(float) tb) {
    if (tb < ta) {
        float t = ta;
        ta = tb;
        tb = t;
        uint c = ca;
        ca = cb;
        cb = c;
    }
}

// The inner children that the ray enters before tLimit, sorted by entry distance (a
// five-comparator network over the four slots; absent ones last).
GDPT_INLINE WideOrder wideSortInner(BvhWideNode n, uvec4 count, bvec4 hit, vec4 tNear, float tLimit) {
    WideOrder o;
    bvec4 inner = bvec4(hit.x && count.x == 0u && tNear.x <= tLimit, hit.y && count.y == 0u && tNear.y <= tLimit,
                        hit.z && count.z == 0u && tNear.z <= tLimit, hit.w && count.w == 0u && tNear.w <= tLimit);
    o.child = uvec4(inner.x ? n.child.x : kInvalidIndex, inner.y ? n.child.y : kInvalidIndex,
                    inner.z ? n.child.z : kInvalidIndex, inner.w ? n.child.w : kInvalidIndex);
    o.t = vec4(inner.x ? tNear.x : kBvhNoEntry, inner.y ? tNear.y : kBvhNoEntry, inner.z ? tNear.z : kBvhNoEntry,
               inner.w ? tNear.w : kBvhNoEntry);
    wideCompareSwap(o.child.x, o.t.x, o.child.y, o.t.y);
    wideCompareSwap(o.child.z, o.t.z, o.child.w, o.t.w);
    wideCompareSwap(o.child.x, o.t.x, o.child.z, o.t.z);
    wideCompareSwap(o.child.y, o.t.y, o.child.w, o.t.w);
    wideCompareSwap(o.child.y, o.t.y, o.child.z, o.t.z);
    return o;
}

GDPT_NAMESPACE_END

#ifndef __cplusplus
// ---------------------------------------------------------------------------------------------
// Device traversal (GLSL only). Mirrored by src/bvh/traverse_cpu.cpp.
// ---------------------------------------------------------------------------------------------

// Hook for cutout materials: return false to ignore the candidate hit (tri, u, v).
#ifndef GDPT_ANYHIT_FILTER
#define GDPT_ANYHIT_FILTER(tri, u, v) true
#endif

// The traversal stack. lavapipe keeps an array indexed by a per-lane size in scratch memory
// and reads and writes it lane by lane. A tree whose traversals never hold more than 8 or 16
// entries (WideBvh::maxStack, known before the pipelines are created for small scenes:
// SceneSpec) is traversed with the stack in two or four uvec4 / vec4 pairs instead, the
// newest entry in .x of the first, shifted on push and pop, which stay in registers
// (bench/RESULTS.md). The same entries in the same order either way, so the same hits.
// kBvhRegisterStack = 0 (the host's default): the array.
layout(constant_id = kSpecBvhRegisterStack) const uint kBvhRegisterStack = 0u;

#define GDPT_BVH_STACK_DECLARE()                                  \
    uint stackNode[kBvhWideStackSize];                            \
    float stackNear[kBvhWideStackSize];                           \
    uvec4 regNode0 = uvec4(0u), regNode1 = uvec4(0u);             \
    uvec4 regNode2 = uvec4(0u), regNode3 = uvec4(0u);             \
    vec4 regNear0 = vec4(0.0f), regNear1 = vec4(0.0f);            \
    vec4 regNear2 = vec4(0.0f), regNear3 = vec4(0.0f);            \
    uint stackSize = 0u

// With 8 entries the upper pairs are never written, so they stay zero (constants).
#define GDPT_BVH_STACK_PUSH(c, t)                                 \
    if (kBvhRegisterStack > 0u) {                                 \
        if (kBvhRegisterStack > 8u) {                             \
            regNode3 = uvec4(regNode2.w, regNode3.xyz);           \
            regNear3 = vec4(regNear2.w, regNear3.xyz);            \
            regNode2 = uvec4(regNode1.w, regNode2.xyz);           \
            regNear2 = vec4(regNear1.w, regNear2.xyz);            \
        }                                                         \
        regNode1 = uvec4(regNode0.w, regNode1.xyz);               \
        regNear1 = vec4(regNear0.w, regNear1.xyz);                \
        regNode0 = uvec4((c), regNode0.xyz);                      \
        regNear0 = vec4((t), regNear0.xyz);                       \
    } else {                                                      \
        stackNode[stackSize] = (c);                               \
        stackNear[stackSize] = (t);                               \
    }                                                             \
    ++stackSize

#define GDPT_BVH_STACK_POP(c, t)                                  \
    --stackSize;                                                  \
    if (kBvhRegisterStack > 0u) {                                 \
        (c) = regNode0.x;                                         \
        (t) = regNear0.x;                                         \
        regNode0 = uvec4(regNode0.yzw, regNode1.x);               \
        regNear0 = vec4(regNear0.yzw, regNear1.x);                \
        regNode1 = uvec4(regNode1.yzw, regNode2.x);               \
        regNear1 = vec4(regNear1.yzw, regNear2.x);                \
        regNode2 = uvec4(regNode2.yzw, regNode3.x);               \
        regNear2 = vec4(regNear2.yzw, regNear3.x);                \
        regNode3 = uvec4(regNode3.yzw, 0u);                       \
        regNear3 = vec4(regNear3.yzw, 0.0f);                      \
    } else {                                                      \
        (c) = stackNode[stackSize];                               \
        (t) = stackNear[stackSize];                               \
    }

// The inner children of a WideOrder but the nearest, farthest first (so that they pop in
// near-to-far order), with their entry distances.
#define GDPT_BVH_PUSH_FARTHER(o)                                  \
    if ((o).child.w != kInvalidIndex) {                           \
        GDPT_BVH_STACK_PUSH((o).child.w, (o).t.w);                \
    }                                                             \
    if ((o).child.z != kInvalidIndex) {                           \
        GDPT_BVH_STACK_PUSH((o).child.z, (o).t.z);                \
    }                                                             \
    if ((o).child.y != kInvalidIndex) {                           \
        GDPT_BVH_STACK_PUSH((o).child.y, (o).t.y);                \
    }

// traceAny's order: the first inner child hit (slot order) becomes `next`, the others are
// pushed (order does not change an occlusion answer).
#define GDPT_BVH_ANY_ORDER(n, h, count, next)                     \
    [[unroll]] for (uint j = 0u; j < 4u; ++j) {                   \
        if ((h)[j] && (count)[j] == 0u) {                         \
            if ((next) == kInvalidIndex) {                        \
                (next) = (n).child[j];                            \
            } else {                                              \
                GDPT_BVH_STACK_PUSH((n).child[j], 0.0f);          \
            }                                                     \
        }                                                         \
    }

// Triangle `tri` (TriangleGeom order) against the ray; see intersectTriangleGeom.
bool intersectTriangle(vec3 orig, vec3 dir, uint tri, float tMin, inout float tMax, out float u,
                       out float v) {
    TriangleGeom g = triangleGeom(tri);
    return intersectTriangleGeom(orig, dir, g.v0, g.e1, g.e2, tMin, tMax, u, v);
}

// Triangle `tri`, fetched as g, against the ray: shrinks `hit` to it if it is accepted and closer.
void closerHitGeom(vec3 orig, vec3 dir, TriangleGeom g, uint tri, float tMin, inout Hit hit) {
    float tCand = hit.t;
    float u;
    float v;
    if (intersectTriangleGeom(orig, dir, g.v0, g.e1, g.e2, tMin, tCand, u, v) && GDPT_ANYHIT_FILTER(tri, u, v)) {
        hit.t = tCand;
        hit.u = u;
        hit.v = v;
        hit.triangle = tri;
    }
}

// Triangle `tri` against the ray: shrinks `hit` to it if it is accepted and closer.
void closerHit(vec3 orig, vec3 dir, uint tri, float tMin, inout Hit hit) {
    closerHitGeom(orig, dir, triangleGeom(tri), tri, tMin, hit);
}

// Triangle `tri` is hit and accepted with tMin < t < tMax.
bool anyHitAt(vec3 orig, vec3 dir, uint tri, float tMin, float tMax) {
    float tCand = tMax;
    float u;
    float v;
    return intersectTriangle(orig, dir, tri, tMin, tCand, u, v) && GDPT_ANYHIT_FILTER(tri, u, v);
}

// Closest hit with tMin < t < tMax. Per node: the four boxes, then the triangles of every hit
// leaf child (slot order), then the inner children in reach sorted by entry distance: the
// nearest is visited next, the others pushed farthest first (so they pop near to far) with
// their entry distance; popped entries beyond the closest hit so far are skipped. The stack
// never holds more than collapseToWide's maxStack <= kBvhWideStackSize.
//
// Two builds of the loop (SceneSpec::bvhUnitSteps picks one per scene and device). Both
// test the same triangles in the same order and find the same hit; they differ in what one
// iteration does.
//  * Node steps (the default build): a node's boxes and then every triangle of its hit
//    leaves, before its inner children are sorted.
//  * Unit steps (GDPT_BVH_UNIT_STEPS; trees whose stack is in memory, on lavapipe before
//    Mesa 23): at most one triangle and then, once the node's leaves are done, the next node.
//    Lavapipe 22.3 runs an iteration's code for every branch that any lane of a SIMD vector
//    takes, so with node steps a lane that met sixteen leaf triangles made the vector's eight
//    lanes wait through sixteen tests; with unit steps one lane's triangles share iterations
//    with another's nodes. On trees of 10k to 1M triangles that traces 25-37 % more rays per
//    second; on the Cornell box's few, full nodes the extra iterations cost 20 %, and Mesa 25,
//    which skips the branches no lane takes, traced 3-9 % fewer rays with them
//    (bench/RESULTS.md, "Unit steps for large trees").
//    Inner children are sorted before the node's triangles shrink the hit distance, so an
//    entry beyond it is skipped when popped rather than not pushed: the same nodes visited.
//    The host gives this build kBvhRegisterStack = 0 (SceneSpec::bvhUnitSteps); the triangle
//    loop's break on that constant is what makes it one triangle per iteration. Written as an
//    `if`, or with an unconditional break, the same steps traced 15-20 % fewer rays per
//    second on lavapipe 22.3 (measured; the code lavapipe makes of the two forms differs).
#ifdef GDPT_BVH_UNIT_STEPS
Hit traceClosest(vec3 orig, vec3 dir, float tMin, float tMax) {
    Hit hit = missHit(tMax);
    vec3 invDir = bvhSafeInverse(dir);
    GDPT_BVH_STACK_DECLARE();
    uint node = 0u;
    float nodeNear = tMin;  // entry distance of `node`
    uvec4 leafFirst = uvec4(0u);
    uvec4 leafCount = uvec4(0u);
    uint k = 0u;     // the next of the last node's leaf triangles (wideLeafTriangle) ...
    uint kEnd = 0u;  // ... and their end
    while (true) {
        while (k < kEnd) {
            uint i = wideLeafTriangle(leafFirst, k, leafCount);
            closerHit(orig, dir, i, tMin, hit);
            ++k;
            if (kBvhRegisterStack == 0u) break;
        }
        if (k < kEnd) continue;
        if (node == kInvalidIndex || nodeNear > hit.t) {
            node = kInvalidIndex;
            while (node == kInvalidIndex && stackSize > 0u) {
                uint popped;
                float poppedNear;
                GDPT_BVH_STACK_POP(popped, poppedNear);
                if (poppedNear <= hit.t) {
                    node = popped;
                    nodeNear = poppedNear;
                }
            }
            if (node == kInvalidIndex) break;
        }
        BvhWideNode n = bvhNode(node);
        vec4 tNear;
        bvec4 h;
        wideNodeBoxes(n, orig, invDir, tMin, hit.t, tNear, h);
        uvec4 count = wideCounts(n);
        leafFirst = n.child;
        leafCount = wideLeafCounts(count, h);
        k = 0u;
        kEnd = leafCount.x + leafCount.y + leafCount.z + leafCount.w;
        WideOrder o = wideSortInner(n, count, h, tNear, hit.t);
        node = o.child.x;
        nodeNear = o.t.x;
        GDPT_BVH_PUSH_FARTHER(o);
    }
    return hit;
}

// Occlusion: true as soon as any accepted hit with tMin < t < tMax is found. Same traversal
// without the shrinking tMax and the ordering (order does not change the answer).
bool traceAny(vec3 orig, vec3 dir, float tMin, float tMax) {
    vec3 invDir = bvhSafeInverse(dir);
    GDPT_BVH_STACK_DECLARE();
    uint node = 0u;
    uvec4 leafFirst = uvec4(0u);
    uvec4 leafCount = uvec4(0u);
    uint k = 0u;
    uint kEnd = 0u;
    while (true) {
        while (k < kEnd) {
            uint i = wideLeafTriangle(leafFirst, k, leafCount);
            if (anyHitAt(orig, dir, i, tMin, tMax)) return true;
            ++k;
            if (kBvhRegisterStack == 0u) break;
        }
        if (k < kEnd) continue;
        if (node == kInvalidIndex) {
            if (stackSize == 0u) break;
            float unusedNear;
            GDPT_BVH_STACK_POP(node, unusedNear);
        }
        BvhWideNode n = bvhNode(node);
        vec4 tNear;
        bvec4 h;
        wideNodeBoxes(n, orig, invDir, tMin, tMax, tNear, h);
        uvec4 count = wideCounts(n);
        leafFirst = n.child;
        leafCount = wideLeafCounts(count, h);
        k = 0u;
        kEnd = leafCount.x + leafCount.y + leafCount.z + leafCount.w;
        uint next = kInvalidIndex;
        GDPT_BVH_ANY_ORDER(n, h, count, next);
        node = next;
    }
    return false;
}
#else
Hit traceClosest(vec3 orig, vec3 dir, float tMin, float tMax) {
    Hit hit = missHit(tMax);
    vec3 invDir = bvhSafeInverse(dir);
    GDPT_BVH_STACK_DECLARE();
    uint node = 0u;
    while (true) {
        BvhWideNode n = bvhNode(node);
        vec4 tNear;
        bvec4 h;
        wideNodeBoxes(n, orig, invDir, tMin, hit.t, tNear, h);
        uvec4 count = wideCounts(n);
        uvec4 c = wideLeafCounts(count, h);
        for (uint k = 0u; k < c.x + c.y + c.z + c.w; ++k) {
            uint i = wideLeafTriangle(n.child, k, c);
            closerHit(orig, dir, i, tMin, hit);
        }
        // Inner children still in reach, nearest first (wideSortInner); visit the nearest,
        // push the others farthest first so that they pop in near-to-far order.
        WideOrder o = wideSortInner(n, count, h, tNear, hit.t);
        uint next = o.child.x;
        GDPT_BVH_PUSH_FARTHER(o);
        while (next == kInvalidIndex && stackSize > 0u) {
            uint popped;
            float poppedNear;
            GDPT_BVH_STACK_POP(popped, poppedNear);
            if (poppedNear <= hit.t) next = popped;
        }
        if (next == kInvalidIndex) break;
        node = next;
    }
    return hit;
}

// Occlusion: true as soon as any accepted hit with tMin < t < tMax is found. Same traversal
// without the shrinking tMax and the ordering (order does not change the answer).
bool traceAny(vec3 orig, vec3 dir, float tMin, float tMax) {
    vec3 invDir = bvhSafeInverse(dir);
    GDPT_BVH_STACK_DECLARE();
    uint node = 0u;
    while (true) {
        BvhWideNode n = bvhNode(node);
        vec4 tNear;
        bvec4 h;
        wideNodeBoxes(n, orig, invDir, tMin, tMax, tNear, h);
        uvec4 count = wideCounts(n);
        uvec4 c = wideLeafCounts(count, h);
        for (uint k = 0u; k < c.x + c.y + c.z + c.w; ++k) {
            uint i = wideLeafTriangle(n.child, k, c);
            if (anyHitAt(orig, dir, i, tMin, tMax)) return true;
        }
        uint next = kInvalidIndex;
        GDPT_BVH_ANY_ORDER(n, h, count, next);
        if (next == kInvalidIndex) {
            if (stackSize == 0u) break;
            float unusedNear;
            GDPT_BVH_STACK_POP(next, unusedNear);
        }
        node = next;
    }
    return false;
}

#endif  // GDPT_BVH_UNIT_STEPS

// Whether anything lies between `origin` and a target point (a light point, a reconnection
// vertex), the target's own surface excluded. The ray is aimed from the offset origin at the
// target and stops a relative 1e-4 short of it. A ray along the direction from the surface
// point instead, stopped at that point's distance x (1 - 1e-4), can reach the target's own
// surface: the origin's offset grows with the scene's size (offsetComponent: 1.3 mm for a
// coordinate near 0 in an 85 m scene) and moves the ray towards the target's plane -- next-
// event estimation from a floor at y = 0 of a large scene to a lamp 3 m above it was occluded
// for most light points.
//
// towardsTarget gives that ray (unit direction, tMax) for callers that trace it themselves; it
// is false for a zero or NaN distance, where nothing occludes.
bool towardsTarget(vec3 origin, vec3 target, out vec3 dir, out float tMax) {
    vec3 d = target - origin;
    float len = length(d);
    dir = d / len;
    tMax = len * (1.0 - 1e-4);
    return len > 0.0;
}

bool occludedTowards(vec3 origin, vec3 target) {
    vec3 dir;
    float tMax;
    if (!towardsTarget(origin, target, dir, tMax)) return false;
    return traceAny(origin, dir, 0.0, tMax);
}

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
#endif  // !__cplusplus

#endif  // GDPT_LIB_BVH_TRAVERSE
