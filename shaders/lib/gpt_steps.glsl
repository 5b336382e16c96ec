// gpt_steps.glsl — the named steps of one G-PT bounce (gpt_bounce.glsl), mostly for one pixel
// pair (base, offset i): the offset's vertex, next-event estimation with the base's light
// point, the base's BSDF sample and Russian roulette, the shift of the offset over the base's
// new segment, and the emission the pair reaches (Kettunen et al. 2015 §4; the shift mappings
// themselves are shift.glsl's). GLSL only: needs gpt.comp's scene buffers, bvh_traverse.glsl,
// gpt_light.glsl and gpt_path.glsl.
//
// Every function here has one exit: spirv-opt then inlines it (it leaves calls of functions
// with an early return to the driver), so the SPIR-V that lavapipe lowers keeps the shape of
// the pasted loop body these steps replaced.
#ifndef GDPT_LIB_GPT_STEPS
#define GDPT_LIB_GPT_STEPS

const float kInf = 1.0 / 0.0;

// An offset's current vertex as the bounce sees it: with a vertex of its own (NOT_CONNECTED)
// that vertex's BSDF and shading frame; sharing the base's vertex, the base's. wo: the
// offset's own incoming direction in that frame.
struct OffsetVertex {
    BsdfParams bsdf;
    vec3 t;
    vec3 b;
    vec3 wo;
};

OffsetVertex gptOffsetVertex(OffsetPath o, bool own, BsdfParams baseBsdf, vec3 t, vec3 b, vec3 ns) {
    OffsetVertex v;
    v.bsdf = baseBsdf;
    v.t = t;
    v.b = b;
    v.wo = vec3(0.0, 0.0, 1.0);
    if (own) {
        v.bsdf = materialBsdf(o.hit.material, o.hit.uv);
        makeBasis(o.hit.ns, v.t, v.b);
        v.wo = toLocal(o.woWorld, v.t, v.b, o.hit.ns);
    } else if (o.alive) {
        v.wo = toLocal(o.woWorld, t, b, ns);
    }
    return v;
}

// Whether the light strategy exists for the pair at this vertex: always for a lone base
// (failed shift) and a shared vertex; for separate vertices only if both are rough (area
// lights; BSDF sampling never hits a punctual light). The BSDF-sampled emission of the next
// vertex then competes with it or not. Rough means rough over ALL components (not only the
// smooth ones NEE evaluates, the authors' implementation's choice): only then does the BSDF
// step reconnect to the light point, so NEE and BSDF sampling use the same shift and their
// pair weights sum to one (the smooth-only rule made a diffuse lobe under a mirror coat count
// its light twice: NEE with four strategies, and again through the half-vector branch, which
// has no light strategy). A Dirac-only offset vertex fails every shift of both techniques, so
// its pair is the lone base's (PT weights, light strategy included).
bool gptPairHasLightStrategy(bool own, BsdfParams offsetBsdf, bool baseRough) {
    return !own || bsdfIsDeltaOnly(offsetBsdf) || (baseRough && roughAll(offsetBsdf));
}

// ---- Next-event estimation with the same light point for all pairs ----

// The base's light sample at its vertex, shared by the four pairs. Densities are
// visibility-aware: a path whose last segment is occluded cannot be produced by BSDF sampling
// (its BSDF density is 0) but can by light sampling, which keeps a path's weights equal
// whichever technique sampled it.
struct BaseNee {
    LightSample ls;
    vec3 ul;        // the uniforms that drew ls (the punctual light is a function of ul.x)
    vec3 wiLocal;   // ls.wi in the base vertex's shading frame
    vec3 f;         // base BSDF along ls.wi
    float pdfBsdf;  // base BSDF density of ls.wi; 0 for a punctual light or an occluded one
    bool visible;
    vec3 fBase;  // base contribution beta·f·Li/p_L (0 where occluded)
};

