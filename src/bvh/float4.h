// float4.h — the four-float vector and box the BVH builder bins with: SSE registers on x86-64
// (every x86-64 processor has SSE2), four plain floats elsewhere. The fourth lane is carried
// along and never read for geometry; `loadXyz` zeroes it (the builder keeps a triangle's index
// in the fourth float of its box's lower corner). Only the operations the
// builder needs, each exactly rounded in either form, so both give the same trees.
#pragma once

#include <cstdint>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace gdpt::bvh_simd {

#if defined(__SSE2__)
struct Float4 {
    __m128 v;
};
inline Float4 load4(const float* p) {
    return {_mm_loadu_ps(p)};
}
// p[0..2] with a zero fourth lane (p[3] is read, then masked).
inline Float4 loadXyz(const float* p) {
    const __m128 mask = _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1));
    return {_mm_and_ps(_mm_loadu_ps(p), mask)};
}
inline void store4(float* p, Float4 a) {
    _mm_storeu_ps(p, a.v);
}
inline Float4 splat4(float x) {
    return {_mm_set1_ps(x)};
}
inline Float4 min4(Float4 a, Float4 b) {
    return {_mm_min_ps(a.v, b.v)};
}
inline Float4 max4(Float4 a, Float4 b) {
    return {_mm_max_ps(a.v, b.v)};
}
inline Float4 add4(Float4 a, Float4 b) {
    return {_mm_add_ps(a.v, b.v)};
}
inline Float4 sub4(Float4 a, Float4 b) {
    return {_mm_sub_ps(a.v, b.v)};
}
inline Float4 mul4(Float4 a, Float4 b) {
    return {_mm_mul_ps(a.v, b.v)};
}
// Truncation towards zero of each lane (the lanes are non-negative and below 2^31 here).
inline void truncate4(Float4 a, std::int32_t* out) {
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm_cvttps_epi32(a.v));
}
#else
struct Float4 {
    float v[4];
};
inline Float4 load4(const float* p) {
    return {{p[0], p[1], p[2], p[3]}};
}
inline Float4 loadXyz(const float* p) {
    return {{p[0], p[1], p[2], 0.0f}};
}
inline void store4(float* p, Float4 a) {
    for (int k = 0; k < 4; ++k) p[k] = a.v[k];
}
inline Float4 splat4(float x) {
    return {{x, x, x, x}};
}
// The same operand order as SSE's minps/maxps: (a < b ? a : b), (a > b ? a : b).
inline Float4 min4(Float4 a, Float4 b) {
    return {{a.v[0] < b.v[0] ? a.v[0] : b.v[0], a.v[1] < b.v[1] ? a.v[1] : b.v[1],
             a.v[2] < b.v[2] ? a.v[2] : b.v[2], a.v[3] < b.v[3] ? a.v[3] : b.v[3]}};
}
inline Float4 max4(Float4 a, Float4 b) {
    return {{a.v[0] > b.v[0] ? a.v[0] : b.v[0], a.v[1] > b.v[1] ? a.v[1] : b.v[1],
             a.v[2] > b.v[2] ? a.v[2] : b.v[2], a.v[3] > b.v[3] ? a.v[3] : b.v[3]}};
}
inline Float4 add4(Float4 a, Float4 b) {
    return {{a.v[0] + b.v[0], a.v[1] + b.v[1], a.v[2] + b.v[2], a.v[3] + b.v[3]}};
}
inline Float4 sub4(Float4 a, Float4 b) {
    return {{a.v[0] - b.v[0], a.v[1] - b.v[1], a.v[2] - b.v[2], a.v[3] - b.v[3]}};
}
inline Float4 mul4(Float4 a, Float4 b) {
    return {{a.v[0] * b.v[0], a.v[1] * b.v[1], a.v[2] * b.v[2], a.v[3] * b.v[3]}};
}
inline void truncate4(Float4 a, std::int32_t* out) {
    for (int k = 0; k < 4; ++k) out[k] = static_cast<std::int32_t>(a.v[k]);
}
#endif

inline float lane(Float4 a, int k) {
    alignas(16) float f[4];
    store4(f, a);
    return f[k];
}

// An axis-aligned box; empty when lo > hi (the initial state).
struct Box4 {
    Float4 lo = splat4(std::numeric_limits<float>::max());
    Float4 hi = splat4(-std::numeric_limits<float>::max());

    void grow(Float4 p) {
        lo = min4(lo, p);
        hi = max4(hi, p);
    }
    void grow(Float4 boxLo, Float4 boxHi) {
        lo = min4(lo, boxLo);
        hi = max4(hi, boxHi);
    }
    void grow(const Box4& b) { grow(b.lo, b.hi); }
    // Half the surface area (the SAH needs only ratios); 0 for an empty box. Evaluated as
    // (dx·dy + dy·dz) + dz·dx in either form, so both round alike.
    float halfArea() const {
#if defined(__SSE2__)
        if (_mm_movemask_ps(_mm_cmpgt_ps(lo.v, hi.v)) & 7) return 0.0f;
        const __m128 d = _mm_sub_ps(hi.v, lo.v);
        const __m128 p = _mm_mul_ps(d, _mm_shuffle_ps(d, d, _MM_SHUFFLE(3, 0, 2, 1)));
        const __m128 sum = _mm_add_ss(p, _mm_shuffle_ps(p, p, _MM_SHUFFLE(3, 3, 3, 1)));
        return _mm_cvtss_f32(_mm_add_ss(sum, _mm_shuffle_ps(p, p, _MM_SHUFFLE(3, 3, 3, 2))));
#else
        if (lo.v[0] > hi.v[0] || lo.v[1] > hi.v[1] || lo.v[2] > hi.v[2]) return 0.0f;
        const float dx = hi.v[0] - lo.v[0];
        const float dy = hi.v[1] - lo.v[1];
        const float dz = hi.v[2] - lo.v[2];
        return dx * dy + dy * dz + dz * dx;
#endif
    }
};

}  // namespace gdpt::bvh_simd
