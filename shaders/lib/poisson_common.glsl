// poisson_common.glsl — bindings, push constants and stencil helpers shared by the
// poisson_*.comp kernels (maths in shaders/shared/poisson_shared.h and
// src/poisson/poisson_cpu.h). Include after "poisson_shared.h".
#ifndef POISSON_COMMON_GLSL
#define POISSON_COMMON_GLSL

#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require

// The field buffers (poisson_shared.h); either way each name is a float array, X[i].
#ifdef GDPT_POISSON_DEVICE_ADDRESS
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require
layout(buffer_reference, scalar, buffer_reference_align = 4) buffer PoissonFloats { float v[]; };
layout(set = 0, binding = kPoissonBindFields, scalar) readonly restrict buffer FieldBuf {
    uvec2 fieldAddress[kPoissonFieldCount];
};
#define POISSON_FIELD(f) (PoissonFloats(fieldAddress[f]).v)
#define Coef POISSON_FIELD(kPoissonFieldCoef)
#define X POISSON_FIELD(kPoissonFieldX)
#define B POISSON_FIELD(kPoissonFieldB)
#define R POISSON_FIELD(kPoissonFieldR)
#define P POISSON_FIELD(kPoissonFieldP)
#define Ap POISSON_FIELD(kPoissonFieldAp)
#define Sol POISSON_FIELD(kPoissonFieldSol)
#define Rhs POISSON_FIELD(kPoissonFieldRhs)
#define Primal POISSON_FIELD(kPoissonFieldPrimal)
#define Dx POISSON_FIELD(kPoissonFieldDx)
#define Dy POISSON_FIELD(kPoissonFieldDy)
#define Wt POISSON_FIELD(kPoissonFieldWeights)
#define Irls POISSON_FIELD(kPoissonFieldIrls)
#define Partials POISSON_FIELD(kPoissonFieldPartials)
#else
#define POISSON_BIND(f) layout(set = 0, binding = kPoissonBindFieldBase + f, scalar)
POISSON_BIND(kPoissonFieldCoef) buffer CoefBuf { float Coef[]; };
POISSON_BIND(kPoissonFieldX) buffer XBuf { float X[]; };
POISSON_BIND(kPoissonFieldB) buffer BBuf { float B[]; };
POISSON_BIND(kPoissonFieldR) buffer RBuf { float R[]; };
POISSON_BIND(kPoissonFieldP) buffer PBuf { float P[]; };
POISSON_BIND(kPoissonFieldAp) buffer ApBuf { float Ap[]; };
POISSON_BIND(kPoissonFieldSol) buffer SolBuf { float Sol[]; };
POISSON_BIND(kPoissonFieldRhs) buffer RhsBuf { float Rhs[]; };
POISSON_BIND(kPoissonFieldPrimal) readonly buffer PrimalBuf { float Primal[]; };
POISSON_BIND(kPoissonFieldDx) readonly buffer DxBuf { float Dx[]; };
POISSON_BIND(kPoissonFieldDy) readonly buffer DyBuf { float Dy[]; };
POISSON_BIND(kPoissonFieldWeights) readonly buffer WeightBuf { float Wt[]; };
POISSON_BIND(kPoissonFieldIrls) buffer IrlsBuf { float Irls[]; };
POISSON_BIND(kPoissonFieldPartials) buffer PartialBuf { float Partials[]; };
#endif
// Entry k = c·G + g of partial-sum slot `slot` (kPoissonSlot*), G = pc.groups.
#define PARTIAL(slot, k) Partials[(slot) * 3u * pc.groups + (k)]

layout(set = 0, binding = kPoissonBindScalars, scalar) buffer ScalarBuf {
    PoissonScalars sc;
    float history[];
};

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
// PARTIAL(slot, c·G + g·S + subgroup) with S = gl_NumSubgroups and G·S = pc.groups
// (≥ this dispatch's count; unused entries stay 0). No shared memory and no barrier: on
// lavapipe a barrier anywhere in a shader turns every workgroup into coroutines, which made
// the stencil kernels several times slower. poisson_scalars adds the partials in order.
void writePartials(vec3 v, uint slot) {
    vec3 s = subgroupAdd(v);
    uint g = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_NumSubgroups + gl_SubgroupID;
    if (subgroupElect())
        for (uint c = 0u; c < 3u; ++c) PARTIAL(slot, c * pc.groups + g) = s[c];
}

#endif
