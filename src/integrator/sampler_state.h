// sampler_state.h — everything a render needs to continue where another stopped: the
// per-pixel running statistics of every accumulation buffer and the position in the batch
// schedule. The buffers, in the order of the passes' downloadStats():
//   PT:   2 = the path tracer's accumulation, then emitter supersampling's;
//   G-PT: 11 = the ten per-pixel statistics of gpt.comp in binding order (central, four
//         neighbours, four gradients, direct), then emitter supersampling's; 12 with
//         demodulation, whose modulation statistics come last.
// Checkpoints (integrator/checkpoint.h) store it; RenderOptions::resume restores it.
#pragma once

#include <cstdint>
#include <vector>

#include "gdpt_shared.h"
#include "image/image.h"

namespace gdpt {

struct SamplerState {
    std::uint32_t spp = 0;        // samples per pixel merged into the statistics
    std::uint32_t nextBatch = 1;  // spp of the next batch in the schedule (1, 2, 4, ... max)
    std::uint32_t batches = 0;    // batches run so far
    // Welford mean / M2 / count per pixel, row-major, one vector per statistics buffer.
    std::vector<std::vector<gpu::PixelStats>> buffers;
    // A viewable image of the samples so far (PT: the mean; G-PT: primal + direct, not
    // reconstructed). Not needed to resume.
    Image preview;
};

}  // namespace gdpt
