// cache_dir.h — where gdpt keeps what it remembers between runs: the reconstruction's times
// (integrator/recon_reserve.h) and the specialised kernels (vk/spirv_specialise.h). Both are
// optimisations only: a missing or unwritable directory costs time, never a result.
#pragma once

#include <filesystem>

namespace gdpt {

// $GDPT_CACHE_DIR, else $XDG_CACHE_HOME/gdpt, else $HOME/.cache/gdpt; empty if none is set.
// Not created here.
std::filesystem::path cacheDirectory();

}  // namespace gdpt
