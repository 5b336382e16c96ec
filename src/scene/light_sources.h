// light_sources.h — whether a scene emits any light at all. A scene without an emissive
// surface, a punctual light or an environment renders black, which no kernel reports, so the
// commands warn about it up front.
#pragma once

#include <glm/glm.hpp>
#include <optional>
#include <string>

#include "scene/scene.h"

namespace gdpt {

// True if some triangle has an emissive material with a positive emission component and a
// non-zero area, some punctual light has a positive intensity component, or envRadiance
// has a positive component.
[[nodiscard]] bool hasLightSource(const Scene& scene, glm::vec3 envRadiance);

// The warning for a scene without a light source, or nothing when it has one:
//   "SCENE: no light source (no emissive surface, no punctual light, no --env): the image
//   will be black; try --env 1,1,1"
// where SCENE is the file it was loaded from. envOption = false for commands without --env
// (the message then neither mentions nor suggests it).
[[nodiscard]] std::optional<std::string> blackImageWarning(const Scene& scene, glm::vec3 envRadiance,
                                                           bool envOption = true);

}  // namespace gdpt
