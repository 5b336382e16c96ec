// bsdf.glsl: sampling matches the pdf (chi-square), sample weight = eval/pdf, pdf
// normalisation, white furnace, reciprocity, the Lambertian special case and edge cases.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "gdpt_shared.h"
#include "lib/bsdf.glsl"
#include "sampling_test_util.h"
#include "stats.h"

namespace {

using namespace gdpt::gpu;
using gdpt::test::DirHistogram;
using gdpt::test::kPiD;
using gdpt::test::Uniform;

vec3 dirFromTheta(float thetaDeg, float phiDeg = 0.0f) {
    float t = thetaDeg * kPi / 180.0f;
    float p = phiDeg * kPi / 180.0f;
    return vec3(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
}

struct Config {
    const char* name;
    BsdfParams m;
    float thetaODeg;
};

std::vector<Config> chi2Configs() {
    const vec3 c(0.8f, 0.5f, 0.2f);
    const vec3 white(1.0f);
    return {
        {"lambert_30", makeBsdfParams(c, 0.0f, 0.5f, 0.0f, white, 1.5f), 30.0f},
        {"lambert_80", makeBsdfParams(c, 0.0f, 0.5f, 0.0f, white, 1.5f), 80.0f},
        {"metal_r0.3_20", makeBsdfParams(c, 1.0f, 0.3f, 1.0f, white, 1.5f), 20.0f},
        {"metal_r0.3_70", makeBsdfParams(c, 1.0f, 0.3f, 1.0f, white, 1.5f), 70.0f},
        {"metal_r0.7_10", makeBsdfParams(c, 1.0f, 0.7f, 1.0f, white, 1.5f), 10.0f},
        {"metal_r0.7_75", makeBsdfParams(c, 1.0f, 0.7f, 1.0f, white, 1.5f), 75.0f},
        {"dielectric_r0.2_45", makeBsdfParams(c, 0.0f, 0.2f, 1.0f, white, 1.5f), 45.0f},
        {"dielectric_r0.2_85", makeBsdfParams(c, 0.0f, 0.2f, 1.0f, white, 1.5f), 85.0f},
        {"mix_m0.5_r0.5_s0.5", makeBsdfParams(c, 0.5f, 0.5f, 0.5f, vec3(1.0f, 0.8f, 0.6f), 1.4f), 50.0f},
        {"mirror_plus_diffuse", makeBsdfParams(c, 0.0f, 0.0f, 1.0f, white, 1.5f), 40.0f},
        {"tinted_spec_r0.4", makeBsdfParams(c, 0.2f, 0.4f, 0.8f, vec3(0.2f, 1.0f, 2.0f), 2.0f), 60.0f},
    };
}

// Mitsuba-style goodness of fit of bsdfSample against bsdfPdf on a (theta, phi) histogram of
// the upper hemisphere. Two extra cells make the test sensitive to normalisation as well:
// Dirac samples (expected n * P(mirror lobe)) and failed samples (expected n minus
// everything else, i.e. VNDF directions reflected below the horizon).
gdpt::stats::Chi2Result bsdfChi2(const Config& cfg, std::uint32_t seed) {
    const int n = 500000;
    vec3 wo = dirFromTheta(cfg.thetaODeg, 30.0f);
    DirHistogram hist(24, 48, kPiD / 2);
    Uniform rnd(seed);
    double dirac = 0.0;
    double failed = 0.0;
    for (int i = 0; i < n; ++i) {
        BsdfSample s;
        if (!bsdfSample(cfg.m, wo, rnd.next3(), s)) {
            failed += 1.0;
        } else if (s.lobe == kLobeSpecular) {
            dirac += 1.0;
        } else {
            EXPECT_TRUE(hist.add(s.wi));
        }
    }
    std::vector<double> obs = hist.counts;
    std::vector<double> expd = hist.expected([&](vec3 wi) { return bsdfPdf(cfg.m, wo, wi); }, n);
    double sum = 0.0;
    for (double e : expd) {
        sum += e;
    }
    double diracExp = bsdfHasDelta(cfg.m) ? n * double(glossySelectProb(cfg.m, wo)) : 0.0;
    obs.push_back(dirac);
    expd.push_back(diracExp);
    obs.push_back(failed);
    // Integration error (~1e-6 relative) can make the remainder slightly negative.
    expd.push_back(std::max(0.0, n - sum - diracExp));
    return gdpt::stats::chi2Test(obs, expd);
}

TEST(Bsdf, SamplingMatchesPdfChi2) {
    std::uint32_t seed = 100u;
    for (const Config& cfg : chi2Configs()) {
        auto r = bsdfChi2(cfg, seed++);
        EXPECT_TRUE(r.error.empty()) << cfg.name << ": " << r.error;
        EXPECT_GT(r.pValue, gdpt::test::chi2Alpha())
            << cfg.name << ": chi2=" << r.statistic << " dof=" << r.dof << " p=" << r.pValue;
    }
}

// The chi-square test must be able to fail: a pdf that ignores the lobe-selection
// probability (glossy lobe only) does not describe a mixture's samples.
TEST(Bsdf, Chi2DetectsWrongPdf) {
    Config cfg{"wrong", makeBsdfParams(vec3(0.8f), 0.0f, 0.4f, 1.0f, vec3(1.0f), 1.5f), 30.0f};
    BsdfParams diffuseOnly = makeBsdfParams(vec3(0.8f), 0.0f, 0.4f, 0.0f, vec3(1.0f), 1.5f);
    vec3 wo = dirFromTheta(30.0f, 30.0f);
    DirHistogram hist(24, 48, kPiD / 2);
    Uniform rnd(7u);
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
        BsdfSample s;
        if (bsdfSample(cfg.m, wo, rnd.next3(), s)) {
            hist.add(s.wi);
        }
    }
    auto r = gdpt::stats::chi2Test(
        hist.counts, hist.expected([&](vec3 wi) { return bsdfPdf(diffuseOnly, wo, wi); }, n, 4));
    EXPECT_LT(r.pValue, 1e-10);
}

TEST(Bsdf, WeightIsEvalOverPdf) {
    Uniform rnd(11u);
    for (const Config& cfg : chi2Configs()) {
        vec3 wo = dirFromTheta(cfg.thetaODeg, 30.0f);
        for (int i = 0; i < 20000; ++i) {
            BsdfSample s;
            if (!bsdfSample(cfg.m, wo, rnd.next3(), s)) {
                ASSERT_EQ(s.weight, vec3(0.0f)) << cfg.name;
                continue;
            }
            ASSERT_GT(s.wi.z, 0.0f) << cfg.name;
            ASSERT_NEAR(length(s.wi), 1.0f, 1e-5f) << cfg.name;
            if (s.lobe == kLobeSpecular) {
                vec3 expected = glossyFresnel(cfg.m, wo.z) / glossySelectProb(cfg.m, wo);
                ASSERT_NEAR(length(s.weight - expected), 0.0f, 1e-6f) << cfg.name;
                ASSERT_NEAR(length(s.wi - vec3(-wo.x, -wo.y, wo.z)), 0.0f, 1e-6f);
                continue;
            }
            float pdf = bsdfPdf(cfg.m, wo, s.wi);
            vec3 f = bsdfEval(cfg.m, wo, s.wi);
            ASSERT_NEAR(s.pdf, pdf, 1e-5f * pdf) << cfg.name;
            for (int c = 0; c < 3; ++c) {
                ASSERT_NEAR(s.weight[c], f[c] / pdf, 1e-5f * (f[c] / pdf) + 1e-7f) << cfg.name;
            }
        }
    }
}

// Integral of bsdfPdf over the hemisphere by the cell Simpson rule of DirHistogram: exactly
// 1 when only the diffuse lobe exists; at most 1 otherwise (VNDF loses the mass it reflects
// below the horizon). The adaptive quadrature is accurate to ~1e-4, tolerance 1e-3.
TEST(Bsdf, PdfIntegratesToAtMostOne) {
    DirHistogram grid(48, 48, kPiD / 2);
    for (const Config& cfg : chi2Configs()) {
        vec3 wo = dirFromTheta(cfg.thetaODeg, 30.0f);
        // Counts for 1e6 samples so the refinement criterion (0.01 counts) means 1e-8.
        auto cells = grid.expected([&](vec3 wi) { return bsdfPdf(cfg.m, wo, wi); }, 1e6);
        double total = 0.0;
        for (double c : cells) {
            total += c * 1e-6;
        }
        double dirac = bsdfHasDelta(cfg.m) ? double(glossySelectProb(cfg.m, wo)) : 0.0;
        EXPECT_LE(total + dirac, 1.0 + 1e-3) << cfg.name;
        if (cfg.m.metallic == 0.0f && cfg.m.specular == 0.0f) {
            EXPECT_NEAR(total, 1.0, 1e-3) << cfg.name;
        }
        if (cfg.m.alpha > 0.0f) {
            EXPECT_GT(total, 0.5) << cfg.name;
        }
    }
}

// White furnace: albedo(wo) = E[weight] must not exceed 1 for a white base colour at any wo.
// Accept mean <= 1 + 4 standard errors (standard error estimated from the sample variance).
TEST(Bsdf, WhiteFurnaceAlbedoAtMostOne) {
    Uniform rnd(21u);
    const float roughness[] = {0.0f, 0.1f, 0.3f, 0.6f, 1.0f};
    const float metallic[] = {0.0f, 0.5f, 1.0f};
    for (float r : roughness) {
        for (float mt : metallic) {
            BsdfParams m = makeBsdfParams(vec3(1.0f), mt, r, 1.0f, vec3(1.0f), 1.5f);
            for (float thetaO : {0.0f, 30.0f, 60.0f, 80.0f, 89.0f}) {
                vec3 wo = dirFromTheta(thetaO);
                gdpt::stats::RunningStats st[3];
                for (int i = 0; i < 20000; ++i) {
                    BsdfSample s;
                    bool ok = bsdfSample(m, wo, rnd.next3(), s);
                    for (int c = 0; c < 3; ++c) {
                        st[c].add(ok ? double(s.weight[c]) : 0.0);
                    }
                }
                for (int c = 0; c < 3; ++c) {
                    EXPECT_LE(st[c].mean, 1.0 + 4.0 * st[c].standardError() + 1e-6)
                        << "roughness " << r << " metallic " << mt << " theta_o " << thetaO;
                    // Sanity lower bound away from grazing only. Single-scattering GGX loses
                    // energy: for alpha = 1 and F = 1 at normal incidence D = 1/pi and
                    // G2 = 2 cos_i / (1 + cos_i), so the albedo is 1 - ln 2 = 0.307; at 89 deg
                    // the Fresnel-coupled diffuse adds little (albedo ~0.15 for metallic 0).
                    if (thetaO <= 60.0f) {
                        EXPECT_GT(st[c].mean, 0.28)
                            << "energy lost: roughness " << r << " metallic " << mt << " theta_o " << thetaO;
                    }
                }
            }
        }
    }
}

// Lambertian albedo is exactly baseColor: cosine sampling has zero variance (weight == c),
// and an independent uniform-hemisphere estimate of the integral of bsdfEval agrees within
// 4 standard errors.
TEST(Bsdf, LambertianFurnaceIsBaseColor) {
    const vec3 c(0.8f, 0.5f, 0.2f);
    BsdfParams m = makeBsdfParams(c, 0.0f, 0.5f, 0.0f, vec3(1.0f), 1.5f);
    Uniform rnd(22u);
    vec3 wo = dirFromTheta(40.0f, 10.0f);
    gdpt::stats::RunningStats st[3];
    for (int i = 0; i < 100000; ++i) {
        BsdfSample s;
        ASSERT_TRUE(bsdfSample(m, wo, rnd.next3(), s));
        ASSERT_EQ(s.lobe, kLobeDiffuse);
        ASSERT_NEAR(length(s.weight - c), 0.0f, 1e-6f);
        vec3 wi = sampleUniformHemisphere(rnd.next2());
        vec3 f = bsdfEval(m, wo, wi) / uniformHemispherePdf();
        for (int k = 0; k < 3; ++k) {
            st[k].add(double(f[k]));
        }
    }
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(st[k].mean, double(c[k]), 4.0 * st[k].standardError());
    }
}