BaseNee gptBaseNee(LightSample ls, vec3 ul, BsdfParams bsdf, vec3 woLocal, vec3 t, vec3 b, vec3 ns,
                   vec3 origin, vec3 beta, inout uint rays) {
    BaseNee n;
    n.ls = ls;
    n.ul = ul;
    n.wiLocal = toLocal(ls.wi, t, b, ns);
    n.f = bsdfEval(bsdf, woLocal, n.wiLocal);
    float pdfBsdf = ls.isDelta != 0u ? 0.0 : bsdfPdf(bsdf, woLocal, n.wiLocal);
    rays++;
    n.visible = !occludedTowards(origin, ls.pLight);
    n.fBase = n.visible ? beta * n.f * ls.Li / ls.pdf : vec3(0.0);
    n.pdfBsdf = n.visible ? pdfBsdf : 0.0;
    return n;
}

// The offset's own vertex connected to the base's light point: direction (world and local),
// distance, the radiance arriving and the Jacobian of the light vertex shift
// (gptOffsetLight). Not attempted (ok false) unless `attempt`; fails where the base sampler
// at p + δ would have rejected the sample (light behind the surface or facing away,
// Dirac-only vertex), i.e. where the offset has zero density.
struct LightConnection {
    vec3 wi;
    vec3 wiLocal;
    float dist;
    vec3 li;
    float jacobian;
    bool ok;
};

LightConnection gptConnectToLight(BaseNee nee, vec3 pBase, SurfaceHit oh, OffsetVertex v, bool attempt) {
    LightConnection c;
    c.wi = vec3(0.0);
    c.wiLocal = vec3(0.0, 0.0, 1.0);
    c.dist = 0.0;
    c.li = vec3(0.0);
    c.jacobian = 0.0;
    c.ok = false;
    if (attempt) {
        vec3 toLight = nee.ls.pLight - oh.p;
        c.dist = length(toLight);
        c.wi = toLight / c.dist;
        c.wiLocal = toLocal(c.wi, v.t, v.b, oh.ns);
        c.ok = c.dist > 0.0 && dot(c.wi, oh.ng) > 0.0 && !bsdfIsDeltaOnly(v.bsdf) &&
               gptOffsetLight(nee.ls, nee.ul, pBase, oh.p, c.wi, c.dist, c.li, c.jacobian);
    }
    return c;
}

// The offset's side of one pair's NEE sample, in the base's measure: its contribution, its
// light and BSDF densities (times r and the light Jacobian), and whether the sample counts
// for the pair at all. Zero densities and contribution: a failed shift, the base alone with
// PT's weight.
struct OffsetNee {
    vec3 f;
    float qLight;
    float qBsdf;
    bool counts;
};

// Shared vertex (RECENTLY_CONNECTED or CONNECTED): the same light point and visibility; only
// the offset's own incoming direction changes the BSDF (fEval, pdfEval).
OffsetNee gptNeeSharedVertex(OffsetPath o, BaseNee nee, vec3 fEval, float pdfEval) {
    OffsetNee r;
    float pdfBsdfO = (nee.ls.isDelta != 0u || !nee.visible) ? 0.0 : pdfEval;
    r.f = nee.visible ? o.beta * fEval * nee.ls.Li / nee.ls.pdf : vec3(0.0);
    r.qLight = o.r * nee.ls.pdf;
    r.qBsdf = o.r * pdfBsdfO;
    r.counts = true;
    return r;
}

// Own vertex reconnected to the light point (c.ok), with its own shadow ray where `traced`
// (gptPairNeeBegin's choice) and that ray's answer. The offset's visibility matters for its
// contribution and for its BSDF density, which enters the base's weight. Light strategy in
// the base's measure: p'_L·J = p_L (same light point, area measure); BSDF strategy p'_B·J.
OffsetNee gptNeeOwnVertex(OffsetPath o, BaseNee nee, LightConnection c, vec3 fEval, float pdfEval, bool traced,
                          bool occluded, inout uint rays) {
    OffsetNee r;
    r.f = vec3(0.0);
    vec3 fo = fEval * c.li;
    float pdfBsdfO = nee.ls.isDelta != 0u ? 0.0 : pdfEval;
    if (traced) {
        rays++;
        if (!occluded)
            r.f = o.beta * fo * (c.jacobian / nee.ls.pdf);
        else
            pdfBsdfO = 0.0;
    }
    r.qLight = o.r * nee.ls.pdf;
    r.qBsdf = o.r * pdfBsdfO * c.jacobian;
    r.counts = true;
    return r;
}

