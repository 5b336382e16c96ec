// camera.glsl — the pinhole camera's ray through a continuous pixel position (x right, y
// down, pixel (i, j) covers [i, i+1) x [j, j+1)), shared by every kernel that starts camera
// paths. GLSL only; expects the scene constants (scene_buffers.glsl). The host's copy, and its
// inverse, is src/render/device_scene/camera_ray.h: change both.
#ifndef GDPT_LIB_CAMERA
#define GDPT_LIB_CAMERA

vec3 cameraRay(vec2 pixelPos) {
    vec2 ndc = vec2(2.0 * pixelPos.x / float(scene.width) - 1.0,
                    1.0 - 2.0 * pixelPos.y / float(scene.height));
    vec3 d = scene.camForward + ndc.x * scene.tanHalfFovY * scene.aspect * scene.camRight +
             ndc.y * scene.tanHalfFovY * scene.camUp;
    return normalize(d);
}

#endif  // GDPT_LIB_CAMERA
