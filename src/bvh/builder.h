// builder.h — binned-SAH BVH construction over a triangle mesh, flattened directly into the
// two-wide gpu::BvhNode layout of gdpt_shared.h (root = node 0), plus the leaf-ordered
// TriangleGeom array that the traversal (shaders/lib/bvh_traverse.glsl, traverse_cpu.h) reads.
#pragma once

#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "gdpt_shared.h"

namespace gdpt {

// Build parameters. Defaults were chosen with gdpt_bvh_bench (see bench/bvh_bench_notes.md):
// the CPU traversal is used as a proxy for the GPU one.
struct BvhBuildOptions {
    uint32_t maxLeafSize = 4;    // leaf triangle limit (clamped to [1, kMaxLeafTriangles])
    uint32_t binCount = 16;      // centroid bins per axis (Wald 2007), clamped to [2, 256]
    float traversalCost = 1.0f;  // SAH cost of visiting one node (testing its two boxes)
    float intersectCost = 1.0f;  // SAH cost of one ray/triangle test
    // Depth limit (leaf depth; children of the root have depth 1). Clamped to
    // kBvhMaxDepth, and raised if the mesh cannot fit in a tree that shallow. Lower values
    // only serve tests of the depth cap.
    uint32_t maxDepth = gpu::kBvhMaxDepth;
    // Worker threads for the top levels of the build: 0 = hardware concurrency, 1 = serial.
    // The result is identical for every value.
    uint32_t buildThreads = 0;
};

struct BvhStats {
    uint32_t nodeCount = 0;  // number of gpu::BvhNode (inner nodes, including the root)
    uint32_t leafCount = 0;  // number of leaf children
    uint32_t maxDepth = 0;   // deepest leaf; children of the root have depth 1
    float sahCost = 0.0f;    // SAH cost of the tree, relative to the root box (Wald 2007)
    double buildMs = 0.0;    // wall-clock build time in milliseconds
};

struct Bvh {
    std::vector<gpu::BvhNode> nodes;      // node 0 is the root
    std::vector<uint32_t> triangleOrder;  // [i] = original triangle placed at leaf position i
    BvhStats stats;
};

// Builds the BVH of `triangles` (vertex indices into `positions`, world space). Every
// triangle is placed in exactly one leaf, including zero-area ones. Throws
// std::invalid_argument if a vertex index is out of range. An empty mesh gives a root whose
// two children are absent.
Bvh buildBvh(const std::vector<glm::vec3>& positions, const std::vector<glm::uvec3>& triangles,
             const BvhBuildOptions& options = {});

// Intersection data in leaf order: result[i] describes triangles[triangleOrder[i]] as
// v0 = p0, e1 = p1 - p0, e2 = p2 - p0 (float arithmetic, as the builder's bounds assume).
std::vector<gpu::TriangleGeom> makeTriangleGeoms(const std::vector<glm::vec3>& positions,
                                                 const std::vector<glm::uvec3>& triangles,
                                                 const std::vector<uint32_t>& triangleOrder);

// The same for leaf positions [begin, end) only, written to out[0, end - begin) (callers fill
// one table in parallel ranges, or straight into mapped device memory).
void writeTriangleGeoms(const std::vector<glm::vec3>& positions, const std::vector<glm::uvec3>& triangles,
                        const std::vector<uint32_t>& triangleOrder, size_t begin, size_t end,
                        gpu::TriangleGeom* out);

// Conservative bounds of the triangle that the intersector actually tests, i.e.
// (v0, v0 + e1, v0 + e2) with e1, e2 rounded as in makeTriangleGeoms, padded by 2^-18 of its
// largest coordinate magnitude (the builder adds a scene-wide pad on top). Exposed for the
// structural tests.
void triangleBounds(glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3& lo, glm::vec3& hi);

// Grows every box of `bvh` (built over some positions of `triangles`) so that it also holds its
// triangles at `positions` (the same triangles moved: another frame of an animation), keeping
// the tree and its leaf order. A ray query of either set of positions is then exact on the one
// tree. Throws std::invalid_argument if the tree's triangle order does not fit `triangles`.
void growBvhBoxes(Bvh& bvh, const std::vector<glm::vec3>& positions,
                  const std::vector<glm::uvec3>& triangles);

}  // namespace gdpt
