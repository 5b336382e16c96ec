// gpt_bounce.glsl — one bounce of gpt.comp's base path and its four offsets, as the body of
// traceSample's bounce loop: NEE with the same light point for all, BSDF sampling and Russian
// roulette of the base, the shift of every live offset over the new segment, and the emission
// it reaches. Not a function on purpose: gpt.comp includes this text twice, into two loops,
// once with GDPT_GPT_GENERAL true and once false (the split bounce loop, see gpt.comp). The
// function form (an inlined function returning from inside the loop, the fast loop behind a
// specialisation constant) took lavapipe 22.3 630 ms to create the single-loop pipeline,
// this form 330 ms, as before the split (bench/RESULTS.md, fourth session).
//
// Uses traceSample's locals: depth (the loop counter), px, py, lds, rng, beta, sh, d, offs, rays,
// and pathEnded (set, with a break, when the base path ends). With GDPT_GPT_GENERAL false
// the code for offsets with vertices of their own (NOT_CONNECTED: own BSDFs, NEE rays,
// reconnection and half-vector shifts) is compiled out; that form may only run once no live
// offset has one. No include guard: included twice.
    // One-sided back faces absorb: the base path ends; an offset there cannot continue
    // (its reverse shift does not exist), so its pair falls back to the base alone.
    if (oneSidedBack(sh)) { pathEnded = true; break; }
    for (uint i = 0u; i < kGptNumOffsets; ++i) {
        if (offs[i].alive && ownVertex(offs[i], GDPT_GPT_GENERAL) && oneSidedBack(offs[i].hit))
            offs[i].alive = false;
    }

    BsdfParams bsdf = materialBsdf(sh.material, sh.uv);
    vec3 t, b;
    makeBasis(sh.ns, t, b);
    vec3 woLocal = toLocal(-d, t, b, sh.ns);
    vec3 origin = offsetRayOriginScaled(sh.p, sh.ng, scene.sceneRadius);

    // Offsets' own BSDFs and frames (NOT_CONNECTED only).
    BsdfParams offBsdf[kGptNumOffsets];
    vec3 offT[kGptNumOffsets], offB[kGptNumOffsets], offWo[kGptNumOffsets];
    for (uint i = 0u; i < kGptNumOffsets; ++i) {
        offBsdf[i] = bsdf;  // placeholder for shared / dead offsets (never read)
        if (!offs[i].alive) continue;
        if (ownVertex(offs[i], GDPT_GPT_GENERAL)) {
            SurfaceHit oh = offs[i].hit;
            offBsdf[i] = materialBsdf(oh.material, oh.uv);
            makeBasis(oh.ns, offT[i], offB[i]);
            offWo[i] = toLocal(offs[i].woWorld, offT[i], offB[i], oh.ns);
        } else {
            offWo[i] = toLocal(offs[i].woWorld, t, b, sh.ns);  // shared vertex, own wo
        }
    }

    // Whether the light strategy exists for each pair at this vertex (GPT_REFERENCE §1.5):
    // always for a lone base (failed shift) and a shared vertex; for separate vertices
    // only if both are rough (area lights; the BSDF never hits a punctual light). The
    // BSDF-sampled emission of the next vertex then competes with it or not. Rough means
    // rough over ALL components (not only the smooth ones NEE evaluates, the reference's
    // choice): only then does the BSDF step reconnect to the light point, so NEE and BSDF
    // sampling use the same shift and their pair weights sum to one (the smooth-only rule,
    // combined with the all-components classification above, made a diffuse lobe under
    // a mirror coat count its light twice: NEE with four strategies, and again through
    // the half-vector branch, which has no light strategy).
    bool baseRoughNee = roughAll(bsdf);
    bool lightActive[kGptNumOffsets];
    for (uint i = 0u; i < kGptNumOffsets; ++i) {
        // A Dirac-only offset vertex fails every shift of both techniques, so its pair is
        // the lone base's (PT weights, light strategy included).
        lightActive[i] = !offs[i].alive || !ownVertex(offs[i], GDPT_GPT_GENERAL) ||
                         bsdfIsDeltaOnly(offBsdf[i]) || (baseRoughNee && roughAll(offBsdf[i]));
    }

    // ---- Next-event estimation with the same light point for all (§1.5) ----
    // Densities are visibility-aware: a path whose last segment is occluded cannot be
    // produced by BSDF sampling (its BSDF density is 0) but can by light sampling. This
    // keeps the four weights of a path equal whichever technique sampled it.
    vec3 ul = ldLight(lds, depth);
    LightSample ls;
    if (!bsdfIsDeltaOnly(bsdf) && sampleLight(sh.p, ul, ls) && dot(ls.wi, sh.ng) > 0.0) {
        vec3 wiLocal = toLocal(ls.wi, t, b, sh.ns);
        vec3 f = bsdfEval(bsdf, woLocal, wiLocal);
        float pdfBsdf = ls.isDelta != 0u ? 0.0 : bsdfPdf(bsdf, woLocal, wiLocal);
        rays++;
        bool visible = !traceAny(origin, ls.wi, 0.0, ls.dist * (1.0 - 1e-4));
        vec3 fBase = visible ? beta * f * ls.Li / ls.pdf : vec3(0.0);
        float pdfBsdfV = visible ? pdfBsdf : 0.0;  // BSDF density including visibility
        // Per pair one weight and one addPair, whichever case it is: on lavapipe before Mesa
        // 23 (every branch runs under lane masks) each case's own copy cost its time.
        for (uint i = 0u; i < kGptNumOffsets; ++i) {
            if (!gptPairExists(px, py, i)) continue;
            bool own = offs[i].alive && ownVertex(offs[i], GDPT_GPT_GENERAL);
            bool sharedVertex = offs[i].alive && !own;
            // The offset's light and BSDF densities in the base's measure and its
            // contribution; zero densities = a failed shift: the base alone, PT's weight.
            float qLight = 0.0;
            float qBsdf = 0.0;
            vec3 fOff = vec3(0.0);
            bool counts = true;
            // The one BSDF evaluation a pair needs: a shared vertex with the offset's own
            // incoming direction (§1.5 RECENTLY_CONNECTED), or the offset's own vertex.
            bool evaluate = sharedVertex && offs[i].state == kShiftRecentlyConnected;
            BsdfParams evalBsdf = bsdf;
            vec3 evalWi = wiLocal;
            vec3 wiO = vec3(0.0);
            float distO = 0.0;
            vec3 liO = vec3(0.0);
            float jacobianLight = 0.0;
            bool valid = false;
            if (own) {
                // NOT_CONNECTED: reconnect the offset vertex to the same light point, only
                // if both vertices are rough or the light is punctual; otherwise this NEE
                // sample counts for neither (weight 0, the reference's choice).
                counts = ls.isDelta != 0u || lightActive[i];
                SurfaceHit oh = offs[i].hit;
                vec3 toLight = ls.pLight - oh.p;
                distO = length(toLight);
                wiO = toLight / distO;
                // Densities of the offset path under the reverse technique: zero where the
                // base sampler at p+δ would have rejected it (light behind the surface,
                // light facing away, Dirac-only vertex), which makes the shift fail.
                valid = counts && distO > 0.0 && dot(wiO, oh.ng) > 0.0 && !bsdfIsDeltaOnly(offBsdf[i]) &&
                        gptOffsetLight(ls, ul, sh.p, oh.p, wiO, distO, liO, jacobianLight);
                evaluate = valid;
                evalBsdf = offBsdf[i];
                evalWi = toLocal(wiO, offT[i], offB[i], oh.ns);
            }
            vec3 fEval = f;
            float pdfEval = pdfBsdfV;
            if (evaluate) {
                fEval = bsdfEval(evalBsdf, offWo[i], evalWi);
                pdfEval = bsdfPdf(evalBsdf, offWo[i], evalWi);
            }
            if (sharedVertex) {
                // Shared vertex: same light point and visibility; the offset's own incoming
                // direction only changes the BSDF (f, pdfBsdfV without it: both are zero
                // already where the light is punctual or occluded).
                float pdfBsdfO = (ls.isDelta != 0u || !visible) ? 0.0 : pdfEval;
                fOff = visible ? offs[i].beta * fEval * ls.Li / ls.pdf : vec3(0.0);
                qLight = offs[i].r * ls.pdf;
                qBsdf = offs[i].r * pdfBsdfO;
            }
            if (own && valid) {
                vec3 fo = fEval * liO;
                float pdfBsdfO = ls.isDelta != 0u ? 0.0 : pdfEval;
                // The offset's visibility matters for its contribution and for its BSDF
                // density (which enters the base's weight).
                if (maxComponent(fo) > 0.0 || (pdfBsdfO > 0.0 && maxComponent(fBase) > 0.0)) {
                    SurfaceHit oh = offs[i].hit;
                    rays++;
                    if (!traceAny(offsetRayOriginScaled(oh.p, oh.ng, scene.sceneRadius), wiO, 0.0, distO * (1.0 - 1e-4)))
                        fOff = offs[i].beta * fo * (jacobianLight / ls.pdf);
                    else
                        pdfBsdfO = 0.0;
                }
                // Light strategy of the offset in the base's measure: p'_L J = p_L (same
                // light point, area measure); BSDF strategy p'_B J.
                qLight = offs[i].r * ls.pdf;
                qBsdf = offs[i].r * pdfBsdfO * jacobianLight;
            }
            if (counts) addPair(offs[i], gptMisWeight(ls.pdf, pdfBsdfV, qLight, qBsdf), fBase, fOff);
        }
    }

    // ---- BSDF sampling continues the base path ----
    BsdfSample bs;
    if (!bsdfSample(bsdf, woLocal, ldBsdf(lds, depth), bs)) { pathEnded = true; break; }
    vec3 wi = toWorld(bs.wi, t, b, sh.ns);
    if (dot(wi, sh.ng) <= 0.0) { pathEnded = true; break; }
    beta *= bs.weight;
    bool prevSpecular = bs.lobe == kLobeSpecular;
    vec3 prevP = sh.p;

    // Russian roulette from the base, shared by the offsets (§1.4).
    float rrInv = 1.0;
    if (depth + 1u >= scene.rrDepth) {
        float q = min(maxComponent(beta), 0.95);
        if (rngNext(rng) >= q) { pathEnded = true; break; }
        rrInv = 1.0 / q;
        beta *= rrInv;
    }
    if (depth + 1u >= kMaxDepth) { pathEnded = true; break; }  // pt.comp would not trace this segment either

    Hit next = traceClosest(origin, wi, 0.0, kInf);
    rays++;
    bool baseMissed = next.triangle == kInvalidIndex;
    if (baseMissed && !kHasEnv) { pathEnded = true; break; }
    SurfaceHit nextSh;
    bool baseNextRough = true;
    if (!baseMissed) {
        nextSh = makeSurfaceHit(next.triangle, next.u, next.v, wi);
        if (kHasGlossy) baseNextRough = roughAll(materialBsdf(nextSh.material, nextSh.uv));
    }
    bool baseCurRough = roughAll(bsdf);

    // ---- Shift every live offset over this segment (§1.4) ----
    for (uint i = 0u; i < kGptNumOffsets; ++i) {
        if (!offs[i].alive) continue;
        if (offs[i].state == kShiftConnected) {
            offs[i].beta *= bs.weight * rrInv;  // shares the vertex: same f and p
            offs[i].rLight = offs[i].r;
            continue;
        }
        if (offs[i].state == kShiftRecentlyConnected) {
            // Shared vertex, own incoming direction: re-evaluate f and p (never Dirac: a
            // reconnection target has no Dirac lobe, shiftRoughnessAll); the direction is the
            // base's, so J = 1.
            vec3 fo = bsdfEval(bsdf, offWo[i], bs.wi);
            float po = bsdfPdf(bsdf, offWo[i], bs.wi);
            SegmentShift seg = shiftSegment(fo, po, 1.0, rrInv, bs.pdf);
            offs[i].beta *= seg.throughput;
            offs[i].r *= seg.pdfRatio;
            offs[i].rLight = offs[i].r;
            offs[i].state = kShiftConnected;
            continue;
        }
        if (!GDPT_GPT_GENERAL) continue;  // unreachable in the fast form: no offset of its own
        SurfaceHit oh = offs[i].hit;
        BsdfParams ob = offBsdf[i];
        vec3 ohOrigin = offsetRayOriginScaled(oh.p, oh.ng, scene.sceneRadius);
        bool offCurRough = roughAll(ob);
        if (shiftUseReconnection(baseCurRough, baseNextRough, offCurRough)) {
            // Reconnection shift to the base's next vertex, or the environment shift in the
            // same direction; occlusion = failure.
            ConnectionShift c;
            if (baseMissed) c = shiftEnvironment(wi, oh.ng);
            else c = shiftReconnect(sh.p, oh.p, oh.ng, nextSh.p, nextSh.ng);
            if (!c.ok) {
                offs[i].alive = false;  // no offset path: the reverse never maps here
                continue;
            }
            float rPrefix = offs[i].r;
            // Light strategy at the target: p'_L J = p_L, so the offset's light density in
            // the base's measure is rPrefix·p_L (zero if the offset vertex cannot do NEE).
            offs[i].rLight = bsdfIsDeltaOnly(ob) ? 0.0 : rPrefix;
            offs[i].woWorld = -c.wi;
            offs[i].state = kShiftRecentlyConnected;
            // Visibility from the offset vertex, for the environment too (an escaping offset
            // that is occluded has no density either).
            rays++;
            if (traceAny(ohOrigin, c.wi, 0.0, baseMissed ? kInf : c.dist * (1.0 - 1e-4))) {
                // Occluded: the offset path has no BSDF density and no contribution, but
                // light sampling could still produce it, so its light density stays in
                // this vertex's emission weight. r = 0 and beta' = 0 then act as a failed
                // shift for everything after.
                offs[i].beta = vec3(0.0);
                offs[i].r = 0.0;
                continue;
            }
            vec3 wiLocalO = toLocal(c.wi, offT[i], offB[i], oh.ns);
            vec3 fo = bsdfEval(ob, offWo[i], wiLocalO);
            float po = bsdfPdf(ob, offWo[i], wiLocalO);
            SegmentShift seg = shiftSegment(fo, po, c.jacobian, rrInv, bs.pdf);
            offs[i].beta *= seg.throughput;
            offs[i].r *= seg.pdfRatio;
            continue;
        }
        if (!kHasGlossy) {
            offs[i].alive = false;  // unreachable when every vertex is rough
            continue;
        }
        // Half-vector copy shift (reflection only: gdpt has no transmission).
        HalfVectorShift h = shiftHalfVector(ob, woLocal, bs.wi, bs.lobe == kLobeSpecular, offWo[i]);
        vec3 wiO = toWorld(h.wiLocal, offT[i], offB[i], oh.ns);
        if (!h.ok || dot(wiO, oh.ng) <= 0.0) {
            offs[i].alive = false;
            continue;
        }
        SegmentShift seg = shiftSegment(h.f, h.pdf, h.jacobian, rrInv, bs.pdf);
        offs[i].beta *= seg.throughput;
        offs[i].r *= seg.pdfRatio;
        Hit ho = traceClosest(ohOrigin, wiO, 0.0, kInf);
        rays++;
        bool offMissed = ho.triangle == kInvalidIndex;
        if (offMissed != baseMissed) {
            offs[i].alive = false;  // environment / surface mismatch
            continue;
        }
        bool offNextRough = true;
        if (!offMissed) {
            offs[i].hit = makeSurfaceHit(ho.triangle, ho.u, ho.v, wiO);
            offNextRough = roughAll(materialBsdf(offs[i].hit.material, offs[i].hit.uv));
        }
        // Invertibility: the reverse shift would have reconnected (§1.4).
        if (!shiftHalfVectorInvertible(baseCurRough, offCurRough, offNextRough)) {
            offs[i].alive = false;
            continue;
        }
        offs[i].woWorld = -wiO;
    }

    // ---- Emission reached by the BSDF sample: environment or an emitter (§1.6) ----
    if (kHasEnv && baseMissed) {  // (kHasEnv: else the path ended above; lets the compiler drop this)
        vec3 le = scene.envRadiance;
        for (uint i = 0u; i < kGptNumOffsets; ++i) {
            if (!gptPairExists(px, py, i)) continue;
            if (!offs[i].alive) {
                addPair(offs[i], 1.0, beta * le, vec3(0.0));
            } else {
                // Not light-sampled: two strategies, base and offset.
                addPair(offs[i], gptMisWeightPair(offs[i].r), beta * le, offs[i].beta * le);
            }
        }
        { pathEnded = true; break; }
    }
    if (kHasLightTris) {
        vec3 le = surfaceEmission(nextSh);
        float pdfLight = 0.0;
        if (!prevSpecular && maxComponent(le) > 0.0) {
            vec3 nl = triangleUnitNormal(nextSh.triangle);
            pdfLight = lightTrianglePdf(nextSh.triangle, prevP, nextSh.p, nl);
        }
        for (uint i = 0u; i < kGptNumOffsets; ++i) {
            if (!gptPairExists(px, py, i)) continue;
            // The light strategy competes only where NEE counted for this pair.
            float pdfLightPair = lightActive[i] ? pdfLight : 0.0;
            if (ownVertex(offs[i], GDPT_GPT_GENERAL) && offs[i].alive) {
                // Half-vector branch: BSDF sampling only, w = p²/(p² + (J p')²).
                vec3 leO = surfaceEmission(offs[i].hit);
                if (maxComponent(le) > 0.0 || maxComponent(leO) > 0.0)
                    addPair(offs[i], gptMisWeightPair(offs[i].r), beta * le, offs[i].beta * leO);
            } else if (maxComponent(le) > 0.0) {
                // Reconnected (this bounce or before): four strategies. A failed shift
                // (before or at this bounce): the base alone (zero offset densities); after a
                // failed half-vector step the pair had no NEE, so the base takes full weight.
                bool alive = offs[i].alive;
                float w = gptMisWeight(bs.pdf, pdfLightPair, alive ? offs[i].r * bs.pdf : 0.0,
                                       alive ? offs[i].rLight * pdfLightPair : 0.0);
                addPair(offs[i], w, beta * le, alive ? offs[i].beta * le : vec3(0.0));
            }
        }
    }
    // Nothing left to carry (e.g. the base and all offsets sit on a black emitter): every
    // later contribution of every pair would be w·0, so stop tracing.
    bool carries = maxComponent(beta) > 0.0;
    for (uint i = 0u; i < kGptNumOffsets; ++i) carries = carries || (offs[i].alive && maxComponent(offs[i].beta) > 0.0);
    if (!carries) { pathEnded = true; break; }
    sh = nextSh;
    d = wi;
