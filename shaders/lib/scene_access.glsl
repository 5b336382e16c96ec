// scene_access.glsl — reading the scene on the device: hit reconstruction, textures,
// materials and light sampling. GLSL only. The including kernel declares the scene buffers
// (see shaders/lib/scene_buffers.glsl) and the specialisation constants kHasTextures,
// kHasPunctual, kHasLightTris, kHasAlphaMask before including this file.
#ifndef GDPT_LIB_SCENE_ACCESS
#define GDPT_LIB_SCENE_ACCESS

#include "common.glsl"
#include "sampling.glsl"
#include "bsdf.glsl"

// ---------------------------------------------------------------------------------------------
// Textures: bilinear, repeat wrap, texels stored as two packHalf2x16 words (linear RGBA).
// ---------------------------------------------------------------------------------------------
vec4 fetchTexel(TextureInfo info, int x, int y) {
    int w = int(info.width);
    int h = int(info.height);
    x = ((x % w) + w) % w;
    y = ((y % h) + h) % h;
    return imageTexel(info.offset + uint(y * w + x));
}

vec4 sampleTexture(int tex, vec2 uv) {
    vec4 texel = vec4(1.0);
    if (kHasTextures && tex >= 0) {
        TextureInfo info = textureInfo(tex);
        // glTF uv (0,0) is the top-left of the image (row 0).
        vec2 st = uv * vec2(info.width, info.height) - 0.5;
        vec2 f = floor(st);
        vec2 t = st - f;
        int x0 = int(f.x);
        int y0 = int(f.y);
        vec4 a = mix(fetchTexel(info, x0, y0), fetchTexel(info, x0 + 1, y0), t.x);
        vec4 b = mix(fetchTexel(info, x0, y0 + 1), fetchTexel(info, x0 + 1, y0 + 1), t.x);
        texel = mix(a, b, t.y);
    }
    return texel;
}

// ---------------------------------------------------------------------------------------------
// Surface interaction
// ---------------------------------------------------------------------------------------------
struct SurfaceHit {
    vec3 p;          // world-space position (from barycentrics, not o + t d)
    vec3 ng;         // unit geometric normal, flipped to face the incoming ray
    vec3 ns;         // unit shading normal, same hemisphere as ng
    vec2 uv;
    uint material;
    uint triangle;
    bool frontFace;  // the ray hit the counter-clockwise (front) side
};

vec2 hitUv(uint tri, float u, float v) {
    TriangleShading s = triangleShading(tri);
    return (1.0 - u - v) * s.uv0 + u * s.uv1 + v * s.uv2;
}

SurfaceHit makeSurfaceHit(uint tri, float u, float v, vec3 rayDir) {
    TriangleGeom g = triangleGeom(tri);
    TriangleShading s = triangleShading(tri);
    SurfaceHit h;
    h.triangle = tri;
    h.material = s.material;
    h.p = g.v0 + u * g.e1 + v * g.e2;
    vec3 ng = normalize(cross(g.e1, g.e2));
    h.frontFace = dot(ng, rayDir) < 0.0;
    if (!h.frontFace) ng = -ng;
    h.ng = ng;
    vec3 ns = ng;
    if (kHasShadingNormals && (s.flags & kTriFlagHasNormals) != 0u) {
        vec3 n = (1.0 - u - v) * s.n0 + u * s.n1 + v * s.n2;
        float len = length(n);
        if (len > 0.0 && isFinite(len)) {
            n /= len;
            if (!h.frontFace) n = -n;
            // A shading normal on the far side of the geometric one would let light leak.
            if (dot(n, ng) > 0.0) ns = n;
        }
    }
    h.ns = ns;
    h.uv = (1.0 - u - v) * s.uv0 + u * s.uv1 + v * s.uv2;
    return h;
}

// Cutout test used during traversal (GDPT_ANYHIT_FILTER): false = ignore this hit.
bool alphaPasses(uint tri, float u, float v) {
    bool passes = true;
    if (kHasAlphaMask) {
        Material m = material(triangleShading(tri).material);
        if ((m.flags & kMatFlagAlphaMask) != 0u)
            passes = m.baseColor.w * sampleTexture(m.baseColorTex, hitUv(tri, u, v)).w >= m.alphaCutoff;
    }
    return passes;
}

BsdfParams materialBsdf(uint matIndex, vec2 uv) {
    Material m = material(matIndex);
    vec3 base = m.baseColor.xyz;
    float metallic = m.metallic;
    float roughness = m.roughness;
    if (kHasTextures) {
        base *= sampleTexture(m.baseColorTex, uv).xyz;
        if (m.metallicRoughnessTex >= 0) {
            vec4 mr = sampleTexture(m.metallicRoughnessTex, uv);
            roughness *= mr.y;
            metallic *= mr.z;
        }
    }
    return makeBsdfParams(base, metallic, roughness, m.specular, m.specularColor, m.ior);
}

// Emitted radiance leaving the surface towards the viewer (front faces only unless the
// material is double-sided).
vec3 surfaceEmission(SurfaceHit h) {
    Material m = material(h.material);
    if ((m.flags & kMatFlagEmissive) == 0u) return vec3(0.0);
    if (!h.frontFace && (m.flags & kMatFlagDoubleSided) == 0u) return vec3(0.0);
    vec3 e = m.emissive;
    if (kHasTextures) e *= sampleTexture(m.emissiveTex, h.uv).xyz;
    return e;
}

