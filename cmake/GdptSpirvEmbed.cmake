# Script mode (cmake -P), run by gdpt_add_shaders for each kernel:
#   GLSLANG, SPIRV_OPT (empty: no optimisation), SRC, OUT (the .spv.h), NAME (array name),
#   FLAGS (|-separated extra glslangValidator flags: -D..., -I..., -g)
# 1. glslangValidator -V SRC -> OUT.spv, with a depfile OUT.d naming OUT as the target.
# 2. spirv-opt: inlining, scalar replacement and local-variable elimination to SSA, then dead
#    code. The SPIR-V glslang emits keeps every local in memory and every function call;
#    lavapipe's vkCreateComputePipelines spends its time lowering that in NIR, on one core, and
#    at a 4 s budget that time is the render's (bench/RESULTS.md, spirv-opt: gpt_split
#    0.75 s -> 0.40 s, the kernel runs as fast; Mesa 25 runs it ~12 % slower, hence both
#    variants). Then the loops marked [[unroll]] (those over the four offsets) are unrolled and
#    their arrays split into scalars, which lavapipe 22.3 would otherwise do itself, one nesting
#    level per round of its optimisation loop over the whole kernel (bench/RESULTS.md, "Offset
#    loops unrolled before the driver"). Specialisation constants stay constants. No -O: its
#    extra passes made the G-PT kernel run 4 % slower on lavapipe 22.3.
# 3. Embed the words as `const uint32_t NAME[]` (glslang's) and `NAME_opt[]` (spirv-opt's; the
#    same words without SPIRV_OPT) in OUT; vk::useOptimizedSpirv picks one per device.
string(REPLACE "|" ";" FLAGS "${FLAGS}")
set(raw "${OUT}.spv")
execute_process(
  COMMAND ${GLSLANG} --target-env vulkan1.2 -V ${FLAGS} --depfile ${OUT}.d -o ${raw} ${SRC}
  RESULT_VARIABLE rc OUTPUT_VARIABLE log ERROR_VARIABLE log)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "glslangValidator failed on ${SRC}:\n${log}")
endif()
# The depfile names the raw SPIR-V; the rule's output is the header.
file(READ ${OUT}.d dep)
string(REPLACE "${raw}:" "${OUT}:" dep "${dep}")
file(WRITE ${OUT}.d "${dep}")

set(opt "${raw}")
if(SPIRV_OPT)
  set(opt "${OUT}.opt.spv")
  execute_process(
    COMMAND ${SPIRV_OPT} --target-env=vulkan1.2 --scalar-block-layout
            --inline-entry-points-exhaustive --eliminate-dead-functions --private-to-local
            --scalar-replacement=100 --eliminate-local-single-block --eliminate-local-single-store
            --ssa-rewrite --copy-propagate-arrays --eliminate-dead-code-aggressive
            --simplify-instructions --eliminate-dead-inserts
            --eliminate-dead-branches --merge-blocks --loop-unroll
            --scalar-replacement=100 --ssa-rewrite --copy-propagate-arrays
            --eliminate-dead-code-aggressive --simplify-instructions --eliminate-dead-inserts
            ${raw} -o ${opt}
    RESULT_VARIABLE rc OUTPUT_VARIABLE log ERROR_VARIABLE log)
  # spirv-opt warns about every call it leaves (functions with an early return); lavapipe
  # inlines those itself, so only a failure is reported.
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "spirv-opt failed on ${SRC}:\n${log}")
  endif()
endif()

# The words of a SPIR-V file as C array initialisers, eight per line.
function(spirv_words file outvar)
  file(READ ${file} hex HEX)
  string(LENGTH "${hex}" n)
  math(EXPR rem "${n} % 8")
  if(n EQUAL 0 OR NOT rem EQUAL 0)
    message(FATAL_ERROR "${file}: not a whole number of 32-bit words")
  endif()
  # Little-endian bytes b0 b1 b2 b3 -> the word 0xb3b2b1b0.
  string(REGEX REPLACE "(..)(..)(..)(..)" "0x\\4\\3\\2\\1," words "${hex}")
  string(REPEAT "0x........," 8 eight)  # (CMake's regular expressions have no {8})
  string(REGEX REPLACE "(${eight})" "\\1\n" words "${words}")
  set(${outvar} "${words}" PARENT_SCOPE)
endfunction()

spirv_words(${raw} raw_words)
spirv_words(${opt} opt_words)
file(WRITE ${OUT}.tmp "#pragma once\n#include <cstdint>\nconst uint32_t ${NAME}[] = {\n${raw_words}\n};\n"
                      "const uint32_t ${NAME}_opt[] = {\n${opt_words}\n};\n")
file(RENAME ${OUT}.tmp ${OUT})
