// checkpoint.h — render checkpoints: one EXR that is both a viewable image of the samples so
// far and the state a later run needs to continue them (`gdpt render --checkpoint F`,
// `--resume F`).
//
// Layout (gdpt-checkpoint-1):
//   - default channels R,G,B: SamplerState::preview (PT: the running mean; G-PT: primal +
//     direct, not reconstructed), so any EXR viewer and `gdpt diff` can read the file;
//   - layers state<k>.mean, state<k>.m2, state<k>.count for statistics buffer k (PT: k = 0, 1;
//     G-PT: 0..10, or 0..11 with demodulation; order in sampler_state.h): the Welford
//     running mean and M2 per channel and the sample count (the same integer in R, G and
//     B). FLOAT channels hold the float32 values bit for bit, and counts are integers
//     <= 2^24, exact in float32;
//   - string attributes gdpt.format, gdpt.spp, gdpt.next_batch, gdpt.batches, gdpt.buffers
//     (the schedule position), gdpt.id.<key> (the identity of the render: a resume must match
//     every one) and gdpt.info.<key> (informational, e.g. the device).
#pragma once

#include <string>

#include "image/exr_io.h"
#include "integrator/sampler_state.h"

namespace gdpt {

class StagedFile;

struct Checkpoint {
    ExrAttributes identity;  // key -> value, without the "gdpt.id." prefix
    ExrAttributes info;      // key -> value, without the "gdpt.info." prefix
    SamplerState state;
};

// Writes `state` (via path.tmp + rename). Throws gdpt::Error naming the file.
void writeCheckpoint(const std::string& path, const ExrAttributes& identity, const ExrAttributes& info,
                     const SamplerState& state);

// The same into a staged file of an OutputSet (util/output_files.h); the caller commits.
void writeCheckpoint(const StagedFile& file, const ExrAttributes& identity, const ExrAttributes& info,
                     const SamplerState& state);

// Reads and validates a checkpoint: format, attributes, the statistics buffers of its method
// (gdpt.id.method) with every layer present, sample counts consistent with gdpt.spp (path
// statistics: spp in every pixel, spp x (1 + edge_samples) in G-PT's edge pixels, the same in
// every path statistic of a pixel; emitter supersampling's: 0 or spp), means finite, M2
// finite and >= 0. Throws gdpt::Error naming the file, the layer and the first bad pixel.
Checkpoint readCheckpoint(const std::string& path);

// Throws gdpt::Error naming `path` and the first identity key whose recorded value differs
// from (or is missing in) `expected`.
void checkIdentity(const std::string& path, const ExrAttributes& recorded, const ExrAttributes& expected);

}  // namespace gdpt
