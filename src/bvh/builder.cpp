// builder.cpp — top-down binned SAH construction (Wald 2007, "On fast Construction of
// SAH-based Bounding Volume Hierarchies", IEEE RT'07), written straight into the two-wide
// gpu::BvhNode layout: a node stores the boxes of both children, and a child is either an
// inner node (count 0) or a leaf range of TriangleGeom (count > 0).
//
// Depth guarantee: a child at depth d holding n > L triangles (L = leaf limit) needs
// levels(n) = ceil(log2(ceil(n / L))) more levels if split by count halves. SAH splits are
// allowed only while d + levels(n) < D (D = maxDepth <= kBvhMaxDepth); otherwise the node is
// split at the object median, which keeps d + levels(n) <= D for all descendants (the
// halves need one level less). Hence no leaf is deeper than D and the traversal stack (one
// entry per level) fits in kBvhStackSize.
#include "bvh/builder.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>

#include "util/interrupt.h"

namespace gdpt {
namespace {

constexpr float kFltMax = std::numeric_limits<float>::max();
constexpr uint32_t kMaxBins = 256;
// Subtrees of at least this many triangles in the top kSeparateDepth levels are built into
// their own node arrays (possibly on another thread) and appended afterwards. The rule does
// not depend on the thread count, so the output is the same for any buildThreads.
constexpr uint32_t kSeparateMinTriangles = 16384;
constexpr uint32_t kSeparateDepth = 4;
// Subtrees at least this large poll the interrupt flag (util/interrupt.h) when they start.
constexpr uint32_t kInterruptPollMinTriangles = 1024;
// Padding of triangle bounds, relative to a coordinate magnitude: 2^-18 = 32 float ulps.
// Applied twice: per triangle (its largest coordinate; covers the rounding of
// e1 = p1 - p0, <= 1 ulp) and per scene (the largest scene coordinate; covers the rounding
// error and edge widening of the ray/triangle test, ~2^-20 of the ray-to-triangle distance,
// see kEdgeTolerance in bvh_traverse.glsl, for rays starting within a few scene radii).
constexpr float kBoundsPad = 1.0f / 262144.0f;
// Centroid bins: scale by (1 - 2^-20) so the largest centroid stays in the last bin.
constexpr float kBinScale = 1.0f - 1.0f / 1048576.0f;

struct Aabb {
    glm::vec3 lo{kFltMax};
    glm::vec3 hi{-kFltMax};

    void grow(const glm::vec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    void grow(const Aabb& b) {
        lo = glm::min(lo, b.lo);
        hi = glm::max(hi, b.hi);
    }
    bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    // Half the surface area: the SAH only needs ratios of areas.
    float halfArea() const {
        if (empty()) {
            return 0.0f;
        }
        glm::vec3 d = hi - lo;
        return d.x * d.y + d.y * d.z + d.z * d.x;
    }
};

// A child of a BvhNode under construction.
struct ChildRef {
    Aabb box;
    uint32_t index = gpu::kInvalidIndex;  // node index (count == 0) or first triangle
    uint32_t count = 0;
};

// Triangles order[begin, end) with their bounds and centroid bounds.
struct Range {
    uint32_t begin = 0;
    uint32_t end = 0;
    Aabb box;
    Aabb centroids;
    uint32_t size() const { return end - begin; }
};

struct BuildInput {
    const std::vector<Aabb>& primBoxes;
    const std::vector<glm::vec3>& centroids;
    std::vector<uint32_t>& order;  // ranges are disjoint between threads
    uint32_t leafMax;
    uint32_t binCount;
    uint32_t maxDepth;
    float traversalCost;
    float intersectCost;
};

uint32_t ceilLog2(uint64_t x) {
    uint32_t levels = 0;
    while ((uint64_t{1} << levels) < x) {
        ++levels;
    }
    return levels;
}

// Bin of a centroid coordinate; the same expression is used for binning and partitioning.
uint32_t binOf(float c, float lo, float scale, uint32_t binCount) {
    auto b = static_cast<uint32_t>((c - lo) * scale);
    return std::min(b, binCount - 1);
}

Range makeRange(const BuildInput& in, uint32_t begin, uint32_t end) {
    Range r;
    r.begin = begin;
    r.end = end;
    for (uint32_t i = begin; i < end; ++i) {
        uint32_t t = in.order[i];
        r.box.grow(in.primBoxes[t]);
        r.centroids.grow(in.centroids[t]);
    }
    return r;
}

class SubtreeBuilder {
public:
    SubtreeBuilder(const BuildInput& in, uint32_t threads) : in_(in), threads_(threads) {}

    // Builds the child for `r` at depth `depth` (an inner node created here sits at `depth`,
    // its children at depth + 1). Inner node indices are local to nodes_.
    ChildRef build(const Range& r, uint32_t depth);

