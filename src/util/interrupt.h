// interrupt.h — SIGINT/SIGTERM handling shared by every phase of a command. The first signal
// sets a flag that loading, BVH building, sampling, reconstruction and writing poll (each
// stops within a batch or a solver cycle); the command then exits 130 and writes nothing (a
// render with --checkpoint keeps its checkpoint). A second signal ends the process at once.
#pragma once

#include <atomic>
#include <string>

#include "util/error.h"

namespace gdpt {

// Thrown by throwIfInterrupted; main() prints its message and exits 130.
class Interrupted : public Error {
public:
    // `phase`: what was stopped, as in "interrupted while <phase>"; `note` is appended.
    explicit Interrupted(const std::string& phase, const std::string& note = "")
        : Error("interrupted while " + phase + "; no output written" + note), phase_(phase) {}
    [[nodiscard]] const std::string& phase() const { return phase_; }

private:
    std::string phase_;
};

// Installs the handlers for SIGINT and SIGTERM (idempotent), and ignores SIGXFSZ so that a
// file-size limit makes a write fail with an error instead of killing the process.
void installInterruptHandlers();

// The flag the handlers set; long loops poll it (relaxed loads are enough).
[[nodiscard]] const std::atomic<bool>& interruptFlag();
[[nodiscard]] inline bool interruptRequested() {
    return interruptFlag().load(std::memory_order_relaxed);
}

// Files the first signal removes at once, from the handler (the staged temporary files of a
// command's outputs, util/output_files.h): a signal always means "no output", and a process
// that is sent SIGTERM and then, moments later, SIGKILL (mpirun, batch schedulers) then leaves
// none behind. Returns a slot for keepOnSignal, or -1 if the path was not registered (more
// than 32 at once, or a path longer than 4095 bytes).
int removeOnSignal(const std::string& path);
// The file of `slot` is no longer removed by a signal (it was committed or discarded).
void keepOnSignal(int slot);

// Throws Interrupted ("interrupted while <phase>; no output written") if a signal arrived.
void throwIfInterrupted(const char* phase);

// Marks the start of a phase of a command ("loading", "sampling", "reconstruction",
// "writing"). For tests of the handling of each phase: if the environment variable
// GDPT_TEST_SIGNAL_AT names this phase (optionally "#N": its Nth start, e.g. the second
// frame's sampling of a sequence; optionally ":TERM"), the process sends itself SIGINT (or
// SIGTERM) here, exactly as a user's Ctrl-C at that moment would.
void enterPhase(const char* phase);

}  // namespace gdpt
