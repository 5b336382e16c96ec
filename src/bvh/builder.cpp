// builder.cpp — top-down binned SAH construction (Wald 2007, "On fast Construction of
// SAH-based Bounding Volume Hierarchies", IEEE RT'07), written straight into the two-wide
// gpu::BvhNode layout: a node stores the boxes of both children, and a child is either an
// inner node (count 0) or a leaf range of TriangleGeom (count > 0).
//
// Data layout (as Embree's builders keep their PrimRefs): every triangle becomes a 32-byte
// reference holding its padded box and its index; splits partition these references in place,
// so each level streams through contiguous memory instead of gathering boxes through an index
// array, and binning and the box arithmetic run on four-float registers (float4.h).
//
// Threads: ranges of at least kTaskMinTriangles are split breadth-first, one level at a time,
// the ranges of a level in parallel (a lone range is binned by all threads); the smaller
// ranges below them are built as whole subtrees, in parallel, and every piece is put in place
// in depth-first order at the end. Every split depends only on the set of triangles in its
// range, so the tree is the same for any thread count.
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
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "bvh/float4.h"
#include "util/huge_pages.h"
#include "util/interrupt.h"
#include "util/parallel.h"

namespace gdpt {
namespace {

using bvh_simd::add4;
using bvh_simd::Box4;
using bvh_simd::Float4;
using bvh_simd::load4;
using bvh_simd::loadXyz;
using bvh_simd::mul4;
using bvh_simd::splat4;
using bvh_simd::store4;
using bvh_simd::sub4;

constexpr float kFltMax = std::numeric_limits<float>::max();
constexpr uint32_t kMaxBins = 256;
// Ranges at least this large are split in the breadth-first top phase; the smaller ranges
// under them are the subtrees the threads build whole. The rule does not depend on the
// thread count, so the output is the same for any buildThreads.
constexpr uint32_t kTaskMinTriangles = 16384;
// A top-phase level of fewer ranges than threads bins each range on all threads when it has
// at least this many triangles per thread.
constexpr uint32_t kParallelBinMinTriangles = 16384;
// Triangles per chunk when the references are made in parallel.
constexpr uint32_t kPrepChunk = 65536;
// Subtrees at least this large poll the interrupt flag (util/interrupt.h) when they start.
constexpr uint32_t kInterruptPollMinTriangles = 1024;
// Padding of triangle bounds, relative to a coordinate magnitude: 2^-18 = 32 float ulps.
// Applied twice: per triangle (its largest coordinate; covers the rounding of
// e1 = p1 - p0, <= 1 ulp) and per scene (the largest scene coordinate; covers the rounding
// error and edge widening of the ray/triangle test, ~2^-20 of the ray-to-triangle distance,
// see kEdgeTolerance in bvh_intersect.glsl, for rays starting within a few scene radii).
constexpr float kBoundsPad = 1.0f / 262144.0f;
// Centroid bins: scale by (1 - 2^-20) so the largest centroid stays in the last bin.
constexpr float kBinScale = 1.0f - 1.0f / 1048576.0f;

// A triangle's padded box; lo[3] holds the triangle's index (its bits), hi[3] is zero.
struct alignas(32) PrimRef {
    float lo[4];
    float hi[4];
};

uint32_t primIndex(const PrimRef& p) {
    uint32_t t = 0;
    std::memcpy(&t, &p.lo[3], sizeof t);
    return t;
}

Float4 primLo(const PrimRef& p) {
    return loadXyz(p.lo);
}
Float4 primHi(const PrimRef& p) {
    return load4(p.hi);
}
Float4 centroidOf(const PrimRef& p) {
    return mul4(add4(primLo(p), primHi(p)), splat4(0.5f));
}
// The same value as lane `axis` of centroidOf.
float centroidOf(const PrimRef& p, int axis) {
    return (p.lo[axis] + p.hi[axis]) * 0.5f;
}

// A child of a BvhNode under construction.
struct ChildRef {
    Box4 box;
    uint32_t index = gpu::kInvalidIndex;  // node index (count == 0) or first triangle
    uint32_t count = 0;
};

// References [begin, end) with their bounds and centroid bounds.
struct Range {
    uint32_t begin = 0;
    uint32_t end = 0;
    Box4 box;
    Box4 centroids;
    uint32_t size() const { return end - begin; }
};

struct BuildInput {
    PrimRef* refs;  // ranges are disjoint between threads
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

// Centroid bins of one range: per axis, the box and count of the triangles whose centroid falls
// in each of binCount equal slabs of the range's centroid bounds.
struct Bins {
    std::array<Box4, 3 * kMaxBins> box;
    std::array<uint32_t, 3 * kMaxBins> count;
};

struct BinMapping {
    float lo[4];
    float scale[4];
};

BinMapping binMapping(const Range& r, uint32_t binCount) {
    BinMapping m{};
    alignas(16) float lo[4];
    alignas(16) float hi[4];
    store4(lo, r.centroids.lo);
    store4(hi, r.centroids.hi);
    for (int a = 0; a < 3; ++a) {
        const float extent = hi[a] - lo[a];
        m.lo[a] = lo[a];
        m.scale[a] = extent > 0.0f ? float(binCount) * kBinScale / extent : 0.0f;
    }
    return m;
}

void clearBins(Bins& bins, uint32_t binCount) {
    for (uint32_t a = 0; a < 3; ++a) {
        for (uint32_t b = 0; b < binCount; ++b) {
            bins.box[a * kMaxBins + b] = Box4{};
            bins.count[a * kMaxBins + b] = 0;
        }
    }
}

// Adds references [begin, end) to `bins` (Wald 2007 §3).
void binRefs(const PrimRef* refs, uint32_t begin, uint32_t end, const BinMapping& m, uint32_t binCount,
             Bins& bins) {
    const Float4 lo = load4(m.lo);
    const Float4 scale = load4(m.scale);
    alignas(16) std::int32_t idx[4];
    const auto last = static_cast<std::int32_t>(binCount - 1);
    for (uint32_t i = begin; i < end; ++i) {
        const PrimRef& p = refs[i];
        const Float4 pLo = primLo(p);
        const Float4 pHi = primHi(p);
        bvh_simd::truncate4(mul4(sub4(mul4(add4(pLo, pHi), splat4(0.5f)), lo), scale), idx);
        for (int a = 0; a < 3; ++a) {
            const auto b =
                static_cast<uint32_t>(a) * kMaxBins + static_cast<uint32_t>(std::min(idx[a], last));
            bins.box[b].grow(pLo, pHi);
            ++bins.count[b];
        }
    }
}

void mergeBins(Bins& into, const Bins& from, uint32_t binCount) {
    for (uint32_t a = 0; a < 3; ++a) {
        for (uint32_t b = 0; b < binCount; ++b) {
            into.box[a * kMaxBins + b].grow(from.box[a * kMaxBins + b]);
            into.count[a * kMaxBins + b] += from.count[a * kMaxBins + b];
        }
    }
}

struct Split {
    bool found = false;
    int axis = 0;
    uint32_t bin = 0;  // bins [0, bin) go left
    float costScaled = kFltMax;
};

// Sweeps the binCount - 1 planes of each axis. Costs are scaled by the parent area (no
// division, so zero-area parents work): cost = Ct * A + Ci * (A_L * N_L + A_R * N_R).
Split findSahSplit(const BuildInput& in, const Range& r, const Bins& bins, const BinMapping& m) {
    const uint32_t n = in.binCount;
    Split best;
    std::array<float, kMaxBins> rightCost{};
    const float parentArea = r.box.halfArea();
    for (uint32_t a = 0; a < 3; ++a) {
        if (!(m.scale[a] > 0.0f)) {
            continue;
        }
        // Right sweep: rightCost[b] = A(bins [b, n)) * N(bins [b, n)).
        Box4 acc;
        uint32_t count = 0;
        for (uint32_t b = n - 1; b > 0; --b) {
            acc.grow(bins.box[a * kMaxBins + b]);
            count += bins.count[a * kMaxBins + b];
            rightCost[b] = acc.halfArea() * float(count);
        }
        acc = Box4{};
        count = 0;
        for (uint32_t b = 1; b < n; ++b) {
            acc.grow(bins.box[a * kMaxBins + b - 1]);
            count += bins.count[a * kMaxBins + b - 1];
            const uint32_t rightN = r.size() - count;
            if (count == 0 || rightN == 0) {
                continue;
            }
            const float cost = in.traversalCost * parentArea +
                               in.intersectCost * (acc.halfArea() * float(count) + rightCost[b]);
            if (cost < best.costScaled) {
                best = Split{true, static_cast<int>(a), b, cost};
            }
        }
    }
    return best;
}

// Bounds of references [begin, end).
Range makeRange(const PrimRef* refs, uint32_t begin, uint32_t end) {
    Range r;
    r.begin = begin;
    r.end = end;
    for (uint32_t i = begin; i < end; ++i) {
        r.box.grow(primLo(refs[i]), primHi(refs[i]));
        r.centroids.grow(centroidOf(refs[i]));
    }
    return r;
}

// Moves the references of `r` whose centroid lies in bins [0, s.bin) of axis s.axis to the
// front, growing each side's bounds on the way; returns the first reference of the right side.
uint32_t partitionRefs(const BuildInput& in, const Range& r, const Split& s, const BinMapping& m, Range& left,
                       Range& right) {
    const int a = s.axis;
    const float lo = m.lo[a];
    const float scale = m.scale[a];
    PrimRef* refs = in.refs;
    auto goesLeft = [&](const PrimRef& p) { return binOf(centroidOf(p, a), lo, scale, in.binCount) < s.bin; };
    auto addTo = [](Range& side, const PrimRef& p) {
        side.box.grow(primLo(p), primHi(p));
        side.centroids.grow(centroidOf(p));
    };
    uint32_t i = r.begin;
    uint32_t j = r.end;
    for (;;) {
        while (i < j && goesLeft(refs[i])) addTo(left, refs[i++]);
        while (i < j && !goesLeft(refs[j - 1])) addTo(right, refs[--j]);
        if (i >= j) break;
        // refs[i] goes right and refs[j - 1] left (and i < j - 1): exchange them.
        std::swap(refs[i], refs[j - 1]);
        addTo(left, refs[i++]);
        addTo(right, refs[--j]);
    }
    left.begin = r.begin;
    left.end = i;
    right.begin = i;
    right.end = r.end;
    return i;
}

// How a range is built: as one leaf, or split in two.
struct Decision {
    bool leaf = false;
    Range left;
    Range right;
};

// Decides the range `r` at depth `depth`, partitioning its references for a split. `scratch`
// holds one Bins per thread that may bin this range (binThreads >= 1).
Decision decide(const BuildInput& in, const Range& r, uint32_t depth, std::vector<Bins>& scratch,
                uint32_t binThreads) {
    Decision d;
    const uint32_t n = r.size();
    // SIGINT/SIGTERM: large subtrees poll (a relaxed load per ~thousand triangles' work);
    // an exception in a worker thread reaches the caller.
    if (n >= kInterruptPollMinTriangles && interruptRequested()) throw Interrupted("building the BVH");
    alignas(16) float clo[4];
    alignas(16) float chi[4];
    store4(clo, r.centroids.lo);
    store4(chi, r.centroids.hi);
    const bool centroidsCoincide = !(chi[0] > clo[0]) && !(chi[1] > clo[1]) && !(chi[2] > clo[2]);
    if (n <= in.leafMax && (n == 1 || depth >= in.maxDepth || centroidsCoincide)) {
        d.leaf = true;
        return d;
    }
    // Median split when SAH cannot separate the centroids or the depth budget is tight.
    const uint64_t leavesNeeded = (uint64_t{n} + in.leafMax - 1) / in.leafMax;
    bool median = centroidsCoincide || depth + ceilLog2(leavesNeeded) + 1 > in.maxDepth;
    if (!median) {
        const BinMapping m = binMapping(r, in.binCount);
        const uint32_t chunks = std::max(1u, std::min(binThreads, n / kParallelBinMinTriangles));
        if (scratch.size() < chunks) scratch.resize(chunks);
        parallelFor(chunks, chunks, [&](size_t c) {
            const uint32_t b0 = r.begin + static_cast<uint32_t>(uint64_t{n} * c / chunks);
            const uint32_t b1 = r.begin + static_cast<uint32_t>(uint64_t{n} * (c + 1) / chunks);
            clearBins(scratch[c], in.binCount);
            binRefs(in.refs, b0, b1, m, in.binCount, scratch[c]);
        });
        for (uint32_t c = 1; c < chunks; ++c) mergeBins(scratch[0], scratch[c], in.binCount);
        const Split s = findSahSplit(in, r, scratch[0], m);
        const float leafCostScaled = in.intersectCost * float(n) * r.box.halfArea();
        if (n <= in.leafMax && (!s.found || leafCostScaled <= s.costScaled)) {
            d.leaf = true;
            return d;
        }
        if (s.found) {
            const uint32_t mid = partitionRefs(in, r, s, m, d.left, d.right);
            median = mid <= r.begin || mid >= r.end;  // no usable SAH plane (cannot happen)
        } else {
            median = true;
        }
    }
    if (median) {
        // Object median on the axis of largest centroid extent (arbitrary if all coincide).
        const float ex = chi[0] - clo[0];
        const float ey = chi[1] - clo[1];
        const float ez = chi[2] - clo[2];
        const int a = (ex >= ey && ex >= ez) ? 0 : (ey >= ez ? 1 : 2);
        const uint32_t mid = r.begin + n / 2;
        std::nth_element(
            in.refs + r.begin, in.refs + mid, in.refs + r.end,
            [a](const PrimRef& x, const PrimRef& y) { return centroidOf(x, a) < centroidOf(y, a); });
        d.left = makeRange(in.refs, r.begin, mid);
        d.right = makeRange(in.refs, mid, r.end);
    }
    return d;
}

void setChild(gpu::BvhNode& node, int side, const ChildRef& c) {
    alignas(16) float lo[4];
    alignas(16) float hi[4];
    store4(lo, c.box.lo);
    store4(hi, c.box.hi);
    const glm::vec3 mn(lo[0], lo[1], lo[2]);
    const glm::vec3 mx(hi[0], hi[1], hi[2]);
    if (side == 0) {
        node.lmin = mn;
        node.lmax = mx;
        node.left = c.index;
        node.leftCount = c.count;
    } else {
        node.rmin = mn;
        node.rmax = mx;
        node.right = c.index;
        node.rightCount = c.count;
    }
}

// Nodes of a tree or subtree in depth-first order, with the statistics of what they hold.
struct NodeList {
    std::vector<gpu::BvhNode> nodes;
    uint32_t leafCount = 0;
    uint32_t maxDepth = 0;
    double sahSum = 0.0;  // sum of cost * halfArea over nodes and leaves
};

// Builds a whole subtree on the calling thread.
class SubtreeBuilder {
public:
    explicit SubtreeBuilder(const BuildInput& in) : in_(in), scratch_(1) {}

