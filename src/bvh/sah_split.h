// sah_split.h — one step of the binned SAH build (Wald 2007, "On fast Construction of SAH-based
// Bounding Volume Hierarchies", IEEE RT'07): whether a range of triangle references becomes a
// leaf or is split in two, and the split itself, partitioning the references in place.
// builder.cpp makes the references and the tree around these steps. Internal to gdpt_bvh.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

#include "bvh/float4.h"

namespace gdpt::bvh_build {

using bvh_simd::add4;
using bvh_simd::Box4;
using bvh_simd::Float4;
using bvh_simd::load4;
using bvh_simd::loadXyz;
using bvh_simd::mul4;
using bvh_simd::splat4;
using bvh_simd::store4;
using bvh_simd::sub4;

constexpr uint32_t kMaxBins = 256;

// A triangle's padded box; lo[3] holds the triangle's index (its bits), hi[3] is zero.
struct alignas(32) PrimRef {
    float lo[4];
    float hi[4];
};

inline uint32_t primIndex(const PrimRef& p) {
    uint32_t t = 0;
    std::memcpy(&t, &p.lo[3], sizeof t);
    return t;
}

inline Float4 primLo(const PrimRef& p) {
    return loadXyz(p.lo);
}
inline Float4 primHi(const PrimRef& p) {
    return load4(p.hi);
}
inline Float4 centroidOf(const PrimRef& p) {
    return mul4(add4(primLo(p), primHi(p)), splat4(0.5f));
}
// The same value as lane `axis` of centroidOf.
inline float centroidOf(const PrimRef& p, int axis) {
    return (p.lo[axis] + p.hi[axis]) * 0.5f;
}

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

inline uint32_t ceilLog2(uint64_t x) {
    uint32_t levels = 0;
    while ((uint64_t{1} << levels) < x) {
        ++levels;
    }
    return levels;
}

// Centroid bins of one range: per axis, the box and count of the triangles whose centroid falls
// in each of binCount equal slabs of the range's centroid bounds.
struct Bins {
    std::array<Box4, 3 * kMaxBins> box;
    std::array<uint32_t, 3 * kMaxBins> count;
};

// Bounds of references [begin, end).
Range makeRange(const PrimRef* refs, uint32_t begin, uint32_t end);

// How a range is built: as one leaf, or split in two.
struct Decision {
    bool leaf = false;
    Range left;
    Range right;
};

// Decides the range `r` at depth `depth`, partitioning its references for a split. `scratch`
// holds one Bins per thread that may bin this range (binThreads >= 1).
Decision decideRange(const BuildInput& in, const Range& r, uint32_t depth, std::vector<Bins>& scratch,
                     uint32_t binThreads);

}  // namespace gdpt::bvh_build