// Probability of choosing the emissive-triangle class in NEE (vs. punctual lights).
float lightTriangleSelectProb() {
    if (!kHasLightTris || scene.numLightTriangles == 0u) return 0.0;
    if (!kHasPunctual || scene.numPunctualLights == 0u) return 1.0;
    return scene.lightTrianglePower / (scene.lightTrianglePower + scene.punctualPower);
}

// Solid-angle pdf with which NEE would have chosen point `p` on emissive triangle `tri`
// (area pdf pmf/area converted by dist^2/cos) seen from `from`.
float lightTrianglePdf(uint tri, vec3 from, vec3 p, vec3 nLight) {
    uint li = triangleShading(tri).lightIndex;
    if (li == kInvalidIndex) return 0.0;
    vec3 d = p - from;
    float dist2 = dot(d, d);
    float cosL = abs(dot(nLight, normalize(d)));
    if (cosL <= 0.0) return 0.0;
    float pdfArea = lightTriangleSelectProb() * lightTriangle(li).pmf / triangleShading(tri).area;
    return pdfArea * dist2 / cosL;
}

struct LightSample {
    vec3 wi;        // unit direction from the shading point to the light
    float dist;     // distance to the light point (Inf never: punctual/area lights only)
    vec3 Li;        // incident radiance (area) or intensity / dist^2 (punctual)
    float pdf;      // solid-angle pdf (area lights) or discrete selection prob (punctual)
    vec3 pLight;    // world-space light point
    vec3 nLight;    // light normal (area lights; zero for punctual)
    uint isDelta;   // 1 for punctual lights (no MIS with BSDF sampling)
    uint triangle;  // emissive triangle index, kInvalidIndex for punctual
    uint punctual;  // punctual light index, kInvalidIndex for an emissive triangle
};

// Binary search of the power CDF of the emissive triangles.
uint pickLightTriangle(float u) {
    uint lo = 0u;
    uint hi = scene.numLightTriangles - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) >> 1u;
        if (lightTriangle(mid).cdf <= u) lo = mid + 1u; else hi = mid;
    }
    return lo;
}

// Next-event estimation: one light point for the shading point p (u: 3 uniforms).
bool sampleLight(vec3 p, vec3 u, out LightSample ls) {
    ls.isDelta = 0u;
    ls.triangle = kInvalidIndex;
    ls.punctual = kInvalidIndex;
    ls.nLight = vec3(0.0);
    float pTri = lightTriangleSelectProb();
    if (kHasLightTris && u.x < pTri) {
        uint li = pickLightTriangle(u.x / pTri);
        uint tri = lightTriangle(li).triangle;
        TriangleGeom g = triangleGeom(tri);
        vec3 bary = sampleUniformTriangle(u.yz);
        ls.pLight = g.v0 + bary.y * g.e1 + bary.z * g.e2;
        vec3 nl = normalize(cross(g.e1, g.e2));
        vec3 d = ls.pLight - p;
        float dist2 = dot(d, d);
        ls.dist = sqrt(dist2);
        ls.wi = d / ls.dist;
        float cosL = dot(nl, -ls.wi);
        Material m = material(triangleShading(tri).material);
        bool twoSided = (m.flags & kMatFlagDoubleSided) != 0u;
        if (cosL <= 0.0 && !twoSided) return false;
        cosL = abs(cosL);
        if (cosL <= 1e-7 || !(ls.dist > 0.0)) return false;
        ls.nLight = nl;
        ls.triangle = tri;
        vec3 e = m.emissive;
        if (kHasTextures) e *= sampleTexture(m.emissiveTex, hitUv(tri, bary.y, bary.z)).xyz;
        ls.Li = e;
        ls.pdf = pTri * lightTriangle(li).pmf / triangleShading(tri).area * dist2 / cosL;
        return ls.pdf > 0.0 && isFinite(ls.pdf);
    }
    if (!kHasPunctual || scene.numPunctualLights == 0u) return false;
    float uu = (u.x - pTri) / (1.0 - pTri);
    uint idx = min(uint(uu * float(scene.numPunctualLights)), scene.numPunctualLights - 1u);
    PunctualLight l = punctualLight(idx);
    ls.punctual = idx;
    vec3 d = l.position - p;
    float dist2 = dot(d, d);
    if (!(dist2 > 0.0)) return false;
    ls.dist = sqrt(dist2);
    ls.wi = d / ls.dist;
    ls.pLight = l.position;
    ls.isDelta = 1u;
    float falloff = 1.0;
    if (l.type == kPunctualSpot) {
        float c = dot(-ls.wi, l.direction);
        // glTF KHR_lights_punctual: smooth falloff between the outer and inner cone.
        falloff = clamp((c - l.cosOuter) / max(l.cosInner - l.cosOuter, 1e-4), 0.0, 1.0);
        falloff *= falloff;
    }
    ls.Li = l.intensity * falloff / dist2;
    ls.pdf = (1.0 - pTri) / float(scene.numPunctualLights);
    return falloff > 0.0 && ls.pdf > 0.0;
}

#endif  // GDPT_LIB_SCENE_ACCESS