    std::vector<gpu::BvhNode> nodes_;
    uint32_t leafCount_ = 0;
    uint32_t maxDepth_ = 0;
    double sahSum_ = 0.0;  // sum of cost * halfArea over nodes and leaves

private:
    struct Split {
        bool found = false;
        int axis = 0;
        uint32_t bin = 0;  // bins [0, bin) go left
        float costScaled = kFltMax;
    };
    Split findSahSplit(const Range& r);
    ChildRef makeLeaf(const Range& r, uint32_t depth);
    ChildRef appendSubtree(SubtreeBuilder& sub, ChildRef ref);

    const BuildInput& in_;
    uint32_t threads_;
    std::vector<Aabb> binBox_;
    std::vector<uint32_t> binCount_;
};

// Wald 2007 §3: bin centroids into binCount slabs per axis, sweep to evaluate the SAH at the
// binCount - 1 planes of each axis. Costs are scaled by the parent area (no division, so
// zero-area parents work): cost = Ct * A + Ci * (A_L * N_L + A_R * N_R).
SubtreeBuilder::Split SubtreeBuilder::findSahSplit(const Range& r) {
    const uint32_t bins = in_.binCount;
    // Scratch reused across nodes: binBox_[a * bins + b], binCount_[a * bins + b].
    binBox_.assign(3 * bins, Aabb{});
    binCount_.assign(3 * bins, 0u);
    glm::vec3 extent = r.centroids.hi - r.centroids.lo;
    glm::vec3 scale(0.0f);
    for (int a = 0; a < 3; ++a) {
        scale[a] = extent[a] > 0.0f ? float(bins) * kBinScale / extent[a] : 0.0f;
    }
    for (uint32_t i = r.begin; i < r.end; ++i) {
        uint32_t t = in_.order[i];
        for (int a = 0; a < 3; ++a) {
            uint32_t b = binOf(in_.centroids[t][a], r.centroids.lo[a], scale[a], bins);
            binBox_[a * bins + b].grow(in_.primBoxes[t]);
            ++binCount_[a * bins + b];
        }
    }
    Split best;
    std::array<float, kMaxBins> rightCost{};
    for (int a = 0; a < 3; ++a) {
        if (!(extent[a] > 0.0f)) {
            continue;
        }
        // Right sweep: rightCost[b] = A(bins [b, n)) * N(bins [b, n)).
        Aabb acc;
        uint32_t count = 0;
        for (uint32_t b = bins - 1; b > 0; --b) {
            acc.grow(binBox_[a * bins + b]);
            count += binCount_[a * bins + b];
            rightCost[b] = acc.halfArea() * float(count);
        }
        acc = Aabb{};
        count = 0;
        for (uint32_t b = 1; b < bins; ++b) {
            acc.grow(binBox_[a * bins + b - 1]);
            count += binCount_[a * bins + b - 1];
            uint32_t rightN = r.size() - count;
            if (count == 0 || rightN == 0) {
                continue;
            }
            float cost = in_.traversalCost * r.box.halfArea() +
                         in_.intersectCost * (acc.halfArea() * float(count) + rightCost[b]);
            if (cost < best.costScaled) {
                best = Split{true, a, b, cost};
            }
        }
    }
    return best;
}

ChildRef SubtreeBuilder::makeLeaf(const Range& r, uint32_t depth) {
    ++leafCount_;
    maxDepth_ = std::max(maxDepth_, depth);
    sahSum_ += double(in_.intersectCost) * double(r.size()) * double(r.box.halfArea());
    return ChildRef{r.box, r.begin, r.size()};
}

// Appends a separately built subtree's nodes after ours, shifting its inner-node indices.
ChildRef SubtreeBuilder::appendSubtree(SubtreeBuilder& sub, ChildRef ref) {
    auto offset = static_cast<uint32_t>(nodes_.size());
    for (gpu::BvhNode n : sub.nodes_) {
        if (n.leftCount == 0 && n.left != gpu::kInvalidIndex) {
            n.left += offset;
        }
        if (n.rightCount == 0 && n.right != gpu::kInvalidIndex) {
            n.right += offset;
        }
        nodes_.push_back(n);
    }
    if (ref.count == 0) {
        ref.index += offset;
    }
    leafCount_ += sub.leafCount_;
    maxDepth_ = std::max(maxDepth_, sub.maxDepth_);
    sahSum_ += sub.sahSum_;
    return ref;
}

ChildRef SubtreeBuilder::build(const Range& r, uint32_t depth) {
    const uint32_t n = r.size();
    // SIGINT/SIGTERM: large subtrees poll (a relaxed load per ~thousand triangles' work);
    // an exception in a worker thread reaches the caller below.
    if (n >= kInterruptPollMinTriangles && interruptRequested()) throw Interrupted("building the BVH");
    const bool centroidsCoincide = !(r.centroids.hi.x > r.centroids.lo.x) &&
                                   !(r.centroids.hi.y > r.centroids.lo.y) &&
                                   !(r.centroids.hi.z > r.centroids.lo.z);
    if (n <= in_.leafMax && (n == 1 || depth >= in_.maxDepth || centroidsCoincide)) {
        return makeLeaf(r, depth);
    }
    // Median split when SAH cannot separate the centroids or the depth budget is tight.
    const uint64_t leavesNeeded = (uint64_t{n} + in_.leafMax - 1) / in_.leafMax;
    bool median = centroidsCoincide || depth + ceilLog2(leavesNeeded) + 1 > in_.maxDepth;
    uint32_t mid = 0;
    if (!median) {
        Split s = findSahSplit(r);
        float leafCostScaled = in_.intersectCost * float(n) * r.box.halfArea();
        if (n <= in_.leafMax && (!s.found || leafCostScaled <= s.costScaled)) {
            return makeLeaf(r, depth);
        }
        if (s.found) {
            const int a = s.axis;
            const float lo = r.centroids.lo[a];
            const float extent = r.centroids.hi[a] - lo;
            const float scale = float(in_.binCount) * kBinScale / extent;
            auto first = in_.order.begin() + r.begin;
            auto it = std::partition(first, in_.order.begin() + r.end, [&](uint32_t t) {
                return binOf(in_.centroids[t][a], lo, scale, in_.binCount) < s.bin;
            });
            mid = static_cast<uint32_t>(it - in_.order.begin());
        }
        median = mid <= r.begin || mid >= r.end;  // no usable SAH plane (cannot happen)
    }
    if (median) {
        // Object median on the axis of largest centroid extent (arbitrary if all coincide).
        glm::vec3 e = r.centroids.hi - r.centroids.lo;
        int a = (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
        mid = r.begin + n / 2;
        std::nth_element(in_.order.begin() + r.begin, in_.order.begin() + mid, in_.order.begin() + r.end,
                         [&](uint32_t x, uint32_t y) { return in_.centroids[x][a] < in_.centroids[y][a]; });
    }
    const Range left = makeRange(in_, r.begin, mid);
    const Range right = makeRange(in_, mid, r.end);

    const auto self = static_cast<uint32_t>(nodes_.size());
    nodes_.emplace_back();
    sahSum_ += double(in_.traversalCost) * double(r.box.halfArea());
    ChildRef l;
    ChildRef rr;
    if (depth < kSeparateDepth && n >= kSeparateMinTriangles) {
        uint32_t threadsLeft = threads_ / 2;
        SubtreeBuilder lb(in_, std::max(threadsLeft, 1u));
        SubtreeBuilder rb(in_, std::max(threads_ - threadsLeft, 1u));
        if (threads_ > 1) {
            std::exception_ptr error;
            std::thread worker([&] {
                try {
                    l = lb.build(left, depth + 1);
                } catch (...) {
                    error = std::current_exception();
                }
            });
            try {
                rr = rb.build(right, depth + 1);
            } catch (...) {
                worker.join();
                throw;
            }
            worker.join();
            if (error) {
                std::rethrow_exception(error);
            }
        } else {
            l = lb.build(left, depth + 1);
            rr = rb.build(right, depth + 1);
        }
        l = appendSubtree(lb, l);
        rr = appendSubtree(rb, rr);
    } else {
        l = build(left, depth + 1);
        rr = build(right, depth + 1);
    }
    gpu::BvhNode& node = nodes_[self];
    node.lmin = l.box.lo;
    node.lmax = l.box.hi;
    node.left = l.index;
    node.leftCount = l.count;
    node.rmin = rr.box.lo;
    node.rmax = rr.box.hi;
    node.right = rr.index;
    node.rightCount = rr.count;
    return ChildRef{r.box, self, 0};
}

gpu::BvhNode emptyNode() {
    gpu::BvhNode n{};
    n.lmin = n.rmin = glm::vec3(kFltMax);
    n.lmax = n.rmax = glm::vec3(-kFltMax);
    n.left = n.right = gpu::kInvalidIndex;
    n.leftCount = n.rightCount = 0;
    return n;
}

}  // namespace

void triangleBounds(glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3& lo, glm::vec3& hi) {
    lo = glm::min(p0, glm::min(p1, p2));
    hi = glm::max(p0, glm::max(p1, p2));
    glm::vec3 mag = glm::max(glm::abs(lo), glm::abs(hi));
    glm::vec3 pad(std::max(mag.x, std::max(mag.y, mag.z)) * kBoundsPad);
    lo -= pad;
    hi += pad;
}

Bvh buildBvh(const std::vector<glm::vec3>& positions, const std::vector<glm::uvec3>& triangles,
             const BvhBuildOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    if (triangles.size() >= gpu::kInvalidIndex) {
        throw std::invalid_argument("buildBvh: too many triangles (" + std::to_string(triangles.size()) +
                                    ")");
    }
    const auto count = static_cast<uint32_t>(triangles.size());
    std::vector<Aabb> primBoxes(count);
    std::vector<glm::vec3> centroids(count);
    for (uint32_t t = 0; t < count; ++t) {
        const glm::uvec3 tri = triangles[t];
        if (tri.x >= positions.size() || tri.y >= positions.size() || tri.z >= positions.size()) {
            throw std::invalid_argument("buildBvh: triangle " + std::to_string(t) +
                                        " has a vertex index >= " + std::to_string(positions.size()));
        }
        Aabb& b = primBoxes[t];
        triangleBounds(positions[tri.x], positions[tri.y], positions[tri.z], b.lo, b.hi);
        glm::vec3 d = b.hi - b.lo;
        if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z)) {
            throw std::invalid_argument("buildBvh: triangle " + std::to_string(t) +
                                        " has a non-finite or too large vertex");
        }
    }
    // Scene-wide padding (see kBoundsPad), then centroids of the padded boxes.
    Aabb scene;
    for (const Aabb& b : primBoxes) {
        scene.grow(b);
    }
    const glm::vec3 mag = glm::max(glm::abs(scene.lo), glm::abs(scene.hi));
    const glm::vec3 scenePad(std::max(mag.x, std::max(mag.y, mag.z)) * kBoundsPad);
    for (uint32_t t = 0; t < count; ++t) {
        primBoxes[t].lo -= scenePad;
        primBoxes[t].hi += scenePad;
        centroids[t] = (primBoxes[t].lo + primBoxes[t].hi) * 0.5f;
    }

