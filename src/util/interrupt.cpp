// interrupt.cpp — the process-wide interrupt flag and its signal handlers.
#include "util/interrupt.h"

#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>

namespace gdpt {
namespace {

std::atomic<bool> gInterrupted{false};

// removeOnSignal's registry: fixed storage, so that the handler reads it without allocating.
constexpr int kSlots = 32;
constexpr std::size_t kPathBytes = 4096;
char gRemovePaths[kSlots][kPathBytes];
std::atomic<int> gRemoveState[kSlots];  // 0 free, 1 being written, 2 registered

void removeRegistered() {
    for (int i = 0; i < kSlots; ++i)
        if (gRemoveState[i].load(std::memory_order_acquire) == 2) ::unlink(gRemovePaths[i]);
}

extern "C" void onInterruptSignal(int) {
    // A second signal: the user insists; stop now (async-signal-safe calls only).
    if (gInterrupted.exchange(true)) _exit(130);
    removeRegistered();  // unlink is async-signal-safe
}

}  // namespace

void installInterruptHandlers() {
    struct sigaction action {};
    action.sa_handler = onInterruptSignal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
    std::signal(SIGXFSZ, SIG_IGN);
}

int removeOnSignal(const std::string& path) {
    if (path.empty() || path.size() >= kPathBytes) return -1;
    for (int i = 0; i < kSlots; ++i) {
        int expected = 0;
        if (!gRemoveState[i].compare_exchange_strong(expected, 1, std::memory_order_acq_rel)) continue;
        std::memcpy(gRemovePaths[i], path.c_str(), path.size() + 1);
        gRemoveState[i].store(2, std::memory_order_release);
        return i;
    }
    return -1;
}

void keepOnSignal(int slot) {
    if (slot >= 0 && slot < kSlots) gRemoveState[slot].store(0, std::memory_order_release);
}

const std::atomic<bool>& interruptFlag() {
    return gInterrupted;
}

void throwIfInterrupted(const char* phase) {
    if (interruptRequested()) throw Interrupted(phase);
}

void enterPhase(const char* phase) {
    const char* at = std::getenv("GDPT_TEST_SIGNAL_AT");
    if (!at) return;
    const std::string want(at);
    const std::size_t colon = want.find(':');
    const std::string target = want.substr(0, colon);
    const std::size_t hash = target.find('#');
    if (target.substr(0, hash) != phase) return;
    // Starts of the phase so far (phases are entered from the main thread only).
    static std::map<std::string, int> starts;
    const int nth = hash == std::string::npos ? 1 : std::atoi(target.c_str() + hash + 1);
    if (++starts[phase] != nth) return;
    const bool term = colon != std::string::npos && want.substr(colon + 1) == "TERM";
    std::raise(term ? SIGTERM : SIGINT);
}

}  // namespace gdpt
