// env_choice.h — a two-way choice that the host makes per device and that an environment
// variable may override for measurements (GDPT_SPIRV=raw|opt, GDPT_BVH_STEPS=nodes|units).
#pragma once

namespace gdpt {

// `byDefault` when the variable `var` is unset, empty or "auto"; true for `whenTrue`, false for
// `whenFalse`; throws gdpt::Error naming `var`, its value and the accepted values otherwise.
bool envChoice(const char* var, const char* whenFalse, const char* whenTrue, bool byDefault);

}  // namespace gdpt