    // Builds the child for `r` at depth `depth` (an inner node created here sits at `depth`,
    // its children at depth + 1). Inner node indices are local to out.nodes.
    ChildRef build(const Range& r, uint32_t depth, NodeList& out) {
        const Decision d = decide(in_, r, depth, scratch_, 1);
        if (d.leaf) {
            ++out.leafCount;
            out.maxDepth = std::max(out.maxDepth, depth);
            out.sahSum += double(in_.intersectCost) * double(r.size()) * double(r.box.halfArea());
            return ChildRef{r.box, r.begin, r.size()};
        }
        const auto self = static_cast<uint32_t>(out.nodes.size());
        out.nodes.emplace_back();
        out.sahSum += double(in_.traversalCost) * double(r.box.halfArea());
        const ChildRef l = build(d.left, depth + 1, out);
        const ChildRef rr = build(d.right, depth + 1, out);
        setChild(out.nodes[self], 0, l);
        setChild(out.nodes[self], 1, rr);
        return ChildRef{r.box, self, 0};
    }

private:
    const BuildInput& in_;
    std::vector<Bins> scratch_;
};

// The top of the tree, split breadth-first: a piece is either a split range (two child
// pieces) or a subtree built whole.
struct Piece {
    Range range;
    uint32_t depth = 0;
    bool split = false;
    std::array<uint32_t, 2> child{};  // piece indices, when split
    NodeList subtree;                 // when not split
    ChildRef subtreeRoot;
};

class TopBuilder {
public:
    TopBuilder(const BuildInput& in, uint32_t threads) : in_(in), threads_(threads) {}

