// spirv_words.h — the instructions of a SPIR-V module, for tests that read what a kernel's
// module holds (its SpecId decorations, its loops' controls).
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace gdpt::test {

// Calls visit(opcode, instruction, count) for each instruction after the five-word header:
// `instruction` points at its first word (word count and opcode) and holds `count` words. An
// instruction of zero words or one that runs past the end fails the test and ends the walk.
template <class Visit>
void forEachSpirvInstruction(const std::vector<std::uint32_t>& words, Visit visit) {
    for (std::size_t i = 5; i < words.size();) {
        const std::uint32_t count = words[i] >> 16;
        if (count == 0 || i + count > words.size()) {
            ADD_FAILURE() << "malformed SPIR-V instruction at word " << i;
            return;
        }
        visit(words[i] & 0xFFFFu, &words[i], count);
        i += count;
    }
}

}  // namespace gdpt::test
