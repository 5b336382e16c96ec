// gpt_bounce.glsl — one bounce of gpt.comp's base path and its four offsets, as the body of
// traceSample's bounce loop, in the steps of Kettunen et al. 2015 §4 (gpt_pair.glsl):
//   1. the vertices: the base's BSDF and frame, each offset's (gptOffsetVertex);
//   2. next-event estimation with the base's light point for every pair (gptBaseNee,
//      gptPairNee; with GDPT_GPT_BEAMS, gpt_trace.glsl, its halves around one beam of the
//      offsets' own shadow rays), MIS between base and offset over four strategies
//      (gptMisWeight);
//   3. BSDF sampling and Russian roulette of the base (gptContinueBase);
//   4. the shift of every live offset over the base's new segment (gptShiftOffset; with
//      GDPT_GPT_BEAMS and no glossy vertices, the reconnections' rays as one beam:
//      gptShiftOffsetBegin, traceAnyBeam, gptReconnectDone; with glossy vertices, the
//      reconnections' and half-vector copies' rays as bundles: gptShiftOffsetOwnBegin,
//      traceClosestFour, gptOwnVertexHit);
//   5. the emission the pairs reach there, MIS-weighted (gptPairEnvironment, gptPairEmitter).
//
// Not a function: gpt.comp includes this text twice, into two loops, once with
// GDPT_GPT_GENERAL true and once false (the split bounce loop, see gpt.comp); the steps are
// functions. With GDPT_GPT_GENERAL false the code for offsets with vertices of their own
// (NOT_CONNECTED: own BSDFs, NEE rays, reconnection and half-vector shifts) folds away; that
// form may only run once no live offset has one. The whole bounce as a function (an inlined
// function returning from inside the loop, the fast loop behind a specialisation constant)
// took lavapipe 22.3 630 ms to create the single-loop pipeline, this form 330 ms, before
// spirv-opt inlined the kernels' functions.
//
// Uses traceSample's locals: depth (the loop counter), px, py, lds, rng, beta, sh, d, offs,
// rays, and pathEnded (set, with a break, when the base path ends). No include guard:
// included twice.
    // One-sided back faces absorb: the base path ends; an offset there cannot continue
    // (its reverse shift does not exist), so its pair falls back to the base alone.
    if (oneSidedBack(sh)) { pathEnded = true; break; }
    [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) {
        if (offs[i].alive && ownVertex(offs[i], GDPT_GPT_GENERAL) && oneSidedBack(offs[i].hit))
            offs[i].alive = false;
    }

    // ---- 1. Vertices ----
    BsdfParams bsdf = materialBsdf(sh.material, sh.uv);
    vec3 t, b;
    makeBasis(sh.ns, t, b);
    vec3 woLocal = toLocal(-d, t, b, sh.ns);
    vec3 origin = offsetRayOriginScaled(sh.p, sh.ng, scene.sceneRadius);
    bool baseCurRough = roughAll(bsdf);
    OffsetVertex offV[kGptNumOffsets];
    bool lightStrategy[kGptNumOffsets];
    [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) {
        bool own = offs[i].alive && ownVertex(offs[i], GDPT_GPT_GENERAL);
        offV[i] = gptOffsetVertex(offs[i], own, bsdf, t, b, sh.ns);
        lightStrategy[i] = gptPairHasLightStrategy(own, offV[i].bsdf, baseCurRough);
    }

    // ---- 2. Next-event estimation with the same light point for all pairs ----
    vec3 ul = ldLight(lds, depth);
    LightSample ls;
    if (!bsdfIsDeltaOnly(bsdf) && sampleLight(sh.p, ul, ls) && dot(ls.wi, sh.ng) > 0.0) {
        BaseNee nee = gptBaseNee(ls, ul, bsdf, woLocal, t, b, sh.ns, origin, beta, rays);
#ifdef GDPT_GPT_BEAMS
        PairNee pairNee[kGptNumOffsets];
        vec3 neeOrigin[4];
        bvec4 neeTrace = bvec4(false);
        [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) {
            bool own = offs[i].alive && ownVertex(offs[i], GDPT_GPT_GENERAL);
            pairNee[i] = gptPairNeeBegin(offs[i], offV[i], own, lightStrategy[i], nee, bsdf, sh.p);
            neeOrigin[i] = pairNee[i].origin;
            neeTrace[i] = gptPairCounted(px, py, i) && pairNee[i].trace;
        }
        // The own vertices' shadow rays all end at the light point: one beam (the fast form
        // has no own vertices, and no beam).
        bvec4 neeOccluded = bvec4(false);
        if (GDPT_GPT_GENERAL)
            neeOccluded =
                traceAnyBeam(beamTowards(neeOrigin[0], neeOrigin[1], neeOrigin[2], neeOrigin[3], neeTrace, nee.ls.pLight));
#endif
        GDPT_UNROLL_UNLESS_TRACING for (uint i = 0u; i < kGptNumOffsets; ++i) {
            if (gptPairCounted(px, py, i)) {
#ifdef GDPT_GPT_BEAMS
                OffsetNee on = gptPairNeeEnd(offs[i], pairNee[i], nee, neeOccluded[i], rays);
#else
                bool own = offs[i].alive && ownVertex(offs[i], GDPT_GPT_GENERAL);
                OffsetNee on = gptPairNee(offs[i], offV[i], own, lightStrategy[i], nee, bsdf, sh.p, rays);
#endif
                float c = offs[i].countRatio;
                float w = gptMisWeight(ls.pdf, nee.pdfBsdf, c * on.qLight, c * on.qBsdf);
                if (on.counts) addPair(offs[i], w, nee.fBase, on.f);
            }
        }
    }

    // ---- 3. BSDF sampling and Russian roulette of the base (shared by the offsets) ----
    BaseSegment seg;
    seg.from = sh.p;
    seg.bsdf = bsdf;
    seg.woLocal = woLocal;
    seg.curRough = baseCurRough;
    if (!gptContinueBase(bsdf, woLocal, t, b, sh, lds, depth, rng, beta, seg.bs, seg.wi, seg.rrInv)) {
        pathEnded = true;
        break;
    }
    Hit next = traceClosest(origin, seg.wi, 0.0, kInf);
    rays++;
    seg.missed = next.triangle == kInvalidIndex;
    if (seg.missed && !kHasEnv) { pathEnded = true; break; }
    seg.nextRough = true;
    if (!seg.missed) {
        seg.next = makeSurfaceHit(next.triangle, next.u, next.v, seg.wi);
        if (kHasGlossy) seg.nextRough = roughAll(materialBsdf(seg.next.material, seg.next.uv));
    }

    // ---- 4. Shift every live offset over this segment ----