    NodeList build(const Range& root) {
        pieces_.push_back(Piece{root, 0, false, {}, {}, {}});
        std::vector<uint32_t> level;
        if (root.size() >= kTaskMinTriangles) level.push_back(0);
        std::vector<uint32_t> tasks;
        if (level.empty()) tasks.push_back(0);
        while (!level.empty()) {
            splitLevel(level);
            std::vector<uint32_t> next;
            for (const uint32_t p : level) {
                if (!pieces_[p].split) {
                    tasks.push_back(p);
                    continue;
                }
                for (const uint32_t c : pieces_[p].child) {
                    (pieces_[c].range.size() >= kTaskMinTriangles ? next : tasks).push_back(c);
                }
            }
            level = std::move(next);
        }
        // Largest subtrees first, so that the last ones to finish are small.
        std::stable_sort(tasks.begin(), tasks.end(), [this](uint32_t x, uint32_t y) {
            return pieces_[x].range.size() > pieces_[y].range.size();
        });
        parallelFor(threads_, tasks.size(), [&](size_t i) {
            Piece& p = pieces_[tasks[i]];
            // A binary tree over n leaves has n - 1 inner nodes: reserving that touches no page
            // the subtree does not use, and the nodes are never moved as the vector grows.
            reserveHuge(p.subtree.nodes, p.range.size());
            SubtreeBuilder sub(in_);
            p.subtreeRoot = sub.build(p.range, p.depth, p.subtree);
        });
        NodeList out;
        size_t total = 0;
        for (const Piece& p : pieces_) total += p.split ? 1 : p.subtree.nodes.size();
        reserveHuge(out.nodes, total + 1);  // + 1: the root node of a one-leaf mesh
        rootRef_ = place(0, out);
        return out;
    }

