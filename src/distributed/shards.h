// shards.h — a render split into shards run as independent jobs (render-farm managers, batch
// schedulers: `gdpt render SCENE --shard I/N -o shard_I.exr`), and their merge (`gdpt merge`;
// docs/distributed.md).
//
// A shard file is a checkpoint (integrator/checkpoint.h) of part I/N of the render
// (sample_share.h): its identity records the part ("share" = "I/N") besides everything that
// identifies the render, and its information records what the merge needs to finish the
// render as the shards' command line asked: the render's spp ("render_spp"; 0 for --time),
// its settings ("render_args", JSON) and the scene file ("scene_path", absolute).
#pragma once

#include <string>
#include <vector>

#include "image/exr_io.h"
#include "integrator/render_options.h"
#include "integrator/sample_share.h"
#include "integrator/sampler_state.h"

namespace gdpt {

struct MergedShards {
    ExrAttributes identity;  // the render's, without the part
    ExrAttributes info;      // part 0's
    SamplerState state;      // the statistics of every part, merged in part order
    DistributedStats stats;  // parts, their spp, bytes per part, merge time
};

// Reads the shard files, checks that they are the parts 0..N-1 of one render, each once and
// each complete (an --spp render's part has exactly its share of the samples), and merges
// them in part order, whatever the order of `paths`. Throws gdpt::Error naming the file that
// is not a shard, belongs to another render (and in what it differs), repeats a part, or
// has the wrong samples, or the parts that are missing.
MergedShards mergeShards(const std::vector<std::string>& paths);

}  // namespace gdpt
