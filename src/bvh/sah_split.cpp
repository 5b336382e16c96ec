// sah_split.cpp — one step of the binned SAH build (sah_split.h).
#include "bvh/sah_split.h"

#include <algorithm>
#include <limits>

#include "util/interrupt.h"
#include "util/parallel.h"

namespace gdpt::bvh_build {
namespace {

constexpr float kFltMax = std::numeric_limits<float>::max();
// A range binned on several threads has at least this many triangles per thread.
constexpr uint32_t kParallelBinMinTriangles = 16384;
// Subtrees at least this large poll the interrupt flag (util/interrupt.h) when they start.
constexpr uint32_t kInterruptPollMinTriangles = 1024;
// Centroid bins: scale by (1 - 2^-20) so the largest centroid stays in the last bin.
constexpr float kBinScale = 1.0f - 1.0f / 1048576.0f;

// Bin of a centroid coordinate; the same expression is used for binning and partitioning.
uint32_t binOf(float c, float lo, float scale, uint32_t binCount) {
    auto b = static_cast<uint32_t>((c - lo) * scale);
    return std::min(b, binCount - 1);
}

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

}  // namespace

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

Decision decideRange(const BuildInput& in, const Range& r, uint32_t depth, std::vector<Bins>& scratch,
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

}  // namespace gdpt::bvh_build
