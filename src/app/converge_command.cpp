// converge_command.cpp — `gdpt converge`: run time against error. Renders a scene with each
// method at each time budget (independent seeds per repeat), measures relMSE (Kettunen et
// al.'s definition, as `gdpt diff`), MSE and mean bias against a reference, and writes
// DIR/results.json, DIR/results.csv, DIR/error_vs_time.png (gnuplot, log-log, median with
// min/max bars over repeats), an equal-time table and the time each method needs to reach a
// target relMSE. The time counted is everything the user waits for after the scene file is
// parsed: BVH build, upload, sampling and (G-PT) reconstruction.
#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/bench_util.h"
#include "app/cli.h"
#include "app/edge_samples_option.h"
#include "app/subcommand.h"
#include "image/atomic_write.h"
#include "image/exr_io.h"
#include "image/finite_check.h"
#include "image/metrics.h"
#include "integrator/integrator.h"
#include "integrator/pt_sampler.h"
#include "poisson/debias.h"
#include "scene/gltf_loader.h"
#include "scene/light_sources.h"
#include "util/error.h"
#include "util/interrupt.h"
#include "util/output_files.h"
#include "util/timer.h"
#include "vk/context.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct ConvergeArgs {
    std::string scene;
    std::string reference;
    std::string methods = "pt,gpt,gpt-l1";  // gpt: the render default (gpt-wl1)
    std::string times = "1,2,4,8";
    int repeats = 3;
    int width = 256;
    int height = 256;
    std::uint32_t makeReference = 0;
    double target = 0.0;
    std::string output = "converge";
    std::string device;
    bool validate = false;
    std::uint32_t emitterSupersampling = kDefaultEmitterSupersampling;
    std::string edgeSamples = "auto";
    std::string demodulate = "auto";
    int debiasCells = kDefaultDebiasCells;
    std::string env = "0,0,0";    // --env as given
    glm::vec3 envRadiance{0.0f};  // ... parsed (runConverge)
};

// FNV-1a of the scene file's bytes and the render settings: the cache key of a made reference.
// A black environment leaves the key of the references made before --env existed.
std::string referenceKey(const std::string& scenePath, int w, int h, std::uint32_t spp, glm::vec3 env) {
    std::ifstream in(scenePath, std::ios::binary);
    std::uint64_t hash = 1469598103934665603ull;
    char c = 0;
    while (in.get(c)) hash = (hash ^ static_cast<unsigned char>(c)) * 1099511628211ull;
    for (std::uint64_t v : {std::uint64_t(w), std::uint64_t(h), std::uint64_t(spp)})
        hash = (hash ^ v) * 1099511628211ull;
    if (env != glm::vec3(0.0f))
        for (int k = 0; k < 3; ++k) {
            std::uint32_t bits = 0;
            std::memcpy(&bits, &env[k], sizeof bits);
            hash = (hash ^ bits) * 1099511628211ull;
        }
    char buf[32];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(hash));
    return buf;
}

struct Run {
    std::string method;
    double budget = 0.0;
    int repeat = 0;
    double seconds = 0.0;  // measured total
    double reconSeconds = 0.0;
    std::uint32_t spp = 0;
    std::uint32_t partialPassRows = 0;  // rows with one sample more (the partial last pass)
    ImageErrorStats error;
};

// One integrator per method, kept across runs (the G-PT solver compiles its pipelines once,
// as in a long-running application; that one-time compilation is excluded from the timings,
// like scene parsing).
class Converger {
public:
    Converger(const vk::Context& ctx, const Scene& scene, const ConvergeArgs& a)
        : ctx_(ctx), scene_(scene), a_(a) {}

