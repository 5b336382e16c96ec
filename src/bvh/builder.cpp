// builder.cpp — top-down binned SAH construction (Wald 2007, "On fast Construction of
// SAH-based Bounding Volume Hierarchies", IEEE RT'07), written straight into the two-wide
// gpu::BvhNode layout: a node stores the boxes of both children, and a child is either an
// inner node (count 0) or a leaf range of TriangleGeom (count > 0). One range's step (leaf or
// split: the bins, the SAH sweep, the partition) is sah_split.h's; this file builds the tree
// around it.
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

#include "bvh/sah_split.h"
#include "util/huge_pages.h"
#include "util/parallel.h"

namespace gdpt {

// The build's steps (sah_split.h) are its own.
using namespace bvh_build;

namespace {

constexpr float kFltMax = std::numeric_limits<float>::max();
// Ranges at least this large are split in the breadth-first top phase; the smaller ranges
// under them are the subtrees the threads build whole. The rule does not depend on the
// thread count, so the output is the same for any buildThreads.
constexpr uint32_t kTaskMinTriangles = 16384;
// Triangles per chunk when the references are made in parallel.
constexpr uint32_t kPrepChunk = 65536;
// Padding of triangle bounds, relative to a coordinate magnitude: 2^-18 = 32 float ulps.
// Applied twice: per triangle (its largest coordinate; covers the rounding of
// e1 = p1 - p0, <= 1 ulp) and per scene (the largest scene coordinate; covers the rounding
// error and edge widening of the ray/triangle test, ~2^-20 of the ray-to-triangle distance,
// see kEdgeTolerance in bvh_intersect.glsl, for rays starting within a few scene radii).
constexpr float kBoundsPad = 1.0f / 262144.0f;

// A child of a BvhNode under construction.
struct ChildRef {
    Box4 box;
    uint32_t index = gpu::kInvalidIndex;  // node index (count == 0) or first triangle
    uint32_t count = 0;
};

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
        const Decision d = decideRange(in_, r, depth, scratch_, 1);
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
            decisions[i] = decideRange(in_, p.range, p.depth, scratch[i], binThreads);
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