// Analytic check of D and G2: a white metal (F = 1) with alpha = 1 seen from the normal has
// D = 1/pi, Lambda_o = 0, G2 = 2 cos_i / (1 + cos_i), so its albedo is
// (1/2pi) * 2pi * integral_0^1 mu / (1 + mu) dmu = 1 - ln 2. Accept within 4 standard errors.
TEST(Bsdf, RoughMetalAlbedoIsOneMinusLn2) {
    BsdfParams m = makeBsdfParams(vec3(1.0f), 1.0f, 1.0f, 1.0f, vec3(1.0f), 1.5f);
    Uniform rnd(23u);
    gdpt::stats::RunningStats st;
    for (int i = 0; i < 200000; ++i) {
        BsdfSample s;
        bool ok = bsdfSample(m, vec3(0.0f, 0.0f, 1.0f), rnd.next3(), s);
        st.add(ok ? double(s.weight.x) : 0.0);
    }
    EXPECT_NEAR(st.mean, 1.0 - std::log(2.0), 4.0 * st.standardError());
}

TEST(Bsdf, Reciprocity) {
    Uniform rnd(31u);
    for (const Config& cfg : chi2Configs()) {
        for (int i = 0; i < 5000; ++i) {
            vec3 a = sampleCosineHemisphere(rnd.next2());
            vec3 b = sampleCosineHemisphere(rnd.next2());
            if (a.z < 1e-3f || b.z < 1e-3f) {
                continue;
            }
            vec3 fab = bsdfEval(cfg.m, a, b) / b.z;
            vec3 fba = bsdfEval(cfg.m, b, a) / a.z;
            for (int c = 0; c < 3; ++c) {
                ASSERT_NEAR(fab[c], fba[c], 1e-4f * std::max(fab[c], 1.0f)) << cfg.name;
            }
        }
    }
}