    // Renders `method` within `budget` seconds with seed `seed`.
    Run run(const std::string& method, double budget, std::uint32_t seed, const Image& reference) {
        Run r;
        r.method = method;
        r.budget = budget;
        Integrator& integrator = integratorFor(method);
        RenderOptions o = options();
        o.seed = seed;
        // The time the method needs after sampling (G-PT: the reconstruction) is measured
        // before the clock starts: it is calibration, not part of the run. Sampling gets the
        // rest.
        const double reserve = integrator.reserveAfterSampling(ctx_, a_.width, a_.height).seconds;
        o.timeBudget = std::max(0.05 * budget, budget - reserve);
        Timer total;
        const RenderOutput out = integrator.render(ctx_, scene_, o);
        throwIfInterrupted("converging");
        r.seconds = total.seconds();
        r.reconSeconds = out.stats.reconstructionMs * 1e-3;
        r.spp = out.stats.spp;
        r.partialPassRows = out.stats.partialPassRows;
        r.error = compareImages(out.image(), reference);
        return r;
    }

    // One untimed 1-spp render of `method`: lavapipe compiles a pipeline at its first
    // dispatch (later processes hit Mesa's shader cache), which would otherwise land in the
    // first budget's sampling time (measured: a cold G-PT render at 13 k instead of
    // 117 k samples/s).
    // A throwaway integrator, so that this render's reconstruction (its first, the slowest)
    // is not the longest the kept one reserves for.
    void warmUp(const std::string& method) {
        RenderOptions o = options();
        o.spp = 1;
        (void)makeIntegrator(method, methodOptions())->render(ctx_, scene_, o);
        throwIfInterrupted("converging");
    }

private:
    RenderOptions options() const {
        RenderOptions o;
        o.scene.width = a_.width;
        o.scene.height = a_.height;
        o.scene.envRadiance = a_.envRadiance;
        o.quiet = true;
        o.emitterSupersampling = a_.emitterSupersampling;
        o.cancel = &interruptFlag();
        return o;
    }

    Integrator& integratorFor(const std::string& method) {
        auto it = integrators_.find(method);
        if (it != integrators_.end()) return *it->second;
        return *(integrators_[method] = makeIntegrator(method, methodOptions()));
    }

    MethodOptions methodOptions() const {
        MethodOptions m;
        m.gpt.sampling.edgeSamples = parseEdgeSamples(a_.edgeSamples, "--edge-samples");
        m.gpt.sampling.demodulate = parseDemodulation(a_.demodulate);
        m.gpt.debiasCells = a_.debiasCells;
        return m;
    }

    const vk::Context& ctx_;
    const Scene& scene_;
    const ConvergeArgs& a_;
    std::map<std::string, std::unique_ptr<Integrator>> integrators_;
};

// The files converge writes into its output directory, staged before the first render.
struct ConvergeOutputs {
    OutputSet set;
    const StagedFile* json = nullptr;
    const StagedFile* csv = nullptr;
    const StagedFile* dat = nullptr;
    const StagedFile* gp = nullptr;
    std::unique_ptr<StagedFile> png;  // committed only if gnuplot draws it
};

// Writes the plot's data and gnuplot script, and draws the PNG into its staged file.
// Returns false (with a warning) if gnuplot is missing or draws nothing.
bool writePlot(const ConvergeOutputs& out, const std::vector<std::string>& methods, const json& summary) {
    std::ostringstream dat;
    for (std::size_t m = 0; m < methods.size(); ++m) {
        dat << "# " << methods[m] << "\n";
        for (const auto& s : summary)
            if (s["method"] == methods[m])
                dat << s["seconds_median"].get<double>() << " " << s["relmse_median"].get<double>() << " "
                    << s["relmse_min"].get<double>() << " " << s["relmse_max"].get<double>() << "\n";
        dat << "\n\n";
    }
    writeStagedText(*out.dat, dat.str());
    // The script names the final paths (it is kept for re-plotting); gnuplot is run on a
    // copy that reads the staged data and draws into the staged PNG.
    const auto script = [&](const std::string& datPath, const std::string& pngPath) {
        std::ostringstream gp;
        gp << "set terminal pngcairo size 900,600 noenhanced\n"
           << "set output '" << pngPath << "'\n"
           << "set logscale xy\nset xlabel 'time (s)'\nset ylabel 'relMSE'\nset grid\nset key top right\n"
           << "plot ";
        for (std::size_t m = 0; m < methods.size(); ++m)
            gp << (m ? ", " : "") << "'" << datPath << "' index " << m << " with yerrorlines title '"
               << methods[m] << "'";
        gp << "\n";
        return gp.str();
    };
    const std::string kept = script(out.dat->path(), out.png->path());
    writeStagedText(*out.gp, kept);
    const std::string now = script(out.dat->tmpPath(), out.png->tmpPath());
    bool drawn = false;
    // Without gnuplot the pipe has no reader: a write error, not a SIGPIPE that ends gdpt.
    const auto previousPipe = std::signal(SIGPIPE, SIG_IGN);
    if (FILE* gnuplot = popen("gnuplot 2>/dev/null", "w")) {
        const bool sent = std::fputs(now.c_str(), gnuplot) >= 0;
        drawn = pclose(gnuplot) == 0 && sent;
    }
    std::signal(SIGPIPE, previousPipe);
    std::error_code sizeError;
    drawn = drawn && fs::file_size(out.png->tmpPath(), sizeError) > 0 && !sizeError;
    if (!drawn)
        std::fprintf(stderr, "gdpt converge: warning: gnuplot drew no plot; the plot data is in %s\n",
                     out.dat->path().c_str());
    return drawn;
}

