// visible_emission.glsl — what the path kernels need of emitter supersampling
// (emitter_supersampling.comp, render/passes/emitter_supersampling_pass.h): pixels whose camera-visible emission is estimated
// by that pass (its statistics have samples) leave the emission of their first hit, or the
// environment seen by a camera ray that misses, out of their own estimate. GLSL only.
#ifndef GDPT_LIB_VISIBLE_EMISSION
#define GDPT_LIB_VISIBLE_EMISSION

// Off (the pass disabled: nothing in the scene the camera could see emit, or the user's
// choice): the read is compiled out and the binding holds a placeholder.
layout(constant_id = kSpecVisibleEmission) const bool kVisibleEmission = true;
#include "lib/pixel_buffers.glsl"
GDPT_PIXEL_BUFFER(kBindVisibleStats, PixelStatsArray, visibleStats);
#define visibleStats visibleStats_.v

bool emissionSupersampled(uint pixel) { return kVisibleEmission && visibleStats[pixel].count > 0u; }

#endif  // GDPT_LIB_VISIBLE_EMISSION
