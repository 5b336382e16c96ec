#include "integrator/gpt_alpha.h"

namespace gdpt {

GptLighting gptLighting(const SceneFeatures& features) {
    if (!features.hasEnv)
        return features.hasEmissiveEnclosure ? GptLighting::EmissiveSky : GptLighting::Emitters;
    return features.hasLightTris || features.hasPunctual ? GptLighting::EnvironmentAndEmitters
                                                         : GptLighting::Environment;
}

double gptDefaultAlpha(GptLighting lighting) {
    switch (lighting) {
        case GptLighting::Environment:
            return kGptAlphaEnvironment;
        case GptLighting::EnvironmentAndEmitters:
            return kGptAlphaEnvironmentAndEmitters;
        case GptLighting::EmissiveSky:
            return kGptAlphaEmissiveSky;
        case GptLighting::Emitters:
            break;
    }
    return kGptAlphaEmitters;
}

const char* toString(GptLighting lighting) {
    switch (lighting) {
        case GptLighting::Environment:
            return "environment";
        case GptLighting::EnvironmentAndEmitters:
            return "environment and emitters";
        case GptLighting::EmissiveSky:
            return "emissive sky";
        case GptLighting::Emitters:
            break;
    }
    return "emitters";
}

}  // namespace gdpt