// One pair's NEE sample (Kettunen et al. 2015 §4: the offset takes the base's light point),
// in two halves around the offset's own shadow ray, so that the four offsets' rays, which all
// end at the light point, can be traced as one beam (traceAnyBeam; gpt_bounce.glsl).
// An offset with a vertex of its own (NOT_CONNECTED) reconnects to that point only where the
// pair has the light strategy or the light is punctual; otherwise the sample counts for
// neither (weight 0). One BSDF evaluation per pair, whichever case: lavapipe before Mesa 23
// runs every branch under lane masks, so each case's own copy would cost its time.
struct PairNee {
    LightConnection c;
    vec3 fEval;     // the offset's BSDF along its light direction, and its density
    float pdfEval;
    bool sharedVertex;
    bool ownConnected;  // own vertex, connected to the light point (c.ok)
    bool counts;
    bool trace;     // the own vertex's shadow ray is worth tracing: a contribution or a density
    vec3 origin;    // its origin
};

PairNee gptPairNeeBegin(OffsetPath o, OffsetVertex v, bool own, bool lightStrategy, BaseNee nee, BsdfParams bsdf,
                        vec3 pBase) {
    PairNee p;
    p.sharedVertex = o.alive && !own;
    p.counts = !own || nee.ls.isDelta != 0u || lightStrategy;
    p.c = gptConnectToLight(nee, pBase, o.hit, v, own && p.counts);
    // The offset's own incoming direction at a shared vertex (RECENTLY_CONNECTED), or its own
    // vertex; a CONNECTED offset has the base's f and density.
    bool evaluate = own ? p.c.ok : p.sharedVertex && o.state == kShiftRecentlyConnected;
    p.fEval = nee.f;
    p.pdfEval = nee.pdfBsdf;
    if (evaluate) {
        BsdfParams evalBsdf = own ? v.bsdf : bsdf;
        vec3 evalWi = own ? p.c.wiLocal : nee.wiLocal;
        p.fEval = bsdfEval(evalBsdf, v.wo, evalWi);
        p.pdfEval = bsdfPdf(evalBsdf, v.wo, evalWi);
    }
    p.ownConnected = own && p.c.ok;
    float pdfBsdfO = nee.ls.isDelta != 0u ? 0.0 : p.pdfEval;
    p.trace = p.ownConnected &&
              (maxComponent(p.fEval * p.c.li) > 0.0 || (pdfBsdfO > 0.0 && maxComponent(nee.fBase) > 0.0));
    p.origin = offsetRayOriginScaled(o.hit.p, o.hit.ng, scene.sceneRadius);
    return p;
}

// The pair's side once its shadow ray's answer is known (`occluded`: false if not traced).
OffsetNee gptPairNeeEnd(OffsetPath o, PairNee p, BaseNee nee, bool occluded, inout uint rays) {
    OffsetNee r;
    r.f = vec3(0.0);
    r.qLight = 0.0;
    r.qBsdf = 0.0;
    if (p.sharedVertex) r = gptNeeSharedVertex(o, nee, p.fEval, p.pdfEval);
    if (p.ownConnected) r = gptNeeOwnVertex(o, nee, p.c, p.fEval, p.pdfEval, p.trace, occluded, rays);
    r.counts = p.counts;
    return r;
}

// Both halves with the offset's own shadow ray traced between them, by itself.
OffsetNee gptPairNee(OffsetPath o, OffsetVertex v, bool own, bool lightStrategy, BaseNee nee, BsdfParams bsdf,
                     vec3 pBase, inout uint rays) {
    PairNee p = gptPairNeeBegin(o, v, own, lightStrategy, nee, bsdf, pBase);
    bool occluded = p.trace && occludedTowards(p.origin, nee.ls.pLight);
    return gptPairNeeEnd(o, p, nee, occluded, rays);
}

// ---- BSDF sampling and Russian roulette of the base ----