TEST(Bsdf, SpecularZeroIsExactlyLambertian) {
    const vec3 c(0.3f, 0.6f, 0.9f);
    Uniform rnd(41u);
    for (float r : {0.0f, 0.5f, 1.0f}) {
        BsdfParams m = makeBsdfParams(c, 0.0f, r, 0.0f, vec3(1.0f), 1.5f);
        EXPECT_FALSE(bsdfHasDelta(m));
        EXPECT_FALSE(bsdfIsDeltaOnly(m));
        for (int i = 0; i < 2000; ++i) {
            vec3 wo = sampleCosineHemisphere(rnd.next2());
            vec3 wi = sampleCosineHemisphere(rnd.next2());
            if (wo.z <= 0.0f || wi.z <= 0.0f) {
                continue;
            }
            vec3 f = bsdfEval(m, wo, wi);
            for (int k = 0; k < 3; ++k) {
                ASSERT_EQ(f[k], c[k] * (kInvPi * wi.z));
            }
            ASSERT_EQ(bsdfPdf(m, wo, wi), wi.z * kInvPi);
        }
    }
}

TEST(Bsdf, BelowSurfaceAndNaN) {
    BsdfParams m = makeBsdfParams(vec3(0.5f), 0.5f, 0.4f, 1.0f, vec3(1.0f), 1.5f);
    vec3 up = dirFromTheta(30.0f);
    vec3 down = vec3(up.x, up.y, -up.z);
    vec3 nan = vec3(NAN, 0.0f, 1.0f);
    EXPECT_EQ(bsdfEval(m, down, up), vec3(0.0f));
    EXPECT_EQ(bsdfEval(m, up, down), vec3(0.0f));
    EXPECT_EQ(bsdfPdf(m, down, up), 0.0f);
    EXPECT_EQ(bsdfPdf(m, up, down), 0.0f);
    EXPECT_EQ(bsdfEval(m, nan, up), vec3(0.0f));
    EXPECT_EQ(bsdfPdf(m, up, nan), 0.0f);
    BsdfSample s;
    EXPECT_FALSE(bsdfSample(m, down, vec3(0.3f, 0.4f, 0.5f), s));
    EXPECT_EQ(s.weight, vec3(0.0f));
    EXPECT_FALSE(bsdfSample(m, nan, vec3(0.3f, 0.4f, 0.5f), s));
    // Grazing wo and extreme random numbers never produce non-finite weights.
    Uniform rnd(51u);
    for (float r : {0.01f, 0.02f, 0.5f, 1.0f}) {
        BsdfParams g = makeBsdfParams(vec3(0.9f), 0.5f, r, 1.0f, vec3(1.0f), 1.5f);
        for (float cosO : {1e-7f, 1e-4f, 1.0f}) {
            vec3 wo = vec3(safeSqrt(1.0f - cosO * cosO), 0.0f, cosO);
            for (int i = 0; i < 2000; ++i) {
                vec3 u = i < 8 ? vec3(i & 1 ? kOneMinusEpsilon : 0.0f, i & 2 ? kOneMinusEpsilon : 0.0f,
                                      i & 4 ? kOneMinusEpsilon : 0.0f)
                               : rnd.next3();
                if (bsdfSample(g, wo, u, s)) {
                    ASSERT_TRUE(isFinite(s.weight)) << r << " " << cosO;
                    ASSERT_TRUE(s.pdf > 0.0f);
                }
            }
        }
    }
}