    // The root's child reference (a leaf when the whole mesh is one).
    const ChildRef& rootRef() const { return rootRef_; }

private:
    // Decides every range of one level: the ranges in parallel, or a lone range binned by
    // every thread.
    void splitLevel(const std::vector<uint32_t>& level) {
        const uint32_t binThreads =
            level.size() < threads_ ? std::max(1u, threads_ / uint32_t(level.size())) : 1u;
        std::vector<Decision> decisions(level.size());
        std::vector<std::vector<Bins>> scratch(level.size());
        parallelFor(binThreads > 1 ? 1u : threads_, level.size(), [&](size_t i) {
            const Piece& p = pieces_[level[i]];
            decisions[i] = decide(in_, p.range, p.depth, scratch[i], binThreads);
        });
        for (size_t i = 0; i < level.size(); ++i) {
            if (decisions[i].leaf) continue;  // built as a subtree (a leaf) later
            const uint32_t p = level[i];
            const uint32_t depth = pieces_[p].depth + 1;
            const auto l = static_cast<uint32_t>(pieces_.size());
            pieces_.push_back(Piece{decisions[i].left, depth, false, {}, {}, {}});
            pieces_.push_back(Piece{decisions[i].right, depth, false, {}, {}, {}});
            pieces_[p].split = true;
            pieces_[p].child = {l, l + 1};
        }
    }

