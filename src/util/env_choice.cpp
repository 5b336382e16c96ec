#include "util/env_choice.h"

#include <cstdlib>
#include <string>

#include "util/error.h"

namespace gdpt {

bool envChoice(const char* var, const char* whenFalse, const char* whenTrue, bool byDefault) {
    const char* env = std::getenv(var);
    const std::string v = env != nullptr ? env : "";
    if (v.empty() || v == "auto") return byDefault;
    if (v == whenTrue) return true;
    if (v == whenFalse) return false;
    throw Error(std::string(var) + "='" + v + "': expected auto, " + whenFalse + " or " + whenTrue);
}

}  // namespace gdpt