// Refuses a reference that cannot measure an error: no pixel finite in every channel (the
// metrics leave such pixels out, metrics.h), e.g. all NaN.
void checkReference(const Image& reference, const std::string& name) {
    if (scanNonFinite(reference).all())
        throw Error(name + ": the reference has no finite pixel value: no error can be measured");
}

// Time at which the median relMSE of `method` first reaches `target`, interpolated in
// log-log between measured budgets; -1 if never.
double timeToReach(const json& summary, const std::string& method, double target) {
    double prevT = 0, prevE = 0;
    bool have = false;
    for (const auto& s : summary) {
        if (s["method"] != method) continue;
        const double t = s["seconds_median"], e = s["relmse_median"];
        if (e <= target) {
            if (!have) return t;
            const double f = (std::log(target) - std::log(prevE)) / (std::log(e) - std::log(prevE));
            return std::exp(std::log(prevT) + f * (std::log(t) - std::log(prevT)));
        }
        prevT = t;
        prevE = e;
        have = true;
    }
    return -1.0;
}

// The methods and budgets of the command line, checked before any work (a usage error never
// waits for a scene or a reference).
std::pair<std::vector<std::string>, std::vector<double>> methodsAndTimes(const ConvergeArgs& a) {
    const auto methods = splitList(a.methods);
    if (methods.empty()) throw UsageError("--methods: no method given");
    for (const std::string& m : methods)  // unknown names, and methods of sequences, fail before any render
        if (makeIntegrator(m)->windowFrames() > 0)
            throw UsageError("--methods " + m + ": converge renders single images; " + m +
                             " renders sequences (scripts/bench-temporal.sh compares it)");
    std::vector<double> times;
    for (const auto& t : splitList(a.times)) {
        try {
            times.push_back(std::stod(t));
        } catch (const std::exception&) {
            throw UsageError("--times: '" + t + "' is not a number");
        }
        if (!(times.back() > 0.0)) throw UsageError("--times: budgets must be positive");
    }
    if (times.empty()) throw UsageError("--times: no time budget given");
    if (a.reference.empty() && a.makeReference == 0)
        throw UsageError("give --reference REF.exr or --make-reference SPP");
    return {methods, times};
}