    // Appends piece p's nodes to `out` in depth-first order and returns its child reference.
    ChildRef place(uint32_t p, NodeList& out) {
        Piece& piece = pieces_[p];
        if (!piece.split) {
            const auto offset = static_cast<uint32_t>(out.nodes.size());
            for (gpu::BvhNode n : piece.subtree.nodes) {
                if (n.leftCount == 0 && n.left != gpu::kInvalidIndex) n.left += offset;
                if (n.rightCount == 0 && n.right != gpu::kInvalidIndex) n.right += offset;
                out.nodes.push_back(n);
            }
            out.leafCount += piece.subtree.leafCount;
            out.maxDepth = std::max(out.maxDepth, piece.subtree.maxDepth);
            out.sahSum += piece.subtree.sahSum;
            ChildRef ref = piece.subtreeRoot;
            if (ref.count == 0) ref.index += offset;
            piece.subtree = NodeList{};
            return ref;
        }
        const auto self = static_cast<uint32_t>(out.nodes.size());
        out.nodes.emplace_back();
        out.sahSum += double(in_.traversalCost) * double(piece.range.box.halfArea());
        const std::array<uint32_t, 2> child = piece.child;
        const ChildRef l = place(child[0], out);
        const ChildRef r = place(child[1], out);
        setChild(out.nodes[self], 0, l);
        setChild(out.nodes[self], 1, r);
        return ChildRef{pieces_[p].range.box, self, 0};
    }

