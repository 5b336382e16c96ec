// traverse_cpu.cpp — host mirror of shaders/lib/bvh_traverse.glsl (traceClosest, traceAny:
// traceClosestWideCpu, traceAnyWideCpu) and the traversal of the binary tree they are
// collapsed from (traceClosestCpu, traceAnyCpu: the builder's tests and benchmark). Keep the
// wide control flow identical to the GLSL's node-step build so both visit the same nodes and
// test the same triangles in the same order (the unit-step build tests the same triangles in
// the same order too; bvh_traverse.glsl); the arithmetic is shared through the included GLSL.
#include "bvh/traverse_cpu.h"

namespace gdpt {
namespace {

thread_local uint32_t tlsNodeVisits = 0;

// The default GDPT_ANYHIT_FILTER (accept every hit); the host has no cutout materials.
inline bool anyHitFilter(uint32_t /*tri*/, float /*u*/, float /*v*/) {
    return true;
}

}  // namespace

bool intersectTriangleCpu(const gpu::TriangleGeom& g, glm::vec3 orig, glm::vec3 dir, float tMin, float& tMax,
                          float& u, float& v) {
    return gpu::intersectTriangleGeom(orig, dir, g.v0, g.e1, g.e2, tMin, tMax, u, v);
}

namespace {

// Triangle i against the ray: shrinks `hit` to it if it is accepted and closer (the body of
// the GLSL traceClosest's triangle loop).
void closerHit(const std::vector<gpu::TriangleGeom>& geoms, glm::vec3 orig, glm::vec3 dir, uint32_t i,
               float tMin, Hit& hit) {
    float tCand = hit.t;
    float u;
    float v;
    if (intersectTriangleCpu(geoms[i], orig, dir, tMin, tCand, u, v) && anyHitFilter(i, u, v)) {
        hit.t = tCand;
        hit.u = u;
        hit.v = v;
        hit.triangle = i;
    }
}

// Triangle i is hit and accepted in (tMin, tMax) (the body of traceAny's triangle loop).
bool anyHitAt(const std::vector<gpu::TriangleGeom>& geoms, glm::vec3 orig, glm::vec3 dir, uint32_t i,
              float tMin, float tMax) {
    float tCand = tMax;
    float u;
    float v;
    return intersectTriangleCpu(geoms[i], orig, dir, tMin, tCand, u, v) && anyHitFilter(i, u, v);
}

// Binary-tree leaves [first, first + count).
void intersectLeafClosest(const std::vector<gpu::TriangleGeom>& geoms, glm::vec3 orig, glm::vec3 dir,
                          uint32_t first, uint32_t count, float tMin, Hit& hit) {
    for (uint32_t i = first; i < first + count; ++i) closerHit(geoms, orig, dir, i, tMin, hit);
}

bool intersectLeafAny(const std::vector<gpu::TriangleGeom>& geoms, glm::vec3 orig, glm::vec3 dir,
                      uint32_t first, uint32_t count, float tMin, float tMax) {
    for (uint32_t i = first; i < first + count; ++i)
        if (anyHitAt(geoms, orig, dir, i, tMin, tMax)) return true;
    return false;
}

}  // namespace

Hit traceClosestCpu(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriangleGeom>& geoms,
                    glm::vec3 orig, glm::vec3 dir, float tMin, float tMax) {
    Hit hit = gpu::missHit(tMax);
    const glm::vec3 invDir = gpu::bvhSafeInverse(dir);
    uint32_t stack[gpu::kBvhStackSize];
    uint32_t stackSize = 0;
    uint32_t node = 0;
    uint32_t visits = 0;
    while (true) {
        const gpu::BvhNode& n = nodes[node];
        ++visits;
        float dL = 0.0f;
        float dR = 0.0f;
        bool hitL =
            n.left != gpu::kInvalidIndex && gpu::intersectBox(orig, invDir, n.lmin, n.lmax, tMin, hit.t, dL);
        bool hitR =
            n.right != gpu::kInvalidIndex && gpu::intersectBox(orig, invDir, n.rmin, n.rmax, tMin, hit.t, dR);
        // Visit order: the child with the nearer entry distance first.
        bool swapLR = hitR && (!hitL || dR < dL);
        uint32_t c0 = swapLR ? n.right : n.left;
        uint32_t count0 = swapLR ? n.rightCount : n.leftCount;
        bool hit0 = swapLR ? hitR : hitL;
        uint32_t c1 = swapLR ? n.left : n.right;
        uint32_t count1 = swapLR ? n.leftCount : n.rightCount;
        bool hit1 = swapLR ? hitL : hitR;
        uint32_t next = gpu::kInvalidIndex;
        if (hit0) {
            if (count0 > 0u) {
                intersectLeafClosest(geoms, orig, dir, c0, count0, tMin, hit);
            } else {
                next = c0;
            }
        }
        if (hit1) {
            if (count1 > 0u) {
                intersectLeafClosest(geoms, orig, dir, c1, count1, tMin, hit);
            } else if (next == gpu::kInvalidIndex) {
                next = c1;
            } else {
                stack[stackSize] = c1;  // far inner child: visit later
                ++stackSize;
            }
        }
        if (next == gpu::kInvalidIndex) {
            if (stackSize == 0u) {
                break;
            }
            --stackSize;
            next = stack[stackSize];
        }
        node = next;
    }
    tlsNodeVisits = visits;
    return hit;
}

bool traceAnyCpu(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriangleGeom>& geoms,
                 glm::vec3 orig, glm::vec3 dir, float tMin, float tMax) {
    const glm::vec3 invDir = gpu::bvhSafeInverse(dir);
    uint32_t stack[gpu::kBvhStackSize];
    uint32_t stackSize = 0;
    uint32_t node = 0;
    tlsNodeVisits = 0;
    while (true) {
        const gpu::BvhNode& n = nodes[node];
        ++tlsNodeVisits;
        float dL = 0.0f;
        float dR = 0.0f;
        bool hitL =
            n.left != gpu::kInvalidIndex && gpu::intersectBox(orig, invDir, n.lmin, n.lmax, tMin, tMax, dL);
        bool hitR =
            n.right != gpu::kInvalidIndex && gpu::intersectBox(orig, invDir, n.rmin, n.rmax, tMin, tMax, dR);
        uint32_t next = gpu::kInvalidIndex;
        if (hitL) {
            if (n.leftCount > 0u) {
                if (intersectLeafAny(geoms, orig, dir, n.left, n.leftCount, tMin, tMax)) return true;
            } else {
                next = n.left;
            }
        }
        if (hitR) {
            if (n.rightCount > 0u) {
                if (intersectLeafAny(geoms, orig, dir, n.right, n.rightCount, tMin, tMax)) return true;
            } else if (next == gpu::kInvalidIndex) {
                next = n.right;
            } else {
                stack[stackSize] = n.right;
                ++stackSize;
            }
        }
        if (next == gpu::kInvalidIndex) {
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

Hit traceClosestWideCpu(const std::vector<gpu::BvhWideNode>& nodes,
                        const std::vector<gpu::TriangleGeom>& geoms, glm::vec3 orig, glm::vec3 dir,
                        float tMin, float tMax) {
    Hit hit = gpu::missHit(tMax);
    const glm::vec3 invDir = gpu::bvhSafeInverse(dir);
    uint32_t stackNode[gpu::kBvhWideStackSize];
    float stackNear[gpu::kBvhWideStackSize];
    uint32_t stackSize = 0;
    uint32_t node = 0;
    uint32_t visits = 0;
    while (true) {
        const gpu::BvhWideNode& n = nodes[node];
        ++visits;
        glm::vec4 tNear;
        glm::bvec4 h;
        gpu::wideNodeBoxes(n, orig, invDir, tMin, hit.t, tNear, h);
        const glm::uvec4 count = gpu::wideCounts(n);
        const glm::uvec4 c = gpu::wideLeafCounts(count, h);
        for (uint32_t k = 0u; k < c.x + c.y + c.z + c.w; ++k)
            closerHit(geoms, orig, dir, gpu::wideLeafTriangle(n.child, k, c), tMin, hit);
        const gpu::WideOrder o = gpu::wideSortInner(n, count, h, tNear, hit.t);
        uint32_t next = o.child.x;
        if (o.child.w != gpu::kInvalidIndex) {
            stackNode[stackSize] = o.child.w;
            stackNear[stackSize] = o.t.w;
            ++stackSize;
        }
        if (o.child.z != gpu::kInvalidIndex) {
            stackNode[stackSize] = o.child.z;
            stackNear[stackSize] = o.t.z;
            ++stackSize;
        }
        if (o.child.y != gpu::kInvalidIndex) {
            stackNode[stackSize] = o.child.y;
            stackNear[stackSize] = o.t.y;
            ++stackSize;
        }
        while (next == gpu::kInvalidIndex && stackSize > 0u) {
            --stackSize;
            if (stackNear[stackSize] <= hit.t) next = stackNode[stackSize];
        }
        if (next == gpu::kInvalidIndex) break;
        node = next;
    }
    tlsNodeVisits = visits;
    return hit;
}

bool traceAnyWideCpu(const std::vector<gpu::BvhWideNode>& nodes, const std::vector<gpu::TriangleGeom>& geoms,
                     glm::vec3 orig, glm::vec3 dir, float tMin, float tMax) {
    const glm::vec3 invDir = gpu::bvhSafeInverse(dir);
    uint32_t stackNode[gpu::kBvhWideStackSize];
    uint32_t stackSize = 0;
    uint32_t node = 0;
    tlsNodeVisits = 0;
    while (true) {
        const gpu::BvhWideNode& n = nodes[node];
        ++tlsNodeVisits;
        glm::vec4 tNear;
        glm::bvec4 h;
        gpu::wideNodeBoxes(n, orig, invDir, tMin, tMax, tNear, h);
        const glm::uvec4 count = gpu::wideCounts(n);
        const glm::uvec4 c = gpu::wideLeafCounts(count, h);
        for (uint32_t k = 0u; k < c.x + c.y + c.z + c.w; ++k)
            if (anyHitAt(geoms, orig, dir, gpu::wideLeafTriangle(n.child, k, c), tMin, tMax)) return true;
        uint32_t next = gpu::kInvalidIndex;
        for (glm::length_t j = 0; j < 4; ++j) {
            if (!(h[j] && count[j] == 0u)) continue;
            if (next == gpu::kInvalidIndex) {
                next = n.child[j];
            } else {
                stackNode[stackSize] = n.child[j];
                ++stackSize;
            }
        }
        if (next == gpu::kInvalidIndex) {
            if (stackSize == 0u) break;
            --stackSize;
            next = stackNode[stackSize];
        }
        node = next;
    }
    return false;
}

Hit traceClosestBruteForce(const std::vector<gpu::TriangleGeom>& geoms, glm::vec3 orig, glm::vec3 dir,
                           float tMin, float tMax) {
    Hit hit = gpu::missHit(tMax);
    for (size_t i = 0; i < geoms.size(); ++i)
        closerHit(geoms, orig, dir, static_cast<uint32_t>(i), tMin, hit);
    return hit;
}

bool traceAnyBruteForce(const std::vector<gpu::TriangleGeom>& geoms, glm::vec3 orig, glm::vec3 dir,
                        float tMin, float tMax) {
    for (size_t i = 0; i < geoms.size(); ++i)
        if (anyHitAt(geoms, orig, dir, static_cast<uint32_t>(i), tMin, tMax)) return true;
    return false;
}

uint32_t lastTraversalNodeVisits() {
    return tlsNodeVisits;
}

}  // namespace gdpt