// The reference image: --reference's, or a PT render of --make-reference spp, cached in the
// output directory `dir` by scene, size, spp and sky. `name` gets its file's name.
Image convergeReference(const ConvergeArgs& a, const fs::path& dir, const vk::Context& ctx,
                        const Scene& scene, std::string& name) {
    Image reference;
    name = a.reference;
    if (!a.reference.empty()) {
        reference = readExrLayer(a.reference);
    } else {
        const fs::path cached =
            dir / ("reference_" + referenceKey(a.scene, a.width, a.height, a.makeReference, a.envRadiance) +
                   ".exr");
        name = cached.string();
        if (fs::exists(cached)) {
            reference = readExrLayer(cached.string());
        } else {
            std::fprintf(stderr, "gdpt converge: rendering a %u spp PT reference (cached as %s)\n",
                         a.makeReference, cached.c_str());
            RenderOptions o;
            o.scene.width = a.width;
            o.scene.height = a.height;
            o.scene.envRadiance = a.envRadiance;
            o.spp = a.makeReference;
            o.seed = 0xC0FFEEu;
            o.cancel = &interruptFlag();
            const RenderResult made = renderPt(ctx, scene, o);
            throwIfInterrupted("rendering the reference");
            reference = made.image;
            writeExr(cached.string(), reference);
        }
    }
    if (reference.width() != a.width || reference.height() != a.height)
        throw Error(name + ": reference is " + std::to_string(reference.width()) + "x" +
                    std::to_string(reference.height()) + ", the render is " + std::to_string(a.width) + "x" +
                    std::to_string(a.height) + " (use --width/--height)");
    checkReference(reference, name);
    return reference;
}

// Every method at every budget, --repeats times each (seeds 1, 2, ... in that order): the runs
// into `runs`, and per method and budget the medians (the summary's rows).
json runAll(Converger& conv, const ConvergeArgs& a, const std::vector<std::string>& methods,
            const std::vector<double>& times, const Image& reference, std::vector<Run>& runs) {
    json summary = json::array();
    std::uint32_t seed = 1;
    for (const auto& m : methods) conv.warmUp(m);
    for (const auto& m : methods)
        for (double t : times) {
            std::vector<double> rel, sec, mse, bias;
            std::vector<double> spp;
            for (int k = 0; k < a.repeats; ++k) {
                Run r = conv.run(m, t, seed++, reference);
                std::fprintf(stderr, "gdpt converge: %-8s budget %6.2fs  took %6.2fs  %5u spp  relMSE %.5g\n",
                             m.c_str(), t, r.seconds, r.spp, r.error.relMse);
                rel.push_back(r.error.relMse);
                sec.push_back(r.seconds);
                mse.push_back(r.error.mse);
                bias.push_back(r.error.meanBias);
                spp.push_back(r.spp);
                runs.push_back(r);
            }
            summary.push_back({{"method", m},
                               {"budget_s", t},
                               {"seconds_median", median(sec)},
                               {"spp_median", median(spp)},
                               {"relmse_median", median(rel)},
                               {"relmse_min", *std::min_element(rel.begin(), rel.end())},
                               {"relmse_max", *std::max_element(rel.begin(), rel.end())},
                               {"mse_median", median(mse)},
                               {"bias_median", median(bias)}});
        }
    return summary;
}

// The equal-time table: per budget each method's median relMSE and, where PT ran, its gain
// over PT.
json equalTimeTable(const json& summary, const std::vector<double>& times) {
    json equalTime = json::array();
    for (double t : times) {
        json row = {{"budget_s", t}};
        double ptErr = 0.0;
        for (const auto& s : summary)
            if (s["budget_s"] == t && s["method"] == "pt") ptErr = s["relmse_median"];
        for (const auto& s : summary)
            if (s["budget_s"] == t) {
                row[s["method"].get<std::string>()] = s["relmse_median"];
                if (ptErr > 0.0 && s["method"] != "pt")
                    row[s["method"].get<std::string>() + "_gain_vs_pt"] =
                        ptErr / s["relmse_median"].get<double>();
            }
        equalTime.push_back(row);
    }
    return equalTime;
}

