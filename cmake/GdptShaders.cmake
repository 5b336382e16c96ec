# gdpt_add_shaders(<target> <kernel.comp>... [SUFFIX <s>] [DEFINES <NAME>...])
#
# Compiles each compute shader to SPIR-V with glslangValidator, optimises it with spirv-opt
# (GDPT_SPIRV_OPT, see GdptSpirvEmbed.cmake) and embeds it as a
# `const uint32_t kSpv_<name>[]` array in <build>/shaders/spv/<name>.spv.h. The rule uses
# glslangValidator's --depfile so that editing any included header (shaders/lib/*.glsl,
# shaders/shared/gdpt_shared.h) rebuilds the SPIR-V. The headers are exposed through the
# INTERFACE library <target>. With SUFFIX and DEFINES, each kernel is compiled with
# -D<NAME> for every name into kSpv_<name><s> in <name><s>.spv.h (a second build of the same
# source, e.g. the device-address variants of the Poisson kernels).
find_program(GLSLANG_VALIDATOR glslangValidator REQUIRED)
option(GDPT_SPIRV_OPT "Optimise the kernels' SPIR-V with spirv-opt (faster pipeline creation on lavapipe)" ON)
if(GDPT_SPIRV_OPT)
  find_program(SPIRV_OPT spirv-opt REQUIRED)
else()
  set(SPIRV_OPT "")
endif()
set(GDPT_SPIRV_EMBED ${CMAKE_CURRENT_LIST_DIR}/GdptSpirvEmbed.cmake)

function(gdpt_add_shaders target)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "SUFFIX" "DEFINES")
  set(define_flags)
  foreach(d ${arg_DEFINES})
    list(APPEND define_flags -D${d})
  endforeach()
  set(out_dir ${CMAKE_BINARY_DIR}/shaders/spv)
  file(MAKE_DIRECTORY ${out_dir})
  set(outputs)
  set(debug_flags)
  if(CMAKE_BUILD_TYPE STREQUAL "Debug")
    set(debug_flags -g)
  endif()
  foreach(src ${arg_UNPARSED_ARGUMENTS})
    get_filename_component(name ${src} NAME_WE)
    set(name ${name}${arg_SUFFIX})
    get_filename_component(abs ${src} ABSOLUTE)
    set(out ${out_dir}/${name}.spv.h)
    set(flags ${debug_flags} ${define_flags} -I${CMAKE_SOURCE_DIR}/shaders -I${CMAKE_SOURCE_DIR}/shaders/shared)
    string(REPLACE ";" "|" flags "${flags}")  # one -D argument; the script splits it
    add_custom_command(
      OUTPUT ${out}
      COMMAND ${CMAKE_COMMAND} -DGLSLANG=${GLSLANG_VALIDATOR} -DSPIRV_OPT=${SPIRV_OPT} -DSRC=${abs}
              -DOUT=${out} -DNAME=kSpv_${name} -DFLAGS=${flags} -P ${GDPT_SPIRV_EMBED}
      DEPENDS ${abs} ${GDPT_SPIRV_EMBED}
      DEPFILE ${out}.d
      COMMENT "GLSL -> SPIR-V ${name}"
      VERBATIM)
    list(APPEND outputs ${out})
  endforeach()
  add_custom_target(${target}_spv DEPENDS ${outputs})
  add_library(${target} INTERFACE)
  add_dependencies(${target} ${target}_spv)
  target_include_directories(${target} INTERFACE ${out_dir})
endfunction()
