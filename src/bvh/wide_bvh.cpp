#include "bvh/wide_bvh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

#include "lib/bvh_intersect.glsl"
#include "util/huge_pages.h"
#include "util/parallel.h"

namespace gdpt {
namespace {

struct Slot {
    glm::vec3 min, max;
    uint32_t index;  // binary node (count 0) or first triangle
    uint32_t count;  // 0 = inner
};

// Lower bound on the biased exponent of a quantisation scale: 2^-126, the smallest normal.
constexpr int kMinBiasedExponent = 1;
// Upper bound: 255 · 2^(246 - 127) is still finite, so no decoded bound becomes infinite.
constexpr int kMaxBiasedExponent = 246;

// The kernels' scale of a biased exponent and their decode of one bound (byte 0 of q), so
// that the builder checks its rounding against exactly what the traversal computes.
float scaleOf(int biased) {
    return gpu::wideAxisScale(static_cast<uint32_t>(biased), 0u);
}

// q·scale is exact (an 8-bit integer times a power of two), so origin + q·scale is one
// rounding, the same in the kernels' vector form (gpu::wideDecodeAxis) and here.
float decode(float origin, uint32_t q, float scale) {
    return origin + float(q) * scale;
}

// The smallest power-of-two scale whose 255 steps from origin reach `top` (biased exponent).
int axisExponent(float origin, float top) {
    const float extent = top - origin;
    int biased = 127;
    if (extent > 0.0f) {
        int e = 0;
        (void)std::frexp(extent / 255.0f, &e);  // extent / 255 < 2^e
        biased = std::clamp(e + 127, kMinBiasedExponent, kMaxBiasedExponent);
        while (biased > kMinBiasedExponent && decode(origin, 255u, scaleOf(biased - 1)) >= top) --biased;
        while (biased < kMaxBiasedExponent && decode(origin, 255u, scaleOf(biased)) < top) ++biased;
    }
    if (!(decode(origin, 255u, scaleOf(biased)) >= top))
        throw std::invalid_argument("collapseToWide: a node extends over more than a float's range");
    return biased;
}

// Largest q whose decoded bound is <= v (a lower bound) or smallest whose bound is >= v.
// floor/ceil in double are already right whenever v - origin is exact in double (rounding
// to float is monotonic); the loops check the float decode itself for the other cases.
// (v - origin) / scale is computed as a product with `inverse` = 1 / scale: the same value,
// scale being a power of two.
uint32_t quantiseDown(float origin, float scale, double inverse, float v) {
    auto q = static_cast<uint32_t>(std::clamp(std::floor((double(v) - origin) * inverse), 0.0, 255.0));
    while (q > 0 && decode(origin, q, scale) > v) --q;
    return q;
}
uint32_t quantiseUp(float origin, float scale, double inverse, float v) {
    auto q = static_cast<uint32_t>(std::clamp(std::ceil((double(v) - origin) * inverse), 0.0, 255.0));
    while (q < 255 && decode(origin, q, scale) < v) ++q;
    return q;
}

float halfArea(const Slot& s) {
    const glm::vec3 e = s.max - s.min;
    return e.x * e.y + e.y * e.z + e.z * e.x;
}

// The wide node of up to four child boxes: origin = their union's lower corner, per axis the
// scale of axisExponent and each bound rounded outwards (BvhWideNode). Children and counts
// are left for the caller (empty slots keep kInvalidIndex).
// The children of one wide node under construction (at most four: a node starts from its
// binary node's two children and replaces one inner child by two while it has fewer than four).
struct Slots {
    std::array<Slot, 4> slot{};
    std::size_t count = 0;
    std::size_t size() const { return count; }
    const Slot& operator[](std::size_t i) const { return slot[i]; }
    void push(const Slot& s) { slot[count++] = s; }
    void erase(std::size_t i) {
        for (std::size_t k = i + 1; k < count; ++k) slot[k - 1] = slot[k];
        --count;
    }
};

gpu::BvhWideNode quantiseWideNode(const Slots& slots) {
    const std::size_t count = slots.size();
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (std::size_t i = 0; i < count; ++i) {
        lo = glm::min(lo, slots[i].min);
        hi = glm::max(hi, slots[i].max);
    }
    gpu::BvhWideNode w{};
    w.child = glm::uvec4(gpu::kInvalidIndex);
    w.origin = count > 0 ? lo : glm::vec3(0.0f);
    for (glm::length_t a = 0; a < 3; ++a) {
        const int biased = count > 0 ? axisExponent(w.origin[a], hi[a]) : 127;
        w.exponents |= static_cast<uint32_t>(biased) << (8 * a);
        const float scale = scaleOf(biased);
        const double inverse = 1.0 / double(scale);
        for (std::size_t i = 0; i < count; ++i) {
            const auto shift = static_cast<uint32_t>(8 * i);
            w.qMin[a] |= quantiseDown(w.origin[a], scale, inverse, slots[i].min[a]) << shift;
            w.qMax[a] |= quantiseUp(w.origin[a], scale, inverse, slots[i].max[a]) << shift;
        }
    }
    return w;
}

// The four children of binary node b's wide node: its two children, then repeatedly the inner
// child of largest surface area replaced by its own two children.
Slots gatherSlots(const std::vector<gpu::BvhNode>& binary, uint32_t b) {
    auto addChildren = [](const gpu::BvhNode& n, Slots& slots) {
        if (n.left != gpu::kInvalidIndex) slots.push({n.lmin, n.lmax, n.left, n.leftCount});
        if (n.right != gpu::kInvalidIndex) slots.push({n.rmin, n.rmax, n.right, n.rightCount});
    };
    Slots slots;
    addChildren(binary[b], slots);
    while (slots.size() < 4) {
        std::size_t best = slots.size();
        for (std::size_t i = 0; i < slots.size(); ++i)
            if (slots[i].count == 0 && (best == slots.size() || halfArea(slots[i]) > halfArea(slots[best])))
                best = i;
        if (best == slots.size()) break;
        const uint32_t inner = slots[best].index;
        slots.erase(best);
        addChildren(binary[inner], slots);
    }
    return slots;
}

uint32_t innerSlots(const Slots& slots) {
    uint32_t inner = 0;
    for (std::size_t i = 0; i < slots.size(); ++i) inner += slots[i].count == 0 ? 1u : 0u;
    return inner;
}

// Inner binary nodes in the subtree of b (b included).
std::size_t binarySubtreeSize(const std::vector<gpu::BvhNode>& binary, uint32_t b) {
    std::size_t size = 0;
    std::vector<uint32_t> stack{b};
    while (!stack.empty()) {
        const gpu::BvhNode& n = binary[stack.back()];
        stack.pop_back();
        ++size;
        if (n.leftCount == 0 && n.left != gpu::kInvalidIndex) stack.push_back(n.left);
        if (n.rightCount == 0 && n.right != gpu::kInvalidIndex) stack.push_back(n.right);
    }
    return size;
}

// A wide subtree collapsed on its own (node indices local, root at 0), to be appended.
struct WideSubtree {
    uint32_t binary = 0;  // its root's binary node
    uint32_t depth = 0;   // depth of the root's children
    uint32_t stack = 0;   // stack entries a traversal may hold on reaching the root
    WideBvh tree;
};

class Collapser {
public:
    // `ready`: subtrees collapsed beforehand, by binary root, appended instead of collapsed.
    Collapser(const std::vector<gpu::BvhNode>& binary, std::size_t reserve,
              const std::map<uint32_t, const WideSubtree*>* ready = nullptr)
        : binary_(binary), ready_(ready) {
        reserveHuge(out_.nodes, reserve);
    }