    Bvh bvh;
    bvh.triangleOrder.resize(count);
    for (uint32_t t = 0; t < count; ++t) {
        bvh.triangleOrder[t] = t;
    }
    uint32_t threads = options.buildThreads;
    if (threads == 0) {
        threads = std::max(1u, std::thread::hardware_concurrency());
    }
    const uint32_t leafMax = std::clamp(options.maxLeafSize, 1u, gpu::kMaxLeafTriangles);
    // The shallowest possible tree has its leaves at depth levels(count) (>= 1).
    const uint32_t minDepth = std::max(1u, ceilLog2((uint64_t{count} + leafMax - 1) / leafMax));
    BuildInput in{primBoxes,
                  centroids,
                  bvh.triangleOrder,
                  leafMax,
                  std::clamp(options.binCount, 2u, kMaxBins),
                  std::clamp(options.maxDepth, minDepth, gpu::kBvhMaxDepth),
                  options.traversalCost,
                  options.intersectCost};
    SubtreeBuilder builder(in, threads);
    Aabb sceneBox;
    if (count == 0) {
        builder.nodes_.push_back(emptyNode());
    } else {
        const Range root = makeRange(in, 0, count);
        sceneBox = root.box;
        ChildRef ref = builder.build(root, 0);
        if (ref.count > 0) {
            // The whole mesh is one leaf: it becomes the left child of the root node.
            gpu::BvhNode node = emptyNode();
            node.lmin = ref.box.lo;
            node.lmax = ref.box.hi;
            node.left = ref.index;
            node.leftCount = ref.count;
            builder.nodes_.push_back(node);
            builder.maxDepth_ = 1;
            builder.sahSum_ += double(in.traversalCost) * double(ref.box.halfArea());
        }
    }
    bvh.nodes = std::move(builder.nodes_);
    bvh.stats.nodeCount = static_cast<uint32_t>(bvh.nodes.size());
    bvh.stats.leafCount = builder.leafCount_;
    bvh.stats.maxDepth = builder.maxDepth_;
    const double rootArea = sceneBox.halfArea();
    bvh.stats.sahCost = float(rootArea > 0.0 ? builder.sahSum_ / rootArea : builder.sahSum_);
    bvh.stats.buildMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return bvh;
}

std::vector<gpu::TriangleGeom> makeTriangleGeoms(const std::vector<glm::vec3>& positions,
                                                 const std::vector<glm::uvec3>& triangles,
                                                 const std::vector<uint32_t>& triangleOrder) {
    std::vector<gpu::TriangleGeom> geoms(triangleOrder.size());
    for (size_t i = 0; i < triangleOrder.size(); ++i) {
        const glm::uvec3 tri = triangles.at(triangleOrder[i]);
        const glm::vec3 p0 = positions.at(tri.x);
        gpu::TriangleGeom& g = geoms[i];
        g.v0 = p0;
        g.e1 = positions.at(tri.y) - p0;
        g.e2 = positions.at(tri.z) - p0;
        g.pad0 = g.pad1 = g.pad2 = 0.0f;
    }
    return geoms;
}

}  // namespace gdpt
