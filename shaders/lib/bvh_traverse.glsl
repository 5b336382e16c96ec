// bvh_traverse.glsl — ray traversal of the two-wide BVH of gdpt_shared.h (BvhNode) over the
// leaf-ordered TriangleGeom array, and the ray/triangle test it uses.
//
// Two parts:
//  * The pure part (ray/box slab test, safe inverse direction, Möller–Trumbore triangle
//    test, struct Hit) is written in the GLSL/C++ common subset of common.glsl, so that
//    src/bvh/traverse_cpu.cpp runs the very same arithmetic on the host (GUIDE §2).
//  * The traversal loops (traceClosest, traceAny) read the storage buffers and exist in GLSL
//    only. src/bvh/traverse_cpu.cpp mirrors them statement for statement; change both.
//
// The including kernel must declare, before including this file,
//   layout(scalar) readonly buffer ... { BvhNode bvhNodes[]; };
//   layout(scalar) readonly buffer ... { TriangleGeom triGeoms[]; };
// (scene_buffers.glsl does). Triangle indices are positions in TriangleGeom (leaf) order.
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

GDPT_NAMESPACE_END

#ifndef __cplusplus
// ---------------------------------------------------------------------------------------------
// Device traversal (GLSL only). Mirrored by src/bvh/traverse_cpu.cpp.
// ---------------------------------------------------------------------------------------------

// Hook for cutout materials: return false to ignore the candidate hit (tri, u, v).
#ifndef GDPT_ANYHIT_FILTER
#define GDPT_ANYHIT_FILTER(tri, u, v) true
#endif

// Triangle `tri` (TriangleGeom order) against the ray; see intersectTriangleGeom.
bool intersectTriangle(vec3 orig, vec3 dir, uint tri, float tMin, inout float tMax, out float u,
                       out float v) {
    TriangleGeom g = triGeoms[tri];
    return intersectTriangleGeom(orig, dir, g.v0, g.e1, g.e2, tMin, tMax, u, v);
}

// Leaf [first, first + count): shrinks `hit` to the closest accepted triangle.
void intersectLeafClosest(vec3 orig, vec3 dir, uint first, uint count, float tMin, inout Hit hit) {
    for (uint i = first; i < first + count; ++i) {
        float tCand = hit.t;
        float u;
        float v;
        if (intersectTriangle(orig, dir, i, tMin, tCand, u, v) && GDPT_ANYHIT_FILTER(i, u, v)) {
            hit.t = tCand;
            hit.u = u;
            hit.v = v;
            hit.triangle = i;
        }
    }
}

// Leaf [first, first + count): true if any triangle is hit (and accepted) in (tMin, tMax).
bool intersectLeafAny(vec3 orig, vec3 dir, uint first, uint count, float tMin, float tMax) {
    for (uint i = first; i < first + count; ++i) {
        float tCand = tMax;
        float u;
        float v;
        if (intersectTriangle(orig, dir, i, tMin, tCand, u, v) && GDPT_ANYHIT_FILTER(i, u, v)) return true;
    }
    return false;
}

// Closest hit with tMin < t < tMax. Stack-based, nearest child first; leaf children are
// intersected when their parent is visited, so a node fetch tests two boxes and the
// stack only ever holds inner nodes (at most one per level: depth <= kBvhMaxDepth <
// kBvhStackSize).
Hit traceClosest(vec3 orig, vec3 dir, float tMin, float tMax) {
    Hit hit;
    hit.t = tMax;
    hit.u = 0.0f;
    hit.v = 0.0f;
    hit.triangle = kInvalidIndex;
    vec3 invDir = bvhSafeInverse(dir);
    uint stack[kBvhStackSize];
    uint stackSize = 0u;
    uint node = 0u;
    while (true) {
        BvhNode n = bvhNodes[node];
        float dL = 0.0f;
        float dR = 0.0f;
        bool hitL = n.left != kInvalidIndex &&
                    intersectBox(orig, invDir, n.lmin, n.lmax, tMin, hit.t, dL);
        bool hitR = n.right != kInvalidIndex &&
                    intersectBox(orig, invDir, n.rmin, n.rmax, tMin, hit.t, dR);
        // Visit order: the child with the nearer entry distance first.
        bool swapLR = hitR && (!hitL || dR < dL);
        uint c0 = swapLR ? n.right : n.left;
        uint count0 = swapLR ? n.rightCount : n.leftCount;
        bool hit0 = swapLR ? hitR : hitL;
        uint c1 = swapLR ? n.left : n.right;
        uint count1 = swapLR ? n.leftCount : n.rightCount;
        bool hit1 = swapLR ? hitL : hitR;
        uint next = kInvalidIndex;
        if (hit0) {
            if (count0 > 0u) {
                intersectLeafClosest(orig, dir, c0, count0, tMin, hit);
            } else {
                next = c0;
            }
        }
        if (hit1) {
            if (count1 > 0u) {
                intersectLeafClosest(orig, dir, c1, count1, tMin, hit);
            } else if (next == kInvalidIndex) {
                next = c1;
            } else {
                stack[stackSize] = c1;  // far inner child: visit later
                ++stackSize;
            }
        }
        if (next == kInvalidIndex) {
            if (stackSize == 0u) {
                break;
            }
            --stackSize;
            next = stack[stackSize];
        }
        node = next;
    }
    return hit;
}

// Occlusion: true as soon as any accepted hit with tMin < t < tMax is found. Same traversal
// as traceClosest without the shrinking tMax (order does not matter, so no sorting).
bool traceAny(vec3 orig, vec3 dir, float tMin, float tMax) {
    vec3 invDir = bvhSafeInverse(dir);
    uint stack[kBvhStackSize];
    uint stackSize = 0u;
    uint node = 0u;
    while (true) {
        BvhNode n = bvhNodes[node];
        float dL = 0.0f;
        float dR = 0.0f;
        bool hitL = n.left != kInvalidIndex &&
                    intersectBox(orig, invDir, n.lmin, n.lmax, tMin, tMax, dL);
        bool hitR = n.right != kInvalidIndex &&
                    intersectBox(orig, invDir, n.rmin, n.rmax, tMin, tMax, dR);
        uint next = kInvalidIndex;
        if (hitL) {
            if (n.leftCount > 0u) {
                if (intersectLeafAny(orig, dir, n.left, n.leftCount, tMin, tMax)) return true;
            } else {
                next = n.left;
            }
        }
        if (hitR) {
            if (n.rightCount > 0u) {
                if (intersectLeafAny(orig, dir, n.right, n.rightCount, tMin, tMax)) return true;
            } else if (next == kInvalidIndex) {
                next = n.right;
            } else {
                stack[stackSize] = n.right;
                ++stackSize;
            }
        }
        if (next == kInvalidIndex) {
            if (stackSize == 0u) {
                break;
            }
            --stackSize;
            next = stack[stackSize];
        }
        node = next;
    }
    return false;
}
#endif  // !__cplusplus

#endif  // GDPT_LIB_BVH_TRAVERSE
