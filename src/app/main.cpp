// main.cpp — gdpt entry point: parses the command line (CLI11) and runs the chosen
// subcommand. Exit codes: 0 success, 1 runtime or input error (one clear line on stderr),
// 2 usage error, 130 interrupted (SIGINT or SIGTERM; no output written).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include "app/subcommand.h"
#include "distributed/mpi_world.h"
#include "util/address_space_limit.h"
#include "util/error.h"
#include "util/interrupt.h"

namespace {

int run(int argc, char** argv) {
    using namespace gdpt;
    CLI::App app{"gdpt — headless gradient-domain path tracer (GLSL compute over Vulkan; lavapipe first)"};
    app.require_subcommand(1);
    app.set_help_all_flag("--help-all", "Print help for all subcommands");

    const std::vector<Subcommand> commands = {
        addRenderCommand(app),       addDiffCommand(app),          addDiffSequenceCommand(app),
        addInfoCommand(app),         addDevicesCommand(app),       addBenchCommand(app),
        addConvergeCommand(app),     addSolveCommand(app),         addCloneCommand(app),
        addBenchPoissonCommand(app), addBenchFeaturesCommand(app), addMergeCommand(app),
        addBenchMergeCommand(app),
    };

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    } catch (const Error& e) {  // an input the options name is missing or unreadable (InputFile)
        std::fprintf(stderr, "gdpt: error: %s\n", e.what());
        return 1;
    }
    try {
        for (const Subcommand& c : commands) {
            if (!*c.app) continue;
            // Under mpirun only these commands split their work; any other would run N times.
            const std::string name = c.app->get_name();
            if (MpiWorld::get() && name != "render" && name != "bench-merge")
                throw UsageError("gdpt " + name +
                                 " does not split across MPI ranks; run it without mpirun (only "
                                 "render and bench-merge do)");
            return c.run();
        }
    } catch (const ReportedElsewhere&) {  // rank 0 of an MPI render reports it
        return 1;
    } catch (const UsageError& e) {
        std::fprintf(stderr, "gdpt: usage error: %s\n", e.what());
        return 2;
    } catch (const Interrupted& e) {  // SIGINT or SIGTERM (util/interrupt.h)
        std::fprintf(stderr, "gdpt: %s\n", e.what());
        return 130;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "gdpt: error: %s\n", hostAllocationFailure(addressSpaceLimit()).c_str());
        return 1;
    } catch (const std::exception& e) {
        // A signal that ended a phase through a layer that re-wrapped the error.
        if (interruptRequested()) {
            std::fprintf(stderr, "gdpt: interrupted; no output written (%s)\n", e.what());
            return 130;
        }
        std::fprintf(stderr, "gdpt: error: %s\n", e.what());
        return 1;
    }
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    // Before any thread: under `ulimit -v`, one malloc arena (util/address_space_limit.h).
    gdpt::fitMallocToAddressSpaceLimit();
    // Under mpirun, every rank runs the same command (distributed/mpi_world.h).
    gdpt::MpiWorld::start(&argc, &argv);
    return gdpt::MpiWorld::finish(run(argc, argv));
}
