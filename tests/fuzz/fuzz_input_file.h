// fuzz_input_file.h — the file a fuzz harness hands each input to a reader through: one per
// process (named after its id, so parallel fuzzers do not share it), removed when the process
// exits normally (a crash leaves it, holding the input that crashed).
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

namespace gdpt::fuzz {

class InputFile {
public:
    InputFile(const std::string& stem, const std::string& extension)
        : path_("/tmp/" + stem + "_" + std::to_string(::getpid()) + extension) {}
    ~InputFile() { std::remove(path_.c_str()); }
    InputFile(const InputFile&) = delete;
    InputFile& operator=(const InputFile&) = delete;

    // Writes the input; false if the file cannot be written.
    bool write(const std::uint8_t* data, std::size_t size) const {
        FILE* f = std::fopen(path_.c_str(), "wb");
        if (!f) return false;
        const bool ok = std::fwrite(data, 1, size, f) == size;
        return std::fclose(f) == 0 && ok;
    }
    [[nodiscard]] const std::string& path() const { return path_; }

private:
    std::string path_;
};

}  // namespace gdpt::fuzz