#ifdef GDPT_GPT_BEAMS
    if (kHasGlossy && GDPT_GPT_GENERAL) {
        // Reconnections and half-vector copies, each a closest-hit query from the offset's own
        // vertex: the four in as few bundles as their spread allows (traceClosestFour).
        ConnectionShift conn[kGptNumOffsets];
        ShiftRay shiftRay[kGptNumOffsets];
        bool own[kGptNumOffsets];
        bool reconnect[kGptNumOffsets];
        bool offCurRough[kGptNumOffsets];
        vec4 tMax = vec4(0.0);
        [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) {
            shiftRay[i] =
                gptShiftOffsetOwnBegin(offs[i], offV[i], seg, conn[i], own[i], reconnect[i], offCurRough[i], rays);
            if (shiftRay[i].trace) tMax[i] = shiftRay[i].tMax;
        }
        Hit ho[kGptNumOffsets];
        traceClosestFour(shiftRay[0].origin, shiftRay[0].dir, shiftRay[1].origin, shiftRay[1].dir, shiftRay[2].origin,
                         shiftRay[2].dir, shiftRay[3].origin, shiftRay[3].dir, tMax, 2.0 * scene.sceneRadius,
                         kGptBundleGrow * scene.sceneRadius, ho[0], ho[1], ho[2], ho[3]);
        [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) {
            if (own[i]) gptOwnVertexHit(offs[i], offV[i], seg, reconnect[i], offCurRough[i], conn[i], shiftRay[i], ho[i]);
        }
    } else if (GDPT_GPT_GENERAL) {
        // Every own-vertex shift reconnects, to the base's next vertex or along its direction
        // to the environment: the visibility rays as one beam.
        ConnectionShift conn[kGptNumOffsets];
        ShiftRay shiftRay[kGptNumOffsets];
        bvec4 reconnecting;
        [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i)
            shiftRay[i] = gptShiftOffsetBegin(offs[i], offV[i], seg, conn[i], reconnecting[i], rays);
        // (Only a reconnection traces: trace implies reconnecting.)
        bvec4 trace = bvec4(shiftRay[0].trace, shiftRay[1].trace, shiftRay[2].trace, shiftRay[3].trace);
        OcclusionBeam beam =
            seg.missed
                ? beamAlong(shiftRay[0].origin, shiftRay[1].origin, shiftRay[2].origin, shiftRay[3].origin, trace,
                            seg.wi)
                : beamTowards(shiftRay[0].origin, shiftRay[1].origin, shiftRay[2].origin, shiftRay[3].origin,
                              trace, seg.next.p);
        bvec4 shiftOccluded = traceAnyBeam(beam);
        [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) {
            if (reconnecting[i]) gptReconnectDone(offs[i], offV[i], seg, conn[i], shiftOccluded[i]);
        }
    } else
#endif
    {
        GDPT_UNROLL_UNLESS_TRACING for (uint i = 0u; i < kGptNumOffsets; ++i) {
            if (offs[i].alive) gptShiftOffset(offs[i], offV[i], seg, GDPT_GPT_GENERAL, rays);
        }
    }

    // ---- 5. Emission reached by the BSDF sample: the environment or an emitter ----
    if (kHasEnv && seg.missed) {  // (kHasEnv: else the path ended above; lets the compiler drop this)
        [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) {
            if (gptPairCounted(px, py, i)) gptPairEnvironment(offs[i], beta, scene.envRadiance);
        }
        { pathEnded = true; break; }
    }
    if (kHasLightTris) {
        vec3 le = surfaceEmission(seg.next);
        float pdfLight = 0.0;
        if (seg.bs.lobe != kLobeSpecular && maxComponent(le) > 0.0) {
            vec3 nl = triangleUnitNormal(seg.next.triangle);
            pdfLight = lightTrianglePdf(seg.next.triangle, sh.p, seg.next.p, nl);
        }
        [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i) {
            // The light strategy competes only where NEE counted for this pair.
            if (gptPairCounted(px, py, i))
                gptPairEmitter(offs[i], ownVertex(offs[i], GDPT_GPT_GENERAL), beta, le, seg.bs.pdf,
                               lightStrategy[i] ? pdfLight : 0.0);
        }
    }
    // Nothing left to carry (e.g. the base and all offsets sit on a black emitter): every
    // later contribution of every pair would be w·0, so stop tracing.
    bool carries = maxComponent(beta) > 0.0;
    [[unroll]] for (uint i = 0u; i < kGptNumOffsets; ++i)
        carries = carries || (offs[i].alive && maxComponent(offs[i].beta) > 0.0);
    if (!carries) { pathEnded = true; break; }
    sh = seg.next;
    d = seg.wi;