// Samples the base's next direction wi (bs in the local frame) and applies Russian roulette
// from scene.rrDepth on (survival q = min(max(beta), 0.95), shared by the offsets: every p'
// gets the factor q too, so r is unchanged and each beta' is divided by q through rrInv).
// False where the base path ends: no sample, a sample below the geometric surface, absorbed
// by the roulette, or at kMaxDepth (pt.comp would not trace this segment either).
bool gptContinueBase(BsdfParams bsdf, vec3 woLocal, vec3 t, vec3 b, SurfaceHit sh, LdSample lds, uint depth,
                     inout Rng rng, inout vec3 beta, out BsdfSample bs, out vec3 wi, out float rrInv) {
    bool alive = bsdfSample(bsdf, woLocal, ldBsdf(lds, depth), bs);
    wi = vec3(0.0);
    rrInv = 1.0;
    if (alive) {
        wi = toWorld(bs.wi, t, b, sh.ns);
        alive = !(dot(wi, sh.ng) <= 0.0);
    }
    if (alive) {
        beta *= bs.weight;
        if (depth + 1u >= scene.rrDepth) {
            float q = min(maxComponent(beta), 0.95);
            alive = !(ldRoulette(depth, rng) >= q);
            rrInv = 1.0 / q;
            beta *= rrInv;
        }
        alive = alive && depth + 1u < kMaxDepth;
    }
    return alive;
}

// ---- Shift of the offset over the base's new segment ----

// The base's new segment, as the shift of every offset sees it.
struct BaseSegment {
    vec3 from;        // the base's current vertex
    BsdfParams bsdf;  // its BSDF
    vec3 woLocal;     // its incoming direction, local frame
    BsdfSample bs;    // the sampled direction (local), weight f/p, density, lobe
    vec3 wi;          // the sampled direction, world space
    float rrInv;      // 1/q of the base's Russian roulette (1 without)
    bool missed;      // the segment left the scene (environment)
    SurfaceHit next;  // else the vertex it reached
    bool curRough;    // classification of the current and the next vertex (roughAll)
    bool nextRough;
};

// The ray an offset's own-vertex shift traces: from the offset's vertex; `trace` false where
// the shift failed before it (or a zero-length connection, which nothing occludes).
struct ShiftRay {
    vec3 origin;
    vec3 dir;
    float tMax;
    bool trace;
};

ShiftRay noShiftRay(vec3 origin) {
    ShiftRay r;
    r.origin = origin;
    r.dir = vec3(0.0, 0.0, 1.0);
    r.tMax = kInf;
    r.trace = false;
    return r;
}

// No reconnection (an offset that shares the base's vertex, or a half-vector copy).
ConnectionShift noConnectionShift() {
    ConnectionShift c;
    c.wi = vec3(0.0);
    c.dist = 0.0;
    c.jacobian = 0.0;
    c.ok = false;
    return c;
}

// NOT_CONNECTED offset, reconnection shift, first half: to the base's next vertex, or the
// environment shift in the same direction. Afterwards the offset shares every later vertex
// with the base (RECENTLY_CONNECTED). The ray is the visibility test (occludedTowards's for a
// vertex, towardsTarget); any hit on it occludes.
ShiftRay gptReconnectRay(inout OffsetPath o, OffsetVertex v, BaseSegment s, out ConnectionShift c) {
    SurfaceHit oh = o.hit;
    ShiftRay ray = noShiftRay(offsetRayOriginScaled(oh.p, oh.ng, scene.sceneRadius));
    if (s.missed)
        c = shiftEnvironment(s.wi, oh.ng);
    else
        c = shiftReconnect(s.from, oh.p, oh.ng, s.next.p, s.next.ng);
    o.alive = c.ok;  // failure: no offset path, the reverse never maps here
    if (o.alive) {
        // Light strategy at the target: p'_L·J = p_L, so the offset's light density in the
        // base's measure is r·p_L (zero if the offset vertex cannot do NEE).
        o.rLight = bsdfIsDeltaOnly(v.bsdf) ? 0.0 : o.r;
        o.woWorld = -c.wi;
        o.state = kShiftRecentlyConnected;
        ray.dir = c.wi;
        ray.trace = true;
        if (!s.missed) ray.trace = towardsTarget(ray.origin, s.next.p, ray.dir, ray.tMax);
    }
    return ray;
}

