#include "distributed/mpi_world.h"

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "integrator/stats_merge.h"
#include "util/error.h"
#include "util/interrupt.h"
#include "util/timer.h"

#if GDPT_HAVE_MPI
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace gdpt {
namespace {

bool g_started = false;             // MPI_Init was called
std::unique_ptr<MpiWorld> g_world;  // only for more than one rank

// Whether an MPI launcher started this process: Open MPI, MPICH/Hydra and PMIx set these.
bool launchedByMpi() {
    for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"})
        if (std::getenv(var)) return true;
    return false;
}

}  // namespace

MpiWorld* MpiWorld::get() {
    return g_world.get();
}

void MpiWorld::testFault(const char* phase) const {
    const char* fault = std::getenv("GDPT_TEST_RANK_FAULT");
    if (!fault) return;
    const std::string text = fault;
    const auto colon = text.find(':');
    if (colon == std::string::npos || text.substr(0, colon) != std::to_string(rank_)) return;
    const std::string what = text.substr(colon + 1);
    if (what == phase) throw Error("simulated failure while " + what + " (GDPT_TEST_RANK_FAULT)");
    if (what == "killed" && std::string(phase) == "sampling") std::raise(SIGKILL);
}

#if GDPT_HAVE_MPI

namespace {

using nlohmann::json;

enum Tag : int { kTagAgree = 1, kTagVerdict = 2, kTagHeader = 3, kTagData = 4 };
// Largest single message (MPI counts are int); a statistics buffer goes in pieces of this.
constexpr std::size_t kChunkBytes = std::size_t(1) << 30;

// Waits for `request`, polling the interrupt flag: spins for the first milliseconds (a
// transfer in progress), then naps, so an idle rank costs no core.
void wait(MPI_Request& request, const char* phase) {
    const auto start = std::chrono::steady_clock::now();
    for (;;) {
        int done = 0;
        MPI_Test(&request, &done, MPI_STATUS_IGNORE);
        if (done) return;
        if (interruptRequested()) throw Interrupted(phase);
        if (std::chrono::steady_clock::now() - start > std::chrono::milliseconds(5))
            std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
}

void sendText(const std::string& text, int dest, int tag, const char* phase) {
    MPI_Request request;
    MPI_Isend(text.data(), static_cast<int>(text.size()), MPI_CHAR, dest, tag, MPI_COMM_WORLD, &request);
    wait(request, phase);
}

std::string receiveText(int source, int tag, const char* phase) {
    MPI_Status status;
    int ready = 0;
    for (;;) {
        MPI_Iprobe(source, tag, MPI_COMM_WORLD, &ready, &status);
        if (ready) break;
        if (interruptRequested()) throw Interrupted(phase);
        std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    int count = 0;
    MPI_Get_count(&status, MPI_CHAR, &count);
    std::string text(static_cast<std::size_t>(count), '\0');
    MPI_Recv(text.data(), count, MPI_CHAR, source, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    return text;
}

void sendBytes(const void* data, std::size_t bytes, int dest, const char* phase) {
    const auto* p = static_cast<const char*>(data);
    for (std::size_t done = 0; done < bytes; done += kChunkBytes) {
        const int n = static_cast<int>(std::min(kChunkBytes, bytes - done));
        MPI_Request request;
        MPI_Isend(p + done, n, MPI_BYTE, dest, kTagData, MPI_COMM_WORLD, &request);
        wait(request, phase);
    }
}

void receiveBytes(void* data, std::size_t bytes, int source, const char* phase) {
    auto* p = static_cast<char*>(data);
    for (std::size_t done = 0; done < bytes; done += kChunkBytes) {
        const int n = static_cast<int>(std::min(kChunkBytes, bytes - done));
        MPI_Request request;
        MPI_Irecv(p + done, n, MPI_BYTE, source, kTagData, MPI_COMM_WORLD, &request);
        wait(request, phase);
    }
}

json descriptionJson(const ExrAttributes& description) {
    json j = json::object();
    for (const auto& [key, value] : description) j[key] = value;
    return j;
}

// The first key in which `other` differs from `root`, as "key a (rank 0: b)", or "".
std::string firstDifference(const json& root, const json& other) {
    for (const auto& [key, value] : root.items())
        if (!other.contains(key) || other[key] != value)
            return key + " " + (other.contains(key) ? other[key].get<std::string>() : "(none)") +
                   " (rank 0: " + value.get<std::string>() + ")";
    for (const auto& [key, value] : other.items())
        if (!root.contains(key)) return key + " " + value.get<std::string>() + " (rank 0: none)";
    return "";
}

}  // namespace

void MpiWorld::start(int* argc, char*** argv) {
    if (g_started || !launchedByMpi()) return;
    int provided = 0;
    // Only the main thread calls MPI (the pipeline-creation workers never do).
    MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
    g_started = true;
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (size > 1) g_world.reset(new MpiWorld(rank, size));
}

int MpiWorld::finish(int exitCode) {
    if (!g_started) return exitCode;
    if (g_world && g_world->root() && exitCode != 0 && g_world->phase_ == Phase::Agreed) {
        // The other ranks may be sampling or waiting to send: end the whole job.
        std::fflush(stderr);
        MPI_Abort(MPI_COMM_WORLD, exitCode);
    }
    MPI_Finalize();
    g_started = false;
    return exitCode;
}

void MpiWorld::agree(const ExrAttributes& description, const std::string& failure, double* timeBudget) {
    const char* phase = "waiting for the other ranks";
    const json mine = {{"failure", failure}, {"description", descriptionJson(description)}};
    if (!root()) {
        sendText(mine.dump(), 0, kTagAgree, phase);
        const json verdict = json::parse(receiveText(0, kTagVerdict, phase));
        if (!verdict.at("go").get<bool>()) {
            phase_ = Phase::Refused;
            throw ReportedElsewhere(verdict.at("message").get<std::string>());
        }
        if (timeBudget) *timeBudget = verdict.at("time_budget").get<double>();
        phase_ = Phase::Agreed;
        return;
    }
    std::string message;
    if (!failure.empty()) message = "rank 0 failed before sampling: " + failure;
    for (int r = 1; r < size_; ++r) {
        const json other = json::parse(receiveText(r, kTagAgree, phase));
        if (!message.empty()) continue;  // keep receiving, so that every rank gets the verdict
        const std::string otherFailure = other.at("failure").get<std::string>();
        if (!otherFailure.empty()) {
            message = "rank " + std::to_string(r) + " failed before sampling: " + otherFailure;
        } else if (const std::string d = firstDifference(mine.at("description"), other.at("description"));
                   !d.empty()) {
            message = "rank " + std::to_string(r) + " would render another image than rank 0: " + d;
        }
    }
    const json verdict = {
        {"go", message.empty()}, {"message", message}, {"time_budget", timeBudget ? *timeBudget : 0.0}};
    for (int r = 1; r < size_; ++r) sendText(verdict.dump(), r, kTagVerdict, phase);
    if (!message.empty()) {
        phase_ = Phase::Refused;
        throw Error(message);
    }
    phase_ = Phase::Agreed;
}

void MpiWorld::fail(const std::string& message, bool interrupted) {
    if (phase_ != Phase::Agreed) return;
    if (root()) return;  // finish() aborts the job
    const json header = {{"status", interrupted ? "interrupted" : "failed"}, {"message", message}};
    phase_ = Phase::Combined;
    sendText(header.dump(), 0, kTagHeader, "reporting the failure to rank 0");
}

std::optional<SamplerState> MpiWorld::combine(SamplerState mine, RenderStats& stats) {
    const char* phase = "gathering the statistics of the ranks";
    if (!root()) {
        json sizes = json::array();
        for (const auto& b : mine.buffers) sizes.push_back(b.size());
        const json header = {{"status", stats.cancelled ? "interrupted" : "ok"},
                             {"spp", mine.spp},
                             {"rays_traced", stats.raysTraced},
                             {"paths_completed", stats.pathsCompleted},
                             {"nan_samples", stats.nanSamples},
                             {"shift_pairs", stats.shiftPairs},
                             {"shift_failures", stats.shiftFailures},
                             {"buffers", sizes}};
        phase_ = Phase::Combined;
        sendText(header.dump(), 0, kTagHeader, phase);
        if (!stats.cancelled)
            for (const auto& b : mine.buffers)
                sendBytes(b.data(), b.size() * sizeof(gpu::PixelStats), 0, phase);
        return std::nullopt;
    }
    Timer timer;
    SamplerState merged = std::move(mine);
    DistributedStats& d = stats.distributed;
    d.parts = static_cast<std::uint32_t>(size_);
    d.partSpp = {merged.spp};
    d.bytesPerPart = 0;
    d.waitMs = 0.0;
    for (const auto& b : merged.buffers) d.bytesPerPart += b.size() * sizeof(gpu::PixelStats);
    std::string failure;
    std::string interrupted = stats.cancelled ? "rank 0" : "";
    // Two receive buffers: a worker thread merges one while this thread (the only one that
    // calls MPI) receives the next.
    std::vector<gpu::PixelStats> received[2];
    std::thread merger;
    int slot = 0;
    const auto joinMerger = [&merger] {
        if (merger.joinable()) merger.join();
    };
    struct JoinOnExit {
        const std::function<void()> join;
        ~JoinOnExit() { join(); }
    } joinOnExit{joinMerger};
    for (int r = 1; r < size_; ++r) {
        Timer waiting;  // until rank r has finished sampling
        const json header = json::parse(receiveText(r, kTagHeader, phase));
        d.waitMs += waiting.ms();
        const std::string status = header.at("status").get<std::string>();
        const std::string rank = "rank " + std::to_string(r);
        if (status == "failed") {
            if (failure.empty()) failure = rank + " failed: " + header.at("message").get<std::string>();
            continue;
        }
        if (status == "interrupted") {
            if (interrupted.empty()) interrupted = rank;
            continue;
        }
        const auto sizes = header.at("buffers").get<std::vector<std::size_t>>();
        // The same buffers of the same pixels as rank 0's (checked here: the merge runs on a
        // worker thread, where an error could not be reported).
        std::vector<std::size_t> ours;
        for (const auto& b : merged.buffers) ours.push_back(b.size());
        if (failure.empty() && interrupted.empty() && sizes != ours)
            failure = rank + " sent statistics of another shape (buffers and pixels) than rank 0's";
        const bool merging = failure.empty() && interrupted.empty();
        for (std::size_t k = 0; k < sizes.size(); ++k) {
            std::vector<gpu::PixelStats>& into = received[slot];
            into.resize(sizes[k]);
            receiveBytes(into.data(), sizes[k] * sizeof(gpu::PixelStats), r, phase);
            joinMerger();  // the previous buffer (it used the other slot)
            if (merging)
                merger = std::thread(
                    [&acc = merged.buffers[k], &into] { mergeStatsInto(acc, into.data(), into.size()); });
            slot = 1 - slot;
        }
        const auto spp = header.at("spp").get<std::uint32_t>();
        merged.spp += spp;
        d.partSpp.push_back(spp);
        stats.raysTraced += header.at("rays_traced").get<std::uint64_t>();
        stats.pathsCompleted += header.at("paths_completed").get<std::uint64_t>();
        stats.nanSamples += header.at("nan_samples").get<std::uint64_t>();
        stats.shiftPairs += header.at("shift_pairs").get<std::uint64_t>();
        stats.shiftFailures += header.at("shift_failures").get<std::uint64_t>();
    }
    joinMerger();
    phase_ = Phase::Combined;
    d.mergeMs = timer.ms() - d.waitMs;
    if (!failure.empty()) throw Error(failure);
    if (!interrupted.empty())
        throw Interrupted("sampling", " (" + interrupted + " was interrupted; every rank stops)");
    return merged;
}

#else  // !GDPT_HAVE_MPI

void MpiWorld::start(int*, char***) {
    if (launchedByMpi() && !g_started) {
        g_started = true;
        std::fprintf(stderr,
                     "gdpt: warning: started by an MPI launcher, but this gdpt was built without MPI; every "
                     "process renders the whole image alone (install libopenmpi-dev and rebuild)\n");
    }
}

int MpiWorld::finish(int exitCode) {
    return exitCode;
}

void MpiWorld::agree(const ExrAttributes&, const std::string&, double*) {}

void MpiWorld::fail(const std::string&, bool) {}

std::optional<SamplerState> MpiWorld::combine(SamplerState mine, RenderStats&) {
    return mine;
}

#endif

}  // namespace gdpt
