#include "bvh/wide_bvh.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace gdpt {
namespace {

struct Slot {
    glm::vec3 min, max;
    uint32_t index;  // binary node (count 0) or first triangle
    uint32_t count;  // 0 = inner
};

float halfArea(const Slot& s) {
    const glm::vec3 e = s.max - s.min;
    return e.x * e.y + e.y * e.z + e.z * e.x;
}

class Collapser {
public:
    explicit Collapser(const std::vector<gpu::BvhNode>& binary) : binary_(binary) {}

    // Emits the wide node for binary node `b`; returns its index. `depth` is the depth of
    // its children, `stack` the entries a traversal may hold on reaching it.
    uint32_t emit(uint32_t b, uint32_t depth, uint32_t stack) {
        std::vector<Slot> slots;
        addChildren(binary_[b], slots);
        while (slots.size() < 4) {
            auto best = slots.end();
            for (auto it = slots.begin(); it != slots.end(); ++it)
                if (it->count == 0 && (best == slots.end() || halfArea(*it) > halfArea(*best))) best = it;
            if (best == slots.end()) break;
            const uint32_t inner = best->index;
            slots.erase(best);
            addChildren(binary_[inner], slots);
        }
        const auto me = static_cast<uint32_t>(out_.nodes.size());
        out_.nodes.emplace_back();
        const auto inner = static_cast<uint32_t>(
            std::count_if(slots.begin(), slots.end(), [](const Slot& s) { return s.count == 0; }));
        // Visiting this node pushes every inner child but the one it descends into.
        const uint32_t below = stack + (inner > 0 ? inner - 1 : 0);
        out_.maxStack = std::max(out_.maxStack, below);
        gpu::BvhWideNode w{};
        w.child = glm::uvec4(gpu::kInvalidIndex);
        w.count = glm::uvec4(0u);
        for (std::size_t i = 0; i < slots.size(); ++i) {
            const auto k = static_cast<glm::length_t>(i);
            const Slot& s = slots[i];
            w.minX[k] = s.min.x;
            w.minY[k] = s.min.y;
            w.minZ[k] = s.min.z;
            w.maxX[k] = s.max.x;
            w.maxY[k] = s.max.y;
            w.maxZ[k] = s.max.z;
            w.count[k] = s.count;
            if (s.count > 0) {
                w.child[k] = s.index;
                out_.maxDepth = std::max(out_.maxDepth, depth);
            } else {
                w.child[k] = emit(s.index, depth + 1, below);
            }
        }
        out_.nodes[me] = w;
        return me;
    }

    WideBvh take() { return std::move(out_); }

private:
    static void addChildren(const gpu::BvhNode& n, std::vector<Slot>& slots) {
        if (n.left != gpu::kInvalidIndex) slots.push_back({n.lmin, n.lmax, n.left, n.leftCount});
        if (n.right != gpu::kInvalidIndex) slots.push_back({n.rmin, n.rmax, n.right, n.rightCount});
    }

    const std::vector<gpu::BvhNode>& binary_;
    WideBvh out_;
};

}  // namespace

WideBvh collapseToWide(const std::vector<gpu::BvhNode>& binary) {
    if (binary.empty()) throw std::invalid_argument("collapseToWide: the binary tree has no root");
    Collapser c(binary);
    c.emit(0, 1, 0);
    WideBvh w = c.take();
    if (w.maxStack > gpu::kBvhWideStackSize)
        throw std::invalid_argument("collapseToWide: a traversal of this tree could need " + std::to_string(w.maxStack) +
                                    " stack entries, more than the kernels' " +
                                    std::to_string(gpu::kBvhWideStackSize));
    return w;
}

}  // namespace gdpt
