// error.h — gdpt's error types. User-facing failures throw gdpt::Error with a message that
// already names the file/element; layers add context with Error::withContext as the error
// passes outwards. main() prints the message on one line and exits 1 (2 for usage errors).
#pragma once

#include <stdexcept>
#include <string>

namespace gdpt {

class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
    // Returns a copy of this error with "context: " prepended to the message.
    [[nodiscard]] Error withContext(const std::string& context) const {
        return Error(context + ": " + what());
    }
};

// Bad command-line usage (exit code 2).
class UsageError : public Error {
public:
    using Error::Error;
};

// An error that another process reports (rank 0 of an MPI render names the rank that
// failed): main() exits 1 without printing it again.
class ReportedElsewhere : public Error {
public:
    using Error::Error;
};

}  // namespace gdpt

// GDPT_CHECK: a cheap invariant, checked in every build. Throws gdpt::Error with the
// expression, file and line (the message is for developers; it means a bug in gdpt).
#define GDPT_CHECK(cond)                                                                                   \
    do {                                                                                                   \
        if (!(cond))                                                                                       \
            throw ::gdpt::Error(std::string("internal check failed: ") + #cond + " at " + __FILE__ + ":" + \
                                std::to_string(__LINE__));                                                 \
    } while (0)

#define GDPT_CHECK_OP(a, op, b)                                                                      \
    do {                                                                                             \
        const auto gdptA_ = (a);                                                                     \
        const auto gdptB_ = (b);                                                                     \
        if (!(gdptA_ op gdptB_))                                                                     \
            throw ::gdpt::Error(std::string("internal check failed: ") + #a " " #op " " #b + " (" +  \
                                std::to_string(gdptA_) + " vs " + std::to_string(gdptB_) + ") at " + \
                                __FILE__ + ":" + std::to_string(__LINE__));                          \
    } while (0)