    // Emits the wide node for binary node `b`; returns its index. `depth` is the depth of
    // its children, `stack` the entries a traversal may hold on reaching it.
    uint32_t emit(uint32_t b, uint32_t depth, uint32_t stack) {
        if (ready_) {
            const auto it = ready_->find(b);
            if (it != ready_->end()) return append(it->second->tree);
        }
        const Slots slots = gatherSlots(binary_, b);
        const auto me = static_cast<uint32_t>(out_.nodes.size());
        out_.nodes.emplace_back();
        const uint32_t inner = innerSlots(slots);
        // Visiting this node pushes every inner child but the one it descends into.
        const uint32_t below = stack + (inner > 0 ? inner - 1 : 0);
        out_.maxStack = std::max(out_.maxStack, below);
        gpu::BvhWideNode w = quantiseWideNode(slots);
        for (std::size_t i = 0; i < slots.size(); ++i) {
            const auto k = static_cast<glm::length_t>(i);
            const Slot& s = slots[i];
            w.qMin.w |= s.count << (8u * static_cast<uint32_t>(i));
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
    uint32_t append(const WideBvh& sub) {
        const auto offset = static_cast<uint32_t>(out_.nodes.size());
        for (gpu::BvhWideNode n : sub.nodes) {
            for (glm::length_t k = 0; k < 4; ++k) {
                const uint32_t count = (n.qMin.w >> (8u * static_cast<uint32_t>(k))) & 255u;
                if (count == 0 && n.child[k] != gpu::kInvalidIndex) n.child[k] += offset;
            }
            out_.nodes.push_back(n);
        }
        out_.maxStack = std::max(out_.maxStack, sub.maxStack);
        out_.maxDepth = std::max(out_.maxDepth, sub.maxDepth);
        return offset;
    }

    const std::vector<gpu::BvhNode>& binary_;
    const std::map<uint32_t, const WideSubtree*>* ready_;
    WideBvh out_;
};

// Wide subtrees below the top kParallelLevels wide levels are collapsed on their own, in
// parallel, when the tree is large; the result is the same as one depth-first collapse.
constexpr uint32_t kParallelLevels = 2;
constexpr std::size_t kParallelMinNodes = 16384;

void collectSubtrees(const std::vector<gpu::BvhNode>& binary, uint32_t b, uint32_t depth, uint32_t stack,
                     uint32_t level, std::vector<WideSubtree>& out) {
    const Slots slots = gatherSlots(binary, b);
    const uint32_t inner = innerSlots(slots);
    const uint32_t below = stack + (inner > 0 ? inner - 1 : 0);
    for (std::size_t i = 0; i < slots.size(); ++i) {
        if (slots[i].count > 0) continue;
        if (level + 1 == kParallelLevels) {
            out.push_back(WideSubtree{slots[i].index, depth + 1, below, {}});
        } else {
            collectSubtrees(binary, slots[i].index, depth + 1, below, level + 1, out);
        }
    }
}

}  // namespace

WideBvh collapseToWide(const std::vector<gpu::BvhNode>& binary, uint32_t threads) {
    if (binary.empty()) throw std::invalid_argument("collapseToWide: the binary tree has no root");
    threads = defaultThreads(threads);
    std::vector<WideSubtree> subtrees;
    if (threads > 1 && binary.size() >= kParallelMinNodes) collectSubtrees(binary, 0, 1, 0, 0, subtrees);
    // quantiseWideNode throws for a node too large to quantise; parallelFor rethrows it.
    parallelFor(threads, subtrees.size(), [&](std::size_t i) {
        WideSubtree& t = subtrees[i];
        Collapser c(binary, binarySubtreeSize(binary, t.binary));
        c.emit(t.binary, t.depth, t.stack);
        t.tree = c.take();
    });
    std::map<uint32_t, const WideSubtree*> ready;
    for (const WideSubtree& t : subtrees) ready[t.binary] = &t;
    Collapser c(binary, binary.size(), &ready);
    c.emit(0, 1, 0);
    WideBvh w = c.take();
    if (w.maxStack > gpu::kBvhWideStackSize)
        throw std::invalid_argument("collapseToWide: a traversal of this tree could need " +
                                    std::to_string(w.maxStack) + " stack entries, more than the kernels' " +
                                    std::to_string(gpu::kBvhWideStackSize));
    return w;
}

WideChildBox wideChildBox(const gpu::BvhWideNode& node, int k) {
    const auto slot = static_cast<glm::length_t>(k);
    const glm::vec3 scale(gpu::wideAxisScale(node.exponents, 0u), gpu::wideAxisScale(node.exponents, 1u),
                          gpu::wideAxisScale(node.exponents, 2u));
    WideChildBox b;
    b.min = {gpu::wideDecodeAxis(node.origin.x, node.qMin.x, scale.x)[slot],
             gpu::wideDecodeAxis(node.origin.y, node.qMin.y, scale.y)[slot],
             gpu::wideDecodeAxis(node.origin.z, node.qMin.z, scale.z)[slot]};
    b.max = {gpu::wideDecodeAxis(node.origin.x, node.qMax.x, scale.x)[slot],
             gpu::wideDecodeAxis(node.origin.y, node.qMax.y, scale.y)[slot],
             gpu::wideDecodeAxis(node.origin.z, node.qMax.z, scale.z)[slot]};
    return b;
}

}  // namespace gdpt
