// gpt_reconstruction.h — G-PT's final reconstruction when `--recon` is not given, chosen from the
// scene's surfaces.
//
// WL1 (L1 with bounded, box-filtered inverse-variance row weights; docs/reconstruction.md) has the
// lowest relMSE on the scenes whose surfaces are all rough enough to reconnect. Where some vertex
// is glossy (a roughness at or below `--shift-threshold`, or a mirror), paths that reach a light by
// reflection off it are found by BSDF sampling alone, and G-PT's error is their fireflies. There
// WL2 (L2 with unfiltered inverse-variance row weights) all but drops the rows of a pixel whose
// samples met one, and its debiasing (debias.h) puts that pixel's energy back spread over a hat of
// the coarse grid. Measured on the same samples, relMSE of WL2 against WL1 (bench/RESULTS.md,
// "Reconstruction by the scene's surfaces"): the glossy box (a mirror sphere) −13 to −47 % on each
// of thirteen renders of 8 to 128 spp, −50 to −55 % at 128²; a Cornell box with a mirror wall −14 %,
// its small-light variant −76 to −79 %, the open scene with two mirror boxes −37 to −80 %. The
// glossy box with its mirror made rough (no glossy vertex) +25 % (WL1 the better), the Cornell
// box +11 to +20 %.
// The choice reads the scene only: deterministic, before any sample, the same on every run.
// `--recon` overrides it; the other methods keep their own reconstructions.
#pragma once

#include "poisson/poisson_gpu.h"
#include "render/device_scene/features.h"

namespace gdpt {

// The scene's surfaces, as the choice of the reconstruction sees them.
enum class GptSurfaces {
    Rough,   // every vertex reconnects (roughness above the shift threshold)
    Glossy,  // some vertex is glossy (SceneFeatures::hasGlossy)
};

GptSurfaces gptSurfaces(const SceneFeatures& features);
Reconstruction gptDefaultReconstruction(GptSurfaces surfaces);
const char* toString(GptSurfaces surfaces);

}  // namespace gdpt
