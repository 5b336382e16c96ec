// commands.h — the subcommands of the gdpt program. Each returns the process exit code.
#pragma once

#include "app/cli.h"

namespace gdpt {

int runRender(const RenderArgs& args);
int runDiff(const DiffArgs& args);
int runInfo(const InfoArgs& args);
int runDevices(const DevicesArgs& args);

}  // namespace gdpt
