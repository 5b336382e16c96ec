// subcommand.h — how a gdpt subcommand plugs into main(): a factory adds its options to the
// CLI11 app and returns the function that runs it (returning the exit code). Each
// subcommand lives in its own file; main.cpp lists the factories.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

#include "app/input_file.h"

namespace gdpt {

struct Subcommand {
    CLI::App* app = nullptr;
    std::function<int()> run;
};

Subcommand addRenderCommand(CLI::App& app);
Subcommand addDiffCommand(CLI::App& app);
Subcommand addDiffSequenceCommand(CLI::App& app);
Subcommand addInfoCommand(CLI::App& app);
Subcommand addDevicesCommand(CLI::App& app);
Subcommand addBenchCommand(CLI::App& app);
Subcommand addConvergeCommand(CLI::App& app);
Subcommand addSolveCommand(CLI::App& app);
Subcommand addCloneCommand(CLI::App& app);
Subcommand addBenchPoissonCommand(CLI::App& app);
Subcommand addBenchFeaturesCommand(CLI::App& app);
Subcommand addMergeCommand(CLI::App& app);
Subcommand addBenchMergeCommand(CLI::App& app);

}  // namespace gdpt
