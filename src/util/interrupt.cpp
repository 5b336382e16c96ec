// interrupt.cpp — the process-wide interrupt flag and its signal handlers.
#include "util/interrupt.h"

#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <cstring>
#include <string>

namespace gdpt {
namespace {

std::atomic<bool> gInterrupted{false};

extern "C" void onInterruptSignal(int) {
    // A second signal: the user insists; stop now (async-signal-safe calls only).
    if (gInterrupted.exchange(true)) _exit(130);
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
    if (want.substr(0, colon) != phase) return;
    const bool term = colon != std::string::npos && want.substr(colon + 1) == "TERM";
    std::raise(term ? SIGTERM : SIGINT);
}

}  // namespace gdpt