// Every run as JSON rows, and the same as CSV into `csv`.
json runRows(const std::vector<Run>& runs, int repeats, std::ostringstream& csv) {
    json rows = json::array();
    csv << "method,budget_s,repeat,seconds,recon_seconds,spp,partial_pass_rows,relmse,mse,mae,mean_bias\n";
    for (std::size_t i = 0; i < runs.size(); ++i) {
        const Run& r = runs[i];
        const int repeat = static_cast<int>(i % static_cast<std::size_t>(repeats));
        rows.push_back({{"method", r.method},
                        {"budget_s", r.budget},
                        {"repeat", repeat},
                        {"seconds", r.seconds},
                        {"recon_seconds", r.reconSeconds},
                        {"spp", r.spp},
                        {"partial_pass_rows", r.partialPassRows},
                        {"relmse", r.error.relMse},
                        {"mse", r.error.mse},
                        {"mae", r.error.mae},
                        {"mean_bias", r.error.meanBias}});
        csv << r.method << "," << r.budget << "," << repeat << "," << r.seconds << "," << r.reconSeconds
            << "," << r.spp << "," << r.partialPassRows << "," << r.error.relMse << "," << r.error.mse << ","
            << r.error.mae << "," << r.error.meanBias << "\n";
    }
    return rows;
}

// The equal-time table and the times to the target on stdout.
void printTables(const std::vector<std::string>& methods, const json& equalTime, const json& reach,
                 double target, const fs::path& dir, bool plotted) {
    std::printf("%-10s", "budget(s)");
    for (const auto& m : methods) std::printf(" %12s", m.c_str());
    std::printf("\n");
    for (const auto& row : equalTime) {
        std::printf("%-10g", row["budget_s"].get<double>());
        for (const auto& m : methods) std::printf(" %12.5g", row.value(m, 0.0));
        std::printf("\n");
    }
    std::printf("time to relMSE %.4g:", target);
    for (const auto& m : methods) std::printf("  %s %.3gs", m.c_str(), reach[m].get<double>());
    std::printf("\nwrote %s/results.json, results.csv, error_vs_time.dat, error_vs_time.gp%s\n", dir.c_str(),
                plotted ? ", error_vs_time.png" : "");
}

int runConverge(const ConvergeArgs& a) {
    const auto [methods, times] = methodsAndTimes(a);

    installInterruptHandlers();
    const fs::path dir(a.output);
    std::error_code dirError;
    fs::create_directories(dir, dirError);
    if (dirError) throw Error(a.output + ": cannot create the output directory: " + dirError.message());
    ConvergeOutputs out{OutputSet({{"scene", a.scene}, {"--reference", a.reference}})};
    out.json = &out.set.add((dir / "results.json").string(), "results");
    out.csv = &out.set.add((dir / "results.csv").string(), "results table");
    out.dat = &out.set.add((dir / "error_vs_time.dat").string(), "plot data");
    out.gp = &out.set.add((dir / "error_vs_time.gp").string(), "plot script");
    out.png = std::make_unique<StagedFile>((dir / "error_vs_time.png").string());

    const Scene scene = loadGltf(a.scene);
    throwIfInterrupted("loading");
    if (const auto black = blackImageWarning(scene, a.envRadiance))
        std::fprintf(stderr, "gdpt: warning: %s\n", black->c_str());
    vk::ContextOptions co;
    co.device = a.device;
    co.validation = a.validate;
    vk::Context ctx(co);

    std::string referenceName;
    const Image reference = convergeReference(a, dir, ctx, scene, referenceName);
    Converger conv(ctx, scene, a);
    std::vector<Run> runs;
    const json summary = runAll(conv, a, methods, times, reference, runs);

    // Equal-time table (ratio to PT where PT was run) and time to reach the target.
    double target = a.target;
    if (!(target > 0.0)) {
        // Default target: PT's median error at its largest budget (or the first method's).
        for (const auto& s : summary)
            if (s["method"] == methods.front() && s["budget_s"] == times.back()) target = s["relmse_median"];
    }
    const json equalTime = equalTimeTable(summary, times);
    json reach = json::object();
    for (const auto& m : methods) reach[m] = timeToReach(summary, m, target);
    std::ostringstream csv;
    const json runsJson = runRows(runs, a.repeats, csv);
    const json results = {{"schema", "gdpt-converge-1"},
                          {"scene", a.scene},
                          {"reference", a.reference.empty() ? "(made)" : a.reference},
                          {"width", a.width},
                          {"height", a.height},
                          {"env", {a.envRadiance.x, a.envRadiance.y, a.envRadiance.z}},
                          {"repeats", a.repeats},
                          {"device", ctx.info().name},
                          {"methods", methods},
                          {"times", times},
                          {"runs", runsJson},
                          {"summary", summary},
                          {"equal_time", equalTime},
                          {"target_relmse", target},
                          {"time_to_target_s", reach}};
    // Staged files, moved into place together: an interrupted or failed run leaves no
    // truncated table and no table without its plot data.
    const std::string resultsText = results.dump(2) + "\n";
    writeStagedText(*out.json, resultsText);
    writeStagedText(*out.csv, csv.str());
    const bool plotted = writePlot(out, methods, summary);
    throwIfInterrupted("writing");
    out.set.commit();
    if (plotted) out.png->commit();
    printTables(methods, equalTime, reach, target, dir, plotted);
    if (ctx.validationErrors() > 0) {
        std::fprintf(stderr, "gdpt converge: error: %u Vulkan validation error(s)\n", ctx.validationErrors());
        return 1;
    }
    return 0;
}

}  // namespace

