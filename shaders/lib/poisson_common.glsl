// poisson_common.glsl — bindings, push constants and stencil helpers shared by the
// poisson_*.comp kernels (maths in shaders/shared/poisson_shared.h and
// src/poisson/poisson_cpu.h). Include after "poisson_shared.h".
#ifndef POISSON_COMMON_GLSL
#define POISSON_COMMON_GLSL

#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require

layout(set = 0, binding = kPoissonBindCoef, scalar) buffer CoefBuf { float Coef[]; };
layout(set = 0, binding = kPoissonBindX, scalar) buffer XBuf { float X[]; };
layout(set = 0, binding = kPoissonBindB, scalar) buffer BBuf { float B[]; };
layout(set = 0, binding = kPoissonBindR, scalar) buffer RBuf { float R[]; };
layout(set = 0, binding = kPoissonBindP, scalar) buffer PBuf { float P[]; };
layout(set = 0, binding = kPoissonBindAp, scalar) buffer ApBuf { float Ap[]; };
layout(set = 0, binding = kPoissonBindSol, scalar) buffer SolBuf { float Sol[]; };
layout(set = 0, binding = kPoissonBindRhs, scalar) buffer RhsBuf { float Rhs[]; };
layout(set = 0, binding = kPoissonBindPrimal, scalar) readonly buffer PrimalBuf { float Primal[]; };
layout(set = 0, binding = kPoissonBindDx, scalar) readonly buffer DxBuf { float Dx[]; };
layout(set = 0, binding = kPoissonBindDy, scalar) readonly buffer DyBuf { float Dy[]; };
layout(set = 0, binding = kPoissonBindWeights, scalar) readonly buffer WeightBuf { float Wt[]; };
layout(set = 0, binding = kPoissonBindIrls, scalar) buffer IrlsBuf { float Irls[]; };
layout(set = 0, binding = kPoissonBindScalars, scalar) buffer ScalarBuf {
    PoissonScalars sc;
    float history[];
};
layout(set = 0, binding = kPoissonBindPartials, scalar) buffer PartialBuf { float Partials[]; };

layout(push_constant, scalar) uniform Push { PoissonPush pc; };

// The kPoissonFlag* bits of this pipeline variant (see poisson_shared.h).
layout(constant_id = kSpecPoissonFlags) const uint kFlags = 0u;
bool flag(uint f) { return (kFlags & f) != 0u; }

// The 5-point stencil of pixel (x, y) on a level: edge weights to the four neighbours
// (0 where the neighbour does not exist, its index then repeats i) and the screening term.
struct Stencil {
    uint i, iW, iE, iN, iS;  // pixel and neighbour indices (N = y−1, S = y+1)
    float cW, cE, cN, cS;    // edge weights c_ij
    float cp;                // screening diagonal α² wp
};

Stencil loadStencil(uint x, uint y, uint w, uint h, uint cOff) {
    Stencil s;
    uint n = w * h;
    s.i = y * w + x;
    s.iW = x > 0u ? s.i - 1u : s.i;
    s.iE = x + 1u < w ? s.i + 1u : s.i;
    s.iN = y > 0u ? s.i - w : s.i;
    s.iS = y + 1u < h ? s.i + w : s.i;
    s.cE = x + 1u < w ? Coef[cOff + s.i] : 0.0;
    s.cW = x > 0u ? Coef[cOff + s.iW] : 0.0;
    s.cS = y + 1u < h ? Coef[cOff + n + s.i] : 0.0;
    s.cN = y > 0u ? Coef[cOff + n + s.iN] : 0.0;
    s.cp = Coef[cOff + 2u * n + s.i];
    return s;
}

float stencilDiag(Stencil s) { return s.cp + s.cW + s.cE + s.cN + s.cS; }

// (A x)_i in the flux form Σ c_ij (x_i − x_j) + cp x_i (differences first: accurate for
// large, smooth x), given the five values.
float applyStencil(Stencil s, float xi, float xW, float xE, float xN, float xS) {
    return s.cp * xi + s.cW * (xi - xW) + s.cE * (xi - xE) + s.cN * (xi - xN) + s.cS * (xi - xS);
}

// Deterministic partial sums of three values (one per channel): subgroupAdd inside each
// subgroup (a fixed reduction order of the implementation), and one partial per subgroup,
// Partials[(slot·3 + c)·G + g·S + subgroup] with S = gl_NumSubgroups and G·S = pc.groups
// (≥ this dispatch's count; unused entries stay 0). No shared memory and no barrier: on
// lavapipe a barrier anywhere in a shader turns every workgroup into coroutines, which made
// the stencil kernels several times slower. poisson_scalars adds the partials in order.
void writePartials(vec3 v, uint slot) {
    vec3 s = subgroupAdd(v);
    uint g = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_NumSubgroups + gl_SubgroupID;
    if (subgroupElect())
        for (uint c = 0u; c < 3u; ++c) Partials[(slot * 3u + c) * pc.groups + g] = s[c];
}

#endif
