#include "integrator/gpt_reconstruction.h"

namespace gdpt {

GptSurfaces gptSurfaces(const SceneFeatures& features) {
    return features.hasGlossy ? GptSurfaces::Glossy : GptSurfaces::Rough;
}

Reconstruction gptDefaultReconstruction(GptSurfaces surfaces) {
    return surfaces == GptSurfaces::Glossy ? Reconstruction::WeightedL2 : Reconstruction::WeightedL1;
}

const char* toString(GptSurfaces surfaces) {
    return surfaces == GptSurfaces::Glossy ? "glossy vertices" : "rough";
}

}  // namespace gdpt