Subcommand addConvergeCommand(CLI::App& app) {
    auto a = std::make_shared<ConvergeArgs>();
    CLI::App* c =
        app.add_subcommand("converge", "Error against time: each method at each time budget vs a reference");
    c->add_option("scene", a->scene, "glTF 2.0 scene")->required()->check(InputFile);
    c->add_option("--reference", a->reference, "Converged reference EXR (same size and camera)")
        ->check(InputFile);
    c->add_option("--make-reference", a->makeReference,
                  "Render a PT reference with this many spp (cached by scene hash)");
    c->add_option(
         "--methods", a->methods,
         "Methods: pt, gpt (= gpt-wl1, the render default), gpt-l1, gpt-l2, gpt-wl2, gpt-wl1, pssmlt, gmlt")
        ->capture_default_str();
    c->add_option("--times", a->times, "Time budgets in seconds (comma-separated)")->capture_default_str();
    c->add_option("--repeats", a->repeats, "Independent repeats per budget (median reported)")
        ->capture_default_str()
        ->check(CLI::Range(1, 100));
    c->add_option("--emitter-supersampling", a->emitterSupersampling,
                  "Rays per camera sample at the edges of directly visible emission, every method "
                  "(as gdpt render; 0 = off)")
        ->capture_default_str()
        ->check(CLI::Range(0u, kMaxEmitterSupersampling));
    c->add_option("--edge-samples", a->edgeSamples, std::string("(as gdpt render) ") + kEdgeSamplesHelp)
        ->capture_default_str()
        ->check(edgeSamplesValidator());
    c->add_option("--demodulate", a->demodulate,
                  "G-PT methods: first-hit texture demodulation (as gdpt render: auto, on, off)")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "on", "off"}));
    c->add_option("--debias-cells", a->debiasCells,
                  std::string("G-PT methods (as gdpt render): ") + kDebiasCellsHelp)
        ->capture_default_str()
        ->check(CLI::Range(0, kMaxDebiasCells));
    c->add_option("--env", a->env,
                  "(as gdpt render) Constant environment radiance R,G,B (or one value for grey), in the "
                  "runs and in the --make-reference render")
        ->capture_default_str();
    c->add_option("--width", a->width, "Image width")->capture_default_str()->check(CLI::Range(1, 16384));
    c->add_option("--height", a->height, "Image height")->capture_default_str()->check(CLI::Range(1, 16384));
    c->add_option("--target", a->target,
                  "relMSE for the time-to-reach figure (default: the first method's error at "
                  "the largest budget)");
    c->add_option("-o,--output", a->output, "Output directory")->capture_default_str();
    c->add_option("--device", a->device, "Vulkan device index or name substring");
    c->add_flag("--validate", a->validate, "Enable Vulkan validation layers (errors make the run fail)");
    return {c, [a] {
                a->envRadiance = parseColor(a->env, "--env");
                return runConverge(*a);
            }};
}

}  // namespace gdpt
