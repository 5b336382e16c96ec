// bounded_child.h — runs a piece of code in a forked child whose address space may grow by
// only a given headroom (RLIMIT_AS) and whose wall time is bounded, so that a test can show
// that hostile input is refused cheaply: a loader that allocates before it checks fails with
// bad_alloc (or a crash) there instead of succeeding slowly, and a crash (e.g. a stack
// overflow) fails the test instead of the test binary.
#pragma once

#include <poll.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdint>
#include <fstream>
#include <functional>
#include <string>

namespace gdpt::test {

struct ChildResult {
    bool exited = false;  // exited normally (no signal, not killed at the timeout)
    int signal = 0;       // the signal that ended it, if any
    bool timedOut = false;
    std::string output;  // what `run` returned
    double seconds = 0.0;
};

// The current virtual memory size of this process in bytes (VmSize in /proc/self/status).
inline std::uint64_t virtualMemoryBytes() {
    std::ifstream status("/proc/self/status");
    std::string key;
    while (status >> key) {
        if (key == "VmSize:") {
            std::uint64_t kib = 0;
            status >> kib;
            return kib * 1024;
        }
        status.ignore(1 << 20, '\n');
    }
    return 0;
}

// Runs `run` in a child that may map `headroomBytes` more than the parent has mapped now,
// for at most `timeoutSeconds`; returns its result string and how it ended.
inline ChildResult runBounded(const std::function<std::string()>& run, std::uint64_t headroomBytes,
                              double timeoutSeconds) {
    ChildResult result;
    int fds[2];
    if (pipe(fds) != 0) return result;
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = fork();
    if (pid == 0) {
        close(fds[0]);
        const rlimit limit{virtualMemoryBytes() + headroomBytes, virtualMemoryBytes() + headroomBytes};
        setrlimit(RLIMIT_AS, &limit);
        std::string out;
        try {
            out = run();
        } catch (...) {
            out = "unexpected exception";
        }
        for (std::size_t done = 0; done < out.size();) {
            const ssize_t n = write(fds[1], out.data() + done, out.size() - done);
            if (n <= 0) break;
            done += static_cast<std::size_t>(n);
        }
        _exit(0);
    }
    close(fds[1]);
    const auto deadline = start + std::chrono::duration<double>(timeoutSeconds);
    char buffer[4096];
    for (;;) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
            deadline - std::chrono::steady_clock::now());
        if (left.count() <= 0) {
            result.timedOut = true;
            kill(pid, SIGKILL);
            break;
        }
        pollfd p{fds[0], POLLIN, 0};
        if (poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
        const ssize_t n = read(fds[0], buffer, sizeof buffer);
        if (n <= 0) break;  // the child closed the pipe: it has finished
        result.output.append(buffer, static_cast<std::size_t>(n));
    }
    close(fds[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.exited = !result.timedOut && WIFEXITED(status);
    result.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
    return result;
}

}  // namespace gdpt::test
