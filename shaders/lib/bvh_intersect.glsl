// bvh_intersect.glsl — the ray/box and ray/triangle tests of the four-wide BVH of gdpt_shared.h
// (BvhWideNode) and its child-order helpers, written in the GLSL/C++ common subset of common.glsl:
// the device's traversal (bvh_traverse.glsl) and the host's mirror (src/bvh/traverse_cpu.cpp) run
// the very same arithmetic.
//
// Units: ray origins and triangles in world space (metres); t is in units of |dir|
// (the direction need not be normalised).
#ifndef GDPT_LIB_BVH_INTERSECT
#define GDPT_LIB_BVH_INTERSECT

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

#endif  // GDPT_LIB_BVH_INTERSECT
