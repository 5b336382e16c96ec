// memory.h — the machine's memory, and byte counts as people read them, for the checks that
// refuse work too large for the machine before it starts (the glTF loader, tgpt's windows).
#pragma once

#include <cstdint>
#include <string>

namespace gdpt {

// The machine's physical memory in bytes (0 if unknown). The tests of the refusals set it with
// the environment variable GDPT_TEST_MEMORY_BYTES (a byte count), as if the machine had that much.
[[nodiscard]] std::uint64_t physicalMemory();

// "1.5 GiB": bytes in gibibytes with one decimal.
[[nodiscard]] std::string gibibytes(std::uint64_t bytes);
// gibibytes from 1 GiB up, "37 MiB" below, "12 KiB" below 1 MiB, "512 bytes" below 1 KiB.
[[nodiscard]] std::string memoryText(std::uint64_t bytes);

}  // namespace gdpt