    const BuildInput& in_;
    uint32_t threads_;
    std::vector<Piece> pieces_;  // [0] is the root
    ChildRef rootRef_;
};

gpu::BvhNode emptyNode() {
    gpu::BvhNode n{};
    n.lmin = n.rmin = glm::vec3(kFltMax);
    n.lmax = n.rmax = glm::vec3(-kFltMax);
    n.left = n.right = gpu::kInvalidIndex;
    n.leftCount = n.rightCount = 0;
    return n;
}

// The padded references of every triangle and the root range; throws for a bad vertex index
// or a non-finite vertex, naming the first such triangle.
Range makeRefs(const std::vector<glm::vec3>& positions, const std::vector<glm::uvec3>& triangles,
               PrimRef* refs, uint32_t threads) {
    const auto count = static_cast<uint32_t>(triangles.size());
    const size_t chunks = (size_t{count} + kPrepChunk - 1) / kPrepChunk;
    std::vector<Box4> chunkBox(chunks);
    std::vector<std::string> chunkError(chunks);
    parallelRanges(threads, count, kPrepChunk, [&](size_t begin, size_t end) {
        const size_t c = begin / kPrepChunk;
        Box4 box;
        for (auto t = static_cast<uint32_t>(begin); t < end; ++t) {
            const glm::uvec3 tri = triangles[t];
            if (tri.x >= positions.size() || tri.y >= positions.size() || tri.z >= positions.size()) {
                chunkError[c] = "buildBvh: triangle " + std::to_string(t) +
                                " has a vertex index >= " + std::to_string(positions.size());
                return;
            }
            glm::vec3 lo;
            glm::vec3 hi;
            triangleBounds(positions[tri.x], positions[tri.y], positions[tri.z], lo, hi);
            const glm::vec3 d = hi - lo;
            if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z)) {
                chunkError[c] =
                    "buildBvh: triangle " + std::to_string(t) + " has a non-finite or too large vertex";
                return;
            }
            PrimRef& p = refs[t];
            p.lo[0] = lo.x;
            p.lo[1] = lo.y;
            p.lo[2] = lo.z;
            std::memcpy(&p.lo[3], &t, sizeof t);
            p.hi[0] = hi.x;
            p.hi[1] = hi.y;
            p.hi[2] = hi.z;
            p.hi[3] = 0.0f;
            box.grow(primLo(p), primHi(p));
        }
        chunkBox[c] = box;
    });
    for (const std::string& e : chunkError) {
        if (!e.empty()) throw std::invalid_argument(e);
    }
    // Scene-wide padding (see kBoundsPad); the centroids are those of the padded boxes.
    Box4 scene;
    for (const Box4& b : chunkBox) scene.grow(b);
    alignas(16) float slo[4];
    alignas(16) float shi[4];
    store4(slo, scene.lo);
    store4(shi, scene.hi);
    float mag = 0.0f;
    for (int a = 0; a < 3; ++a) mag = std::max(mag, std::max(std::abs(slo[a]), std::abs(shi[a])));
    const float pad = mag * kBoundsPad;
    std::vector<Range> chunkRange(chunks);
    parallelRanges(threads, count, kPrepChunk, [&](size_t begin, size_t end) {
        for (size_t t = begin; t < end; ++t) {
            PrimRef& p = refs[t];
            for (int a = 0; a < 3; ++a) {
                p.lo[a] -= pad;
                p.hi[a] += pad;
            }
        }
        chunkRange[begin / kPrepChunk] =
            makeRange(refs, static_cast<uint32_t>(begin), static_cast<uint32_t>(end));
    });
    Range root;
    root.begin = 0;
    root.end = count;
    for (const Range& r : chunkRange) {
        root.box.grow(r.box);
        root.centroids.grow(r.centroids);
    }
    return root;
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

namespace {

struct GrowBox {
    glm::vec3 lo{std::numeric_limits<float>::max()};
    glm::vec3 hi{-std::numeric_limits<float>::max()};
    void grow(glm::vec3 l, glm::vec3 h) {
        lo = glm::min(lo, l);
        hi = glm::max(hi, h);
    }
};

// The grown box of a child (a node, or a leaf's triangle range), its own box included.
GrowBox grownChild(Bvh& bvh, const std::vector<glm::vec3>& positions,
                   const std::vector<glm::uvec3>& triangles, uint32_t child, uint32_t count, glm::vec3 lo,
                   glm::vec3 hi);

// Grows node `n`'s two child boxes (post-order: depth <= kBvhMaxDepth) and returns their union.
GrowBox growNode(Bvh& bvh, const std::vector<glm::vec3>& positions, const std::vector<glm::uvec3>& triangles,
                 uint32_t n) {
    gpu::BvhNode node = bvh.nodes[n];
    const GrowBox l = grownChild(bvh, positions, triangles, node.left, node.leftCount, node.lmin, node.lmax);
    const GrowBox r =
        grownChild(bvh, positions, triangles, node.right, node.rightCount, node.rmin, node.rmax);
    node.lmin = l.lo;
    node.lmax = l.hi;
    node.rmin = r.lo;
    node.rmax = r.hi;
    bvh.nodes[n] = node;
    GrowBox both = l;
    both.grow(r.lo, r.hi);
    return both;
}

GrowBox grownChild(Bvh& bvh, const std::vector<glm::vec3>& positions,
                   const std::vector<glm::uvec3>& triangles, uint32_t child, uint32_t count, glm::vec3 lo,
                   glm::vec3 hi) {
    GrowBox box;
    box.grow(lo, hi);
    if (count == 0) {
        const GrowBox inner = growNode(bvh, positions, triangles, child);
        box.grow(inner.lo, inner.hi);
        return box;
    }
    for (uint32_t i = child; i < child + count; ++i) {
        const glm::uvec3 t = triangles[bvh.triangleOrder[i]];
        glm::vec3 tl, th;
        triangleBounds(positions[t.x], positions[t.y], positions[t.z], tl, th);
        box.grow(tl, th);
    }
    return box;
}

}  // namespace

void growBvhBoxes(Bvh& bvh, const std::vector<glm::vec3>& positions,
                  const std::vector<glm::uvec3>& triangles) {
    if (bvh.triangleOrder.size() != triangles.size())
        throw std::invalid_argument("growBvhBoxes: the tree holds " +
                                    std::to_string(bvh.triangleOrder.size()) +
                                    " triangles, the positions are of " + std::to_string(triangles.size()));
    if (!bvh.nodes.empty()) growNode(bvh, positions, triangles, 0);
}

Bvh buildBvh(const std::vector<glm::vec3>& positions, const std::vector<glm::uvec3>& triangles,
             const BvhBuildOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    if (triangles.size() >= gpu::kInvalidIndex) {
        throw std::invalid_argument("buildBvh: too many triangles (" + std::to_string(triangles.size()) +
                                    ")");
    }
    const auto count = static_cast<uint32_t>(triangles.size());
    const uint32_t threads = defaultThreads(options.buildThreads);
    // Left uninitialised: makeRefs writes every reference, on every thread (so the pages are
    // first touched in parallel, and only once).
    const std::unique_ptr<PrimRef[]> refs(new PrimRef[triangles.size()]);
    adviseHugePages(refs.get(), triangles.size() * sizeof(PrimRef));
    const Range root = makeRefs(positions, triangles, refs.get(), threads);

    const uint32_t leafMax = std::clamp(options.maxLeafSize, 1u, gpu::kMaxLeafTriangles);
    // The shallowest possible tree has its leaves at depth levels(count) (>= 1).
    const uint32_t minDepth = std::max(1u, ceilLog2((uint64_t{count} + leafMax - 1) / leafMax));
    const BuildInput in{refs.get(),
                        leafMax,
                        std::clamp(options.binCount, 2u, kMaxBins),
                        std::clamp(options.maxDepth, minDepth, gpu::kBvhMaxDepth),
                        options.traversalCost,
                        options.intersectCost};
    NodeList list;
    if (count == 0) {
        list.nodes.push_back(emptyNode());
    } else {
        TopBuilder top(in, threads);
        list = top.build(root);
        const ChildRef& ref = top.rootRef();
        if (ref.count > 0) {
            // The whole mesh is one leaf: it becomes the left child of the root node.
            gpu::BvhNode node = emptyNode();
            setChild(node, 0, ref);
            list.nodes.push_back(node);
            list.maxDepth = 1;
            list.sahSum += double(in.traversalCost) * double(ref.box.halfArea());
        }
    }
    Bvh bvh;
    bvh.triangleOrder.resize(count);
    for (uint32_t i = 0; i < count; ++i) bvh.triangleOrder[i] = primIndex(refs[i]);
    bvh.nodes = std::move(list.nodes);
    bvh.stats.nodeCount = static_cast<uint32_t>(bvh.nodes.size());
    bvh.stats.leafCount = list.leafCount;
    bvh.stats.maxDepth = list.maxDepth;
    const double rootArea = root.box.halfArea();
    bvh.stats.sahCost = float(rootArea > 0.0 ? list.sahSum / rootArea : list.sahSum);
    bvh.stats.buildMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return bvh;
}

void writeTriangleGeoms(const std::vector<glm::vec3>& positions, const std::vector<glm::uvec3>& triangles,
                        const std::vector<uint32_t>& triangleOrder, size_t begin, size_t end,
                        gpu::TriangleGeom* out) {
    for (size_t i = begin; i < end; ++i) {
        const glm::uvec3 tri = triangles.at(triangleOrder[i]);
        const glm::vec3 p0 = positions.at(tri.x);
        gpu::TriangleGeom& g = out[i - begin];
        g.v0 = p0;
        g.e1 = positions.at(tri.y) - p0;
        g.e2 = positions.at(tri.z) - p0;
        g.pad0 = g.pad1 = g.pad2 = 0.0f;
    }
}

std::vector<gpu::TriangleGeom> makeTriangleGeoms(const std::vector<glm::vec3>& positions,
                                                 const std::vector<glm::uvec3>& triangles,
                                                 const std::vector<uint32_t>& triangleOrder) {
    std::vector<gpu::TriangleGeom> geoms(triangleOrder.size());
    writeTriangleGeoms(positions, triangles, triangleOrder, 0, triangleOrder.size(), geoms.data());
    return geoms;
}

}  // namespace gdpt
