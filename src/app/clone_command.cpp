// clone_command.cpp — `gdpt clone`: seamless cloning (Pérez et al. 2003) of a masked source
// region into a target image with the GPU Poisson solver (src/poisson/poisson_clone.h).
// Inputs: PNG/JPEG (sRGB, linearised) or EXR; output PNG (sRGB preview) or EXR by extension.
#include <cstdio>
#include <memory>
#include <sstream>

#include "app/subcommand.h"
#include "image/exr_io.h"
#include "image/finite_check.h"
#include "image/png_preview.h"
#include "poisson/poisson_clone.h"
#include "util/error.h"
#include "util/output_files.h"
#include "vk/context.h"

namespace gdpt {
namespace {

struct CloneArgs {
    std::string source, target, mask, offset = "0,0", output;
    bool mixed = false;
    double tolerance = 1e-5;
    std::string device;
    bool quiet = false;
};

bool endsWith(const std::string& s, const std::string& suffix) {
    if (s.size() < suffix.size()) return false;
    std::string tail = s.substr(s.size() - suffix.size());
    for (char& ch : tail) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    return tail == suffix;
}

int runClone(const CloneArgs& a) {
    int ox = 0, oy = 0;
    char sep = 0;
    std::istringstream in(a.offset);
    if (!(in >> ox >> sep >> oy) || sep != ',' || !in.eof())
        throw UsageError("--offset '" + a.offset + "' must be X,Y (integers)");
    const bool png = endsWith(a.output, ".png");
    if (!png && !endsWith(a.output, ".exr")) throw UsageError("-o must end in .png or .exr");
    OutputSet outputs({{"--source", a.source}, {"--target", a.target}, {"--mask", a.mask}});
    const StagedFile& outFile = outputs.add(a.output, "-o");
    const Image source = readImage(a.source);
    const Image target = readImage(a.target);
    const Image mask = readImage(a.mask);
    // Invalid values, found up front and named with their file (poisson_clone.h says what the
    // clone does with them): a target must be finite; a source's NaN/Inf pixels give no
    // guidance; a mask's select nothing.
    if (const PixelScan bad = scanNonFinite(target); bad.any())
        throw Error(a.target + ": NaN or infinite values in " + bad.describe() +
                    "; the target is copied into the result, so it cannot be cloned into");
    if (const PixelScan bad = scanNonFinite(source); bad.any() && !a.quiet)
        std::fprintf(stderr,
                     "gdpt: warning: %s: NaN or infinite values in %s; the gradients that touch them are "
                     "replaced by the target's\n",
                     a.source.c_str(), bad.describe().c_str());
    if (const PixelScan bad = scanNonFinite(mask); bad.any() && !a.quiet)
        std::fprintf(stderr,
                     "gdpt: warning: %s: NaN or infinite values in %s; those pixels are not selected\n",
                     a.mask.c_str(), bad.describe().c_str());
    vk::ContextOptions co;
    co.device = a.device;
    vk::Context ctx(co);
    CloneOptions o;
    o.offsetX = ox;
    o.offsetY = oy;
    o.mixed = a.mixed;
    o.tolerance = a.tolerance;
    SolveReport report;
    Image result;
    try {
        result = seamlessClone(ctx, source, target, mask, o, &report);
    } catch (const Error& e) {
        throw e.withContext(a.source + " -> " + a.target);
    }
    checkFinite({{"", result}}, a.output);  // the last guard before writing
    if (png)
        writePngPreview(outFile, result);
    else
        writeExr(outFile, {{"", result}});
    outputs.commit();
    if (!a.quiet)
        std::fprintf(stderr, "gdpt: wrote %s (%d iterations, residual %.3g, %.1f ms)\n", a.output.c_str(),
                     report.iterations, report.residual, report.ms);
    return 0;
}

}  // namespace

Subcommand addCloneCommand(CLI::App& app) {
    auto a = std::make_shared<CloneArgs>();
    CLI::App* sub =
        app.add_subcommand("clone", "Seamless cloning (Perez et al. 2003) of a masked source into a target");
    sub->add_option("--source", a->source, "Source image (PNG/JPEG/EXR)")->required()->check(InputFile);
    sub->add_option("--target", a->target, "Target image (PNG/JPEG/EXR)")->required()->check(InputFile);
    sub->add_option("--mask", a->mask, "Mask, source-sized; red > 0.5 selects")->required()->check(InputFile);
    sub->add_option("--offset", a->offset, "Target position X,Y of the source's top-left pixel")
        ->capture_default_str();
    sub->add_flag("--mixed", a->mixed, "Mixed gradients: keep the stronger of source and target gradient");
    sub->add_option("--tolerance", a->tolerance, "Relative residual tolerance")
        ->check(CLI::Range(1e-12, 0.5))
        ->capture_default_str();
    sub->add_option("-o,--output", a->output, "Output .png (sRGB) or .exr")->required();
    sub->add_option("--device", a->device, "Vulkan device index or name substring");
    sub->add_flag("--quiet", a->quiet, "No summary on stderr");
    return {sub, [a] { return runClone(*a); }};
}

}  // namespace gdpt
