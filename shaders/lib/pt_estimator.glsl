// pt_estimator.glsl — the path tracer's rules at one vertex, named: next-event estimation with
// the power heuristic, the weight of emission found by BSDF sampling, and Russian roulette
// (Veach 1997 ch. 9; pbrt-v4 PathIntegrator). pt_core.glsl builds the path tracer's vertex from
// them, and tgpt_reconnect.comp its base path, whose offset's work sits between these steps; so
// both compute one estimator. GLSL only; the including kernel has declared the scene buffers and
// included scene_access.glsl, bvh_traverse.glsl and sampler.glsl. Every function has one exit, so
// that spirv-opt inlines it (gpt_steps.glsl says why that matters on lavapipe).
#ifndef GDPT_LIB_PT_ESTIMATOR
#define GDPT_LIB_PT_ESTIMATOR

// The light sample ls (drawn above the surface: dot(ls.wi, ng) > 0) at a vertex with BSDF `bsdf`,
// outgoing direction woLocal and ls.wi in the same frame as wiLocal: adds beta · f · Li · w / p_L
// to `radiance`, w the power heuristic against BSDF sampling (1 for a punctual light, which BSDF
// sampling cannot hit); nothing where f is zero (no shadow ray) or the segment from `origin` to
// the light point is occluded. Counts the shadow ray in `rays`.
void ptAddNee(LightSample ls, BsdfParams bsdf, vec3 woLocal, vec3 wiLocal, vec3 origin, vec3 beta,
              inout vec3 radiance, inout uint rays) {
    vec3 f = bsdfEval(bsdf, woLocal, wiLocal);
    if (maxComponent(f) > 0.0) {
        rays++;
        if (!occludedTowards(origin, ls.pLight)) {
            float w = 1.0;
            if (ls.isDelta == 0u) w = powerHeuristic(1.0, ls.pdf, 1.0, bsdfPdf(bsdf, woLocal, wiLocal));
            radiance += beta * f * ls.Li * (w / ls.pdf);
        }
    }
}

// The power-heuristic weight of emission that BSDF sampling found at point p of triangle `tri`,
// sampled from prevP with density prevPdf (solid angle); 1 after a Dirac lobe (prevSpecular),
// which next-event estimation cannot sample.
float ptEmissionWeight(bool prevSpecular, float prevPdf, vec3 prevP, uint tri, vec3 p) {
    float w = 1.0;
    if (!prevSpecular) w = powerHeuristic(1.0, prevPdf, 1.0, lightTrianglePdf(tri, prevP, p, triangleUnitNormal(tri)));
    return w;
}

// Russian roulette on the segment sampled at vertex `depth` (from scene.rrDepth segments on):
// survival probability q = min(max(beta), 0.95), by which beta is divided; q = 1 before. Returns
// whether the path survives (the sampler's roulette number of that bounce below q).
bool ptRoulette(uint depth, inout vec3 beta, inout Rng rng, out float q) {
    q = 1.0;
    bool survive = true;
    if (depth + 1u >= scene.rrDepth) {
        q = min(maxComponent(beta), 0.95);
        survive = ldRoulette(depth, rng) < q;
        beta /= q;
    }
    return survive;
}

#endif  // GDPT_LIB_PT_ESTIMATOR
