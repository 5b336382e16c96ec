// camera_ray.h — the pinhole camera of the scene constants on the host: camera.glsl's
// cameraRay (the ray through a continuous pixel position, x right, y down, pixel (i, j)
// covering [i, i+1) x [j, j+1)) and its inverse. Header-only (gdpt_shared.h and GLM), for host
// code that must trace or project exactly as the kernels do.
#pragma once

#include <cmath>
#include <glm/glm.hpp>

#include "gdpt_shared.h"

namespace gdpt {

// camera.glsl's cameraRay for the scene constants `c`: the unit direction through pixelPos.
inline glm::vec3 cameraRay(const gpu::SceneConstants& c, glm::vec2 pixelPos) {
    const glm::vec2 ndc(2.0f * pixelPos.x / float(c.width) - 1.0f,
                        1.0f - 2.0f * pixelPos.y / float(c.height));
    const glm::vec3 d =
        c.camForward + ndc.x * c.tanHalfFovY * c.aspect * c.camRight + ndc.y * c.tanHalfFovY * c.camUp;
    return glm::normalize(d);
}

// The inverse: the continuous pixel position at which the camera sees direction d (from its
// position), or false if d points behind the camera.
inline bool projectToPixel(const gpu::SceneConstants& c, glm::vec3 d, glm::vec2& pixelPos) {
    const float z = glm::dot(d, c.camForward);
    if (!(z > 0.0f)) return false;
    const float nx = glm::dot(d, c.camRight) / (z * c.tanHalfFovY * c.aspect);
    const float ny = glm::dot(d, c.camUp) / (z * c.tanHalfFovY);
    pixelPos = glm::vec2(0.5f * (nx + 1.0f) * float(c.width), 0.5f * (1.0f - ny) * float(c.height));
    return std::isfinite(pixelPos.x) && std::isfinite(pixelPos.y);
}

}  // namespace gdpt