// Second half, once the visibility is known (call only for a live offset).
void gptReconnectDone(inout OffsetPath o, OffsetVertex v, BaseSegment s, ConnectionShift c, bool occluded) {
    if (occluded) {
        // Occluded: no BSDF density and no contribution, but light sampling could still
        // produce this path, so its light density stays in the target's emission weight.
        // r = 0 and beta' = 0 then act as a failed shift for everything after.
        o.beta = vec3(0.0);
        o.r = 0.0;
    } else {
        vec3 wiLocal = toLocal(c.wi, v.t, v.b, o.hit.ns);
        vec3 fo = bsdfEval(v.bsdf, v.wo, wiLocal);
        float po = bsdfPdf(v.bsdf, v.wo, wiLocal);
        SegmentShift seg = shiftSegment(fo, po, c.jacobian, s.rrInv, s.bs.pdf);
        o.beta *= seg.throughput;
        o.r *= seg.pdfRatio;
    }
}

// NOT_CONNECTED offset, half-vector copy shift (reflection only: gdpt has no transmission),
// first half: the offset's own direction; its ray finds the offset's own next vertex.
ShiftRay gptHalfVectorRay(inout OffsetPath o, OffsetVertex v, BaseSegment s) {
    SurfaceHit oh = o.hit;
    ShiftRay ray = noShiftRay(offsetRayOriginScaled(oh.p, oh.ng, scene.sceneRadius));
    HalfVectorShift h = shiftHalfVector(v.bsdf, s.woLocal, s.bs.wi, s.bs.lobe == kLobeSpecular, v.wo);
    ray.dir = toWorld(h.wiLocal, v.t, v.b, oh.ns);
    o.alive = h.ok && !(dot(ray.dir, oh.ng) <= 0.0);
    if (o.alive) {
        SegmentShift seg = shiftSegment(h.f, h.pdf, h.jacobian, s.rrInv, s.bs.pdf);
        o.beta *= seg.throughput;
        o.r *= seg.pdfRatio;
        ray.trace = true;
    }
    return ray;
}

// Second half (call only for a live offset): the next vertex must be of the base's kind
// (surface or environment), and the step must be invertible: the reverse shift would not
// reconnect there.
void gptHalfVectorDone(inout OffsetPath o, BaseSegment s, bool offCurRough, vec3 wi, Hit ho) {
    bool offMissed = ho.triangle == kInvalidIndex;
    bool sameKind = offMissed == s.missed;
    bool offNextRough = true;
    if (sameKind && !offMissed) {
        o.hit = makeSurfaceHit(ho.triangle, ho.u, ho.v, wi);
        offNextRough = roughAll(materialBsdf(o.hit.material, o.hit.uv));
    }
    o.alive = sameKind && shiftHalfVectorInvertible(s.curRough, offCurRough, offNextRough);
    o.woWorld = -wi;
}

// A NOT_CONNECTED offset's shift, first half: the reconnection's ray where `reconnect`, else
// (kHasGlossy only) the half-vector copy's. `c` is the reconnection's (unset for a half-vector
// copy).
ShiftRay gptOwnVertexRay(inout OffsetPath o, OffsetVertex v, BaseSegment s, bool reconnect, out ConnectionShift c,
                         inout uint rays) {
    ShiftRay ray;
    if (reconnect || !kHasGlossy) {  // (the constant lets the compiler drop the other branch)
        ray = gptReconnectRay(o, v, s, c);
    } else {
        ray = gptHalfVectorRay(o, v, s);
        c = noConnectionShift();
    }
    // A live reconnection's zero-length connection traces nothing but counts its ray, as
    // occludedTowards's caller did.
    if (o.alive) rays++;
    return ray;
}

