// bvh_traverse.glsl — ray traversal of the four-wide BVH of gdpt_shared.h (BvhWideNode) over
// the leaf-ordered TriangleGeom array: closest hit (traceClosest) and occlusion (traceAny,
// occludedTowards), in GLSL only. src/bvh/traverse_cpu.cpp mirrors the loops statement for
// statement; change both. The box and triangle tests are bvh_intersect.glsl's, shared with the
// host; bvh_coherent.glsl traces groups of nearby rays at once.
//
// The including kernel must include scene_geometry.glsl (the accessors bvhNode(i) and
// triangleGeom(i)) before this file; scene_buffers.glsl does. Triangle indices are
// positions in TriangleGeom (leaf) order.
//
// Cutout (alpha-masked) triangles: define GDPT_ANYHIT_FILTER(tri, u, v) before including
// this file; a hit for which it is false is ignored by both traceClosest and traceAny.
#ifndef GDPT_LIB_BVH_TRAVERSE
#define GDPT_LIB_BVH_TRAVERSE

#include "bvh_intersect.glsl"

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

#endif  // GDPT_LIB_BVH_TRAVERSE