TEST(Bsdf, DeltaFlagsAndShiftRoughness) {
    BsdfParams mirror = makeBsdfParams(vec3(0.9f), 1.0f, 0.0f, 1.0f, vec3(1.0f), 1.5f);
    BsdfParams coated = makeBsdfParams(vec3(0.9f), 0.0f, 0.005f, 1.0f, vec3(1.0f), 1.5f);
    BsdfParams glossy = makeBsdfParams(vec3(0.9f), 0.0f, 0.3f, 1.0f, vec3(1.0f), 1.5f);
    EXPECT_TRUE(bsdfHasDelta(mirror));
    EXPECT_TRUE(bsdfIsDeltaOnly(mirror));
    EXPECT_TRUE(bsdfHasDelta(coated));  // roughness 0.005 -> alpha 2.5e-5 < kDeltaAlpha
    EXPECT_FALSE(bsdfIsDeltaOnly(coated));
    EXPECT_FALSE(bsdfHasDelta(glossy));
    EXPECT_EQ(bsdfRoughnessForShift(glossy, kLobeDiffuse), 1.0f);
    EXPECT_NEAR(bsdfRoughnessForShift(glossy, kLobeGlossy), 0.3f, 1e-6f);
    EXPECT_EQ(bsdfRoughnessForShift(mirror, kLobeSpecular), 0.0f);
    // A delta-only BSDF has no non-Dirac part and always samples the mirror.
    vec3 wo = dirFromTheta(50.0f, 20.0f);
    EXPECT_EQ(bsdfEval(mirror, wo, vec3(-wo.x, -wo.y, wo.z)), vec3(0.0f));
    BsdfSample s;
    ASSERT_TRUE(bsdfSample(mirror, wo, vec3(0.99f, 0.5f, 0.5f), s));
    EXPECT_EQ(s.lobe, kLobeSpecular);
}

}  // namespace
