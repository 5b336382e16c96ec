// traverse_cpu.h — host reference for ray queries against the flattened BVH: closest-hit
// and any-hit traversal of the binary tree (builder.h) and of the four-wide tree the kernels
// use (a statement-for-statement mirror of traceClosest / traceAny in
// shaders/lib/bvh_traverse.glsl), and brute-force loops over all triangles. Used by tests and
// for debugging; the ray/triangle and ray/box tests are the GLSL functions themselves,
// compiled as C++ (gdpt::gpu::intersectTriangleGeom, gdpt::gpu::intersectBox).
#pragma once

#include <vector>

#include "gdpt_shared.h"
#include "lib/bvh_intersect.glsl"

namespace gdpt {

using gpu::Hit;

// Ray (orig, dir) against one TriangleGeom; see gpu::intersectTriangleGeom.
bool intersectTriangleCpu(const gpu::TriangleGeom& g, glm::vec3 orig, glm::vec3 dir, float tMin, float& tMax,
                          float& u, float& v);

// Closest hit with tMin < t < tMax; Hit::triangle indexes `geoms` (leaf order), or is
// kInvalidIndex on a miss. `nodes` must contain at least the root.
Hit traceClosestCpu(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriangleGeom>& geoms,
                    glm::vec3 orig, glm::vec3 dir, float tMin, float tMax);

// True if any triangle is hit with tMin < t < tMax.
bool traceAnyCpu(const std::vector<gpu::BvhNode>& nodes, const std::vector<gpu::TriangleGeom>& geoms,
                 glm::vec3 orig, glm::vec3 dir, float tMin, float tMax);

// The same queries on the four-wide tree the kernels traverse (wide_bvh.h): a
// statement-for-statement mirror of traceClosest / traceAny in bvh_traverse.glsl.
Hit traceClosestWideCpu(const std::vector<gpu::BvhWideNode>& nodes,
                        const std::vector<gpu::TriangleGeom>& geoms, glm::vec3 orig, glm::vec3 dir,
                        float tMin, float tMax);
bool traceAnyWideCpu(const std::vector<gpu::BvhWideNode>& nodes, const std::vector<gpu::TriangleGeom>& geoms,
                     glm::vec3 orig, glm::vec3 dir, float tMin, float tMax);

// Brute force over every triangle in index order; among equal t the lowest index wins.
Hit traceClosestBruteForce(const std::vector<gpu::TriangleGeom>& geoms, glm::vec3 orig, glm::vec3 dir,
                           float tMin, float tMax);
bool traceAnyBruteForce(const std::vector<gpu::TriangleGeom>& geoms, glm::vec3 orig, glm::vec3 dir,
                        float tMin, float tMax);

// Number of nodes visited by the last traversal call (binary or wide) on this thread
// (diagnostics for the benchmark).
uint32_t lastTraversalNodeVisits();

}  // namespace gdpt