// Second half with glossy vertices, once the ray's closest hit `ho` is known (for the
// reconnection's visibility, any hit before tMax occludes: the same answer as traceAny's; a
// ray not traced: a miss).
void gptOwnVertexHit(inout OffsetPath o, OffsetVertex v, BaseSegment s, bool reconnect, bool offCurRough,
                     ConnectionShift c, ShiftRay ray, Hit ho) {
    if (o.alive && reconnect) gptReconnectDone(o, v, s, c, ho.triangle != kInvalidIndex);
    if (o.alive && !reconnect) gptHalfVectorDone(o, s, offCurRough, ray.dir, ho);
}

// A NOT_CONNECTED offset's shift, both halves around its own ray. With glossy vertices both
// kinds trace their ray at one call site, a closest-hit query: lavapipe before Mesa 23 runs
// every branch that any lane of a SIMD vector takes, so two call sites cost two traversal loops
// wherever a vector holds offsets of both kinds (glossy_cornell: 2.5 % less time per sample,
// the same bits).
void gptOwnVertexShift(inout OffsetPath o, OffsetVertex v, BaseSegment s, bool reconnect, bool offCurRough,
                       inout uint rays) {
    ConnectionShift c;
    ShiftRay ray = gptOwnVertexRay(o, v, s, reconnect, c, rays);
    if (!kHasGlossy) {
        if (o.alive) gptReconnectDone(o, v, s, c, ray.trace && traceAny(ray.origin, ray.dir, 0.0, ray.tMax));
    } else {
        Hit ho = missHit(ray.tMax);
        if (ray.trace) ho = traceClosest(ray.origin, ray.dir, 0.0, ray.tMax);
        gptOwnVertexHit(o, v, s, reconnect, offCurRough, c, ray, ho);
    }
}

// Shifts one live offset that shares the base's vertex over the base's new segment s (the
// connection states of Kettunen et al. 2015 §4.2). CONNECTED: same vertices, same f and p.
// RECENTLY_CONNECTED: the base's vertex with the offset's own incoming direction, f and p
// re-evaluated (never Dirac: a reconnection target has no Dirac lobe, shiftRoughnessAll),
// Jacobian 1.
void gptShiftSharedOffset(inout OffsetPath o, OffsetVertex v, BaseSegment s) {
    if (o.state == kShiftConnected) {
        o.beta *= s.bs.weight * s.rrInv;
        o.rLight = o.r;
    } else {
        vec3 fo = bsdfEval(s.bsdf, v.wo, s.bs.wi);
        float po = bsdfPdf(s.bsdf, v.wo, s.bs.wi);
        SegmentShift seg = shiftSegment(fo, po, 1.0, s.rrInv, s.bs.pdf);
        o.beta *= seg.throughput;
        o.r *= seg.pdfRatio;
        o.rLight = o.r;
        o.state = kShiftConnected;
    }
}

// Shifts one live offset over the base's new segment s: gptShiftSharedOffset, or for a
// NOT_CONNECTED one (only where `general`; the fast loop has none) reconnection where the
// base's current and next and the offset's current vertex are rough, else the half-vector
// copy.
void gptShiftOffset(inout OffsetPath o, OffsetVertex v, BaseSegment s, bool general, inout uint rays) {
    if (o.state != kShiftNotConnected) {
        gptShiftSharedOffset(o, v, s);
    } else if (general) {
        bool offCurRough = roughAll(v.bsdf);
        bool reconnect = shiftUseReconnection(s.curRough, s.nextRough, offCurRough);
        if (reconnect || kHasGlossy)
            gptOwnVertexShift(o, v, s, reconnect, offCurRough, rays);
        else
            o.alive = false;  // unreachable when every vertex is rough
    }
}

