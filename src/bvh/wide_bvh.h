// wide_bvh.h — the four-wide BVH the kernels traverse: the binary binned-SAH tree of
// builder.h collapsed into gpu::BvhWideNode (each wide node adopts grandchildren until it has
// four children or only leaves), over the same leaf-ordered TriangleGeom array, with each
// node's child boxes quantised to 8 bits per bound and rounded outwards.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "gdpt_shared.h"

namespace gdpt {

struct WideBvh {
    std::vector<gpu::BvhWideNode> nodes;  // node 0 is the root
    uint32_t maxStack = 0;                // most stack entries a traversal of this tree can hold
    uint32_t maxDepth = 0;                // deepest leaf; children of the root have depth 1
};

// Collapse of `binary` (a builder.h tree, root = node 0): a wide node starts from its binary
// node's children and repeatedly replaces the inner child of largest surface area by that
// child's two children while it has fewer than four. Leaves keep their triangle ranges.
// Throws std::invalid_argument if a traversal could need more than gpu::kBvhWideStackSize
// entries (bounded here by the sum over a root-to-leaf path of each node's inner children
// minus one; the binary depth cap keeps real trees far below it).
// The slab bounds also throw std::invalid_argument if a node is too large for a finite
// 8-bit quantisation (extents beyond about 2^127).
// threads: 0 = hardware concurrency; large trees collapse the subtrees under the top two wide
// levels in parallel. The result is the same for every value.
WideBvh collapseToWide(const std::vector<gpu::BvhNode>& binary, uint32_t threads = 0);

// Child k's box as the kernels decode it (gpu::wideDecodeAxis); meaningless for an empty slot.
struct WideChildBox {
    glm::vec3 min, max;
};
WideChildBox wideChildBox(const gpu::BvhWideNode& node, int k);

}  // namespace gdpt
