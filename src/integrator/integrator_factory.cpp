// integrator_factory.cpp — the one place method names are parsed.
#include <string>

#include "integrator/gpt_integrator.h"
#include "integrator/integrator.h"
#include "integrator/mlt_integrator.h"
#include "integrator/pt_integrator.h"
#include "integrator/tgpt_integrator.h"
#include "util/error.h"

namespace gdpt {

const std::vector<std::string>& methodNames() {
    static const std::vector<std::string> names = {"pt", "gpt", "pssmlt", "gmlt", "tgpt"};
    return names;
}

const std::vector<std::string>& methodVariantNames() {
    static const std::vector<std::string> names = {"pt",      "gpt",    "gpt-l1", "gpt-l2", "gpt-wl1",
                                                   "gpt-wl2", "pssmlt", "gmlt",   "tgpt"};
    return names;
}

std::unique_ptr<Integrator> makeIntegrator(const std::string& name, const MethodOptions& options) {
    if (name == "pt") return std::make_unique<PtIntegrator>();
    if (name == "gpt") return std::make_unique<GptIntegrator>(name, options.gpt);
    if (name == "pssmlt" || name == "gmlt") return std::make_unique<MltIntegrator>(name, options.mlt);
    if (name == "tgpt") return std::make_unique<TgptIntegrator>(options.tgpt);
    const std::string prefix = "gpt-";
    if (name.compare(0, prefix.size(), prefix) == 0) {
        GptOptions gpt = options.gpt;
        gpt.reconstructionByScene = false;
        try {
            gpt.reconstructions = {parseReconstruction(name.substr(prefix.size()))};
        } catch (const UsageError&) {
            gpt.reconstructions.clear();
        }
        if (!gpt.reconstructions.empty()) return std::make_unique<GptIntegrator>(name, gpt);
    }
    std::string known;
    for (const std::string& n : methodVariantNames()) known += (known.empty() ? "" : ", ") + n;
    throw UsageError("unknown method '" + name + "' (" + known + ")");
}

std::vector<RenderOutput> Integrator::renderWindow(const vk::Context& ctx, const FrameWindow& window,
                                                   const RenderOptions& options) {
    (void)ctx, (void)window, (void)options;
    throw Error("--method " + name() + " renders one image at a time, not windows of frames");
}

}  // namespace gdpt
