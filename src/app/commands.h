// commands.h — the subcommands of the gdpt program. Each returns the process exit code.
#pragma once

#include <string>

#include "app/cli.h"

namespace gdpt {

struct MergedShards;

int runRender(const RenderArgs& args);
// The render of `args` continued from shards' merged statistics (gdpt merge), or a plain one.
int runRender(const RenderArgs& args, const MergedShards* merged);
// The frames args.frames of an animation (gdpt render --frames; runRender calls it).
int runSequence(const RenderArgs& args);
// A render's settings as a shard records them (gdpt.info.render_args), and back; `where`
// names the file in errors.
std::string renderArgsJson(const RenderArgs& args);
RenderArgs renderArgsFromJson(const std::string& text, const std::string& where);
int runDiff(const DiffArgs& args);
int runInfo(const InfoArgs& args);
int runDiffSequence(const DiffSequenceArgs& args);
int runDevices(const DevicesArgs& args);

}  // namespace gdpt
