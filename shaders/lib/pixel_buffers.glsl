// pixel_buffers.glsl — how the sampling kernels reach their per-pixel buffers (statistics,
// masks, probes, resolved images): the buffer's binding holds its device address (8 bytes;
// vk::Kernel::bindAddress) and the kernel indexes the buffer through a buffer reference
// (GL_EXT_buffer_reference). A descriptor's range is capped by maxStorageBufferRange (128 MiB on
// lavapipe: 4.2M PixelStats, less than a 3840x2160 image); an address reaches the whole
// allocation (maxMemoryAllocationSize). The kernels touch these buffers a few times per
// invocation against hundreds of scene reads, so the indirection costs nothing measurable
// (bench/RESULTS.md, "Per-pixel buffers through device addresses"). GLSL only.
//
//   GDPT_PIXEL_BUFFER(kBindAccum, PixelStatsArray, accum);
//   #define accum accum_.v   // then accum[i] as with a descriptor
#ifndef GDPT_LIB_PIXEL_BUFFERS
#define GDPT_LIB_PIXEL_BUFFERS

#extension GL_EXT_buffer_reference : require

layout(buffer_reference, scalar, buffer_reference_align = 4) buffer PixelStatsArray { PixelStats v[]; };
layout(buffer_reference, scalar, buffer_reference_align = 4) buffer UintArray { uint v[]; };

// Declares the binding that holds the address of an `Array` (a buffer_reference type with a
// member array v[]) as `name_`.
#define GDPT_PIXEL_BUFFER(bindingNumber, Array, name) \
    layout(set = 0, binding = bindingNumber, scalar) readonly restrict buffer name##Address { Array name##_; }

#endif  // GDPT_LIB_PIXEL_BUFFERS
