// mpi_world.h — the processes of `mpirun -n N gdpt render ...` (docs/distributed.md). Rank r
// renders part r/N of the samples (sample_share.h); before sampling the ranks agree that they
// render the same thing; after it, rank 0 gathers every rank's statistics in rank order,
// merges them (stats_merge.h) and finishes the render (reconstruction, outputs) alone.
//
// Failure: every message is point to point and every wait polls the interrupt flag, so a
// rank that fails reports it to rank 0 (which names it and exits 1 with no output), a signal
// (Ctrl-C, or mpirun's SIGTERM when a rank dies) ends every waiting rank promptly, and rank 0
// aborts the job (MPI_Abort) if it fails while the others may still be waiting for it.
//
// Without MPI at build time, or when not started by an MPI launcher, there is no world
// (MpiWorld::get() is null) and gdpt runs as one process.
#pragma once

#include <optional>
#include <string>

#include "image/exr_io.h"
#include "integrator/render_options.h"
#include "integrator/sampler_state.h"

namespace gdpt {

class MpiWorld {
public:
    // Starts MPI when this process was started by an MPI launcher (Open MPI, MPICH or PMIx
    // environment) and gdpt was built with MPI. Call once, first thing in main.
    static void start(int* argc, char*** argv);
    // The world of more than one rank, or null.
    static MpiWorld* get();
    // Ends MPI (MPI_Finalize; MPI_Abort with `exitCode` when rank 0 failed after the ranks
    // agreed, since the others may be waiting for it). Returns exitCode. Call last in main.
    static int finish(int exitCode);

    [[nodiscard]] int rank() const { return rank_; }
    [[nodiscard]] int size() const { return size_; }
    [[nodiscard]] bool root() const { return rank_ == 0; }
    // Whether agree() has run (whatever its verdict).
    [[nodiscard]] bool agreed() const { return phase_ != Phase::Start; }
    [[nodiscard]] SampleShare share() const {
        return {static_cast<std::uint32_t>(rank_), static_cast<std::uint32_t>(size_)};
    }

    // Before sampling, on every rank: `description` is what this rank will render (the
    // render's identity, spp or time), `failure` its error so far ("" if none). Returns if
    // every rank is ready and describes the same render as rank 0; else throws gdpt::Error on
    // every rank, naming the first rank that failed (and why) or differs (and in what).
    // `timeBudget`, if given, becomes rank 0's on every rank (a timed render's sampling budget,
    // so that all ranks stop sampling together).
    void agree(const ExrAttributes& description, const std::string& failure, double* timeBudget = nullptr);

    // RenderOptions::combine of a rank: sends this rank's statistics and counters to rank 0
    // (returns nothing), or on rank 0 receives every other rank's in rank order, merges them
    // into its own and returns the merge (adding their counters to `stats`). Throws on rank 0
    // if a rank failed or was interrupted (after receiving what the others sent, so every
    // rank ends cleanly).
    std::optional<SamplerState> combine(SamplerState mine, RenderStats& stats);

    // A rank that fails after agree() and before combine() tells rank 0, which reports it at
    // its combine (rank 0 itself failing then ends the job in finish()).
    void fail(const std::string& message, bool interrupted);

    // For tests of the failure handling: if the environment variable GDPT_TEST_RANK_FAULT is
    // "R:PHASE" and this is rank R, at `phase` ("loading" or "sampling", its end) this rank
    // throws an error, or with "R:killed" it kills itself (SIGKILL) at the end of sampling,
    // as a crashed node would.
    void testFault(const char* phase) const;

private:
    MpiWorld(int rank, int size) : rank_(rank), size_(size) {}
    enum class Phase { Start, Refused, Agreed, Combined };
    int rank_ = 0;
    int size_ = 1;
    Phase phase_ = Phase::Start;
};

}  // namespace gdpt
