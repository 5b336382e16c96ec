// common.glsl — compatibility layer that lets the shader math library compile both as
// GLSL 460 (included by kernels) and as C++17 (included by host code and unit tests).
//
// The library is written in the GLSL/GLM common subset (after Falcor's
// HostDeviceShared.slangh): no swizzles, no references except through GDPT_INOUT/OUT, no
// overloading that depends on qualifiers, explicit float literals (`1.0f`; GLSL >= 1.30
// accepts the suffix) and explicit constructor-style conversions (`float(u)`), which are
// also warning-free under -Wconversion. Every lib file wraps its body in
// GDPT_NAMESPACE_BEGIN / GDPT_NAMESPACE_END so the C++ view lives in gdpt::gpu.
#ifndef GDPT_LIB_COMMON
#define GDPT_LIB_COMMON

#include "../shared/gdpt_shared.h"

#ifdef __cplusplus
#include <glm/glm.hpp>
// glm's functions are made visible only inside gdpt::gpu, never at global scope.
#define GDPT_NAMESPACE_BEGIN namespace gdpt::gpu { using namespace glm;
#define GDPT_NAMESPACE_END }
#define GDPT_INLINE inline
#define GDPT_INOUT(T) T&
#define GDPT_OUT(T) T&
#define GDPT_IN(T) const T&
#else
#define GDPT_NAMESPACE_BEGIN
#define GDPT_NAMESPACE_END
#define GDPT_INLINE
#define GDPT_INOUT(T) inout T
#define GDPT_OUT(T) out T
#define GDPT_IN(T) in T
#endif

GDPT_NAMESPACE_BEGIN

GDPT_CONST float kPi = 3.14159265358979323846f;
GDPT_CONST float kInvPi = 0.31830988618379067154f;
GDPT_CONST float kTwoPi = 6.28318530717958647692f;
GDPT_CONST float kInv2Pi = 0.15915494309189533577f;
GDPT_CONST float kInv4Pi = 0.07957747154594766788f;
GDPT_CONST float kPiOver2 = 1.57079632679489661923f;
GDPT_CONST float kPiOver4 = 0.78539816339744830962f;
// Largest float below 1 (1 - 2^-24): upper clamp for values that must stay in [0,1).
GDPT_CONST float kOneMinusEpsilon = 0.99999994039535522461f;

// Relative luminance of a linear Rec.709 / sRGB-primaries colour (ITU-R BT.709 weights).
GDPT_INLINE float luminance(vec3 c) {
    return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

GDPT_INLINE float maxComponent(vec3 v) {
    return max(v.x, max(v.y, v.z));
}

GDPT_INLINE float minComponent(vec3 v) {
    return min(v.x, min(v.y, v.z));
}

GDPT_INLINE float sqr(float x) {
    return x * x;
}

// sqrt that tolerates the small negative arguments produced by rounding (e.g. 1 - cos^2).
GDPT_INLINE float safeSqrt(float x) {
    return sqrt(max(x, 0.0f));
}

// Finite test on the bit pattern: exponent bits all ones <=> Inf or NaN. Unlike isnan/isinf
// this survives fast-math style optimisation in both compilers.
GDPT_INLINE bool isFinite(float x) {
    return (floatBitsToUint(x) & 0x7F800000u) != 0x7F800000u;
}

GDPT_INLINE bool isFinite(vec3 v) {
    return isFinite(v.x) && isFinite(v.y) && isFinite(v.z);
}

GDPT_NAMESPACE_END

#endif  // GDPT_LIB_COMMON