// gptShiftOffset in a general bounce of a scene without glossy vertices, where every
// own-vertex shift is a reconnection, split around the reconnection's visibility ray so that
// the four offsets' rays, which all end at the base's next vertex (or leave along its
// direction to the environment), are traced as one beam (traceAnyBeam, gpt_bounce.glsl).
// First half: the shift of an offset that shares the base's vertex, or the reconnection's
// ray (`reconnecting`: then finish it with gptReconnectDone).
ShiftRay gptShiftOffsetBegin(inout OffsetPath o, OffsetVertex v, BaseSegment s, out ConnectionShift c,
                             out bool reconnecting, inout uint rays) {
    ShiftRay ray = noShiftRay(vec3(0.0));
    c = noConnectionShift();
    reconnecting = false;
    if (o.alive) {
        if (o.state != kShiftNotConnected) {
            gptShiftSharedOffset(o, v, s);
        } else if (!shiftUseReconnection(s.curRough, s.nextRough, roughAll(v.bsdf))) {
            o.alive = false;  // unreachable when every vertex is rough
        } else {
            ray = gptReconnectRay(o, v, s, c);
            // A live reconnection's zero-length connection traces nothing but counts its ray.
            if (o.alive) rays++;
            reconnecting = o.alive;
        }
    }
    return ray;
}

// How far the offsets' rays of one bundle may spread (traceClosestFour's maxGrow), as a share
// of the scene's radius: 0.003 to 0.1 ran at the same speed on glossy_cornell (bench/RESULTS.md,
// "Ray bundles for the glossy offsets' shifts").
const float kGptBundleGrow = 0.03;

// gptShiftOffset in a general bounce of a scene with glossy vertices, split around the
// own-vertex shift's closest-hit ray so that the four offsets' rays, which start about a pixel
// apart and point near the base's new direction (a reconnection towards the base's next
// vertex, a half-vector copy along its mirrored lobe), are traced as bundles
// (traceClosestFour, gpt_bounce.glsl). First half: the shift of an offset that shares the
// base's vertex, or the own vertex's ray (`own`: then finish it with gptOwnVertexHit; a ray
// not to be traced has trace false).
ShiftRay gptShiftOffsetOwnBegin(inout OffsetPath o, OffsetVertex v, BaseSegment s, out ConnectionShift c,
                                out bool own, out bool reconnect, out bool offCurRough, inout uint rays) {
    ShiftRay ray = noShiftRay(s.from);
    c = noConnectionShift();
    own = o.alive && o.state == kShiftNotConnected;
    offCurRough = roughAll(v.bsdf);
    reconnect = shiftUseReconnection(s.curRough, s.nextRough, offCurRough);
    if (o.alive && !own) gptShiftSharedOffset(o, v, s);
    if (own) ray = gptOwnVertexRay(o, v, s, reconnect, c, rays);
    return ray;
}

// ---- Emission the pairs reach, with MIS between base and offset ----

// The environment, reached by BSDF sampling only: two strategies, base and offset, w =
// 1/(1 + r²); a failed shift leaves the base alone (weight 1).
void gptPairEnvironment(inout OffsetPath o, vec3 beta, vec3 le) {
    if (!o.alive)
        addPair(o, 1.0, beta * le, vec3(0.0));
    else
        addPair(o, gptMisWeightPair(o.countRatio * o.r), beta * le, o.beta * le);
}

// An emitter at the base's next vertex (emission le, reached with BSDF density pdfBsdf, light
// density pdfLight where the pair has the light strategy, else 0). An offset on its own
// vertex (half-vector branch) has BSDF sampling only: w = 1/(1 + r²), with its own emission.
// Reconnected (this bounce or before): four strategies (gptMisWeight). A failed shift, before
// or at this bounce: the base alone (zero offset densities); after a failed half-vector step
// the pair had no NEE, so the base takes full weight.
void gptPairEmitter(inout OffsetPath o, bool own, vec3 beta, vec3 le, float pdfBsdf, float pdfLight) {
    if (own && o.alive) {
        vec3 leO = surfaceEmission(o.hit);
        if (maxComponent(le) > 0.0 || maxComponent(leO) > 0.0)
            addPair(o, gptMisWeightPair(o.countRatio * o.r), beta * le, o.beta * leO);
    } else if (maxComponent(le) > 0.0) {
        bool alive = o.alive;
        float w =
            gptMisWeight(pdfBsdf, pdfLight, alive ? o.countRatio * o.r * pdfBsdf : 0.0,
                         alive ? o.countRatio * o.rLight * pdfLight : 0.0);
        addPair(o, w, beta * le, alive ? o.beta * le : vec3(0.0));
    }
}

#endif  // GDPT_LIB_GPT_STEPS
