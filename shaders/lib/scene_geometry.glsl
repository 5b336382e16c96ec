// scene_geometry.glsl — the two tables every ray query reads, the four-wide BVH nodes and
// the triangles (TriangleGeom, leaf order), declared as uniform texel buffers of RGBA32
// texels, with accessors that return the gdpt_shared.h structs.
//
// Why texel buffers and not storage buffers: lavapipe before Mesa 23 compiles each
// storage-buffer load into a loop over the SIMD lanes with a branch per lane and component,
// whereas texelFetch from a buffer is a vector gather (bench/RESULTS.md, texel
// buffers).
// Both structs are whole 16-byte texels (a node is four, a triangle three), so the layout in
// memory is the same as the storage-buffer one; the host binds the same buffers with a view
// (KernelDesc::texelBindings).
#ifndef GDPT_LIB_SCENE_GEOMETRY
#define GDPT_LIB_SCENE_GEOMETRY

layout(set = 0, binding = kBindTriGeom) uniform textureBuffer triGeomTexels;
layout(set = 0, binding = kBindBvh) uniform utextureBuffer bvhTexels;

// Two frames of one animation in one kernel (GDPT_TWO_FRAMES: tgpt_reconnect.comp; the host's
// FramePairGpu): every per-triangle table holds frame 0's triangles and then frame 1's, in the
// same leaf order, under one tree whose boxes hold both; selectFrame (scene_buffers.glsl)
// sets the first entry of the frame that triangle index i means. Elsewhere the index is the
// entry.
#ifdef GDPT_TWO_FRAMES
uint frameTriangleBase = 0u;
#define GDPT_FRAME_TRIANGLE(i) ((i) + frameTriangleBase)
#else
#define GDPT_FRAME_TRIANGLE(i) (i)
#endif

// Wide node i (BvhWideNode: origin + exponents, qMin, qMax, child).
BvhWideNode bvhNode(uint i) {
    int at = int(i * kBvhWideNodeTexels);
    uvec4 a = texelFetch(bvhTexels, at);
    BvhWideNode n;
    n.origin = uintBitsToFloat(a.xyz);
    n.exponents = a.w;
    n.qMin = texelFetch(bvhTexels, at + 1);
    n.qMax = texelFetch(bvhTexels, at + 2);
    n.child = texelFetch(bvhTexels, at + 3);
    return n;
}

// Triangle i in leaf order (TriangleGeom: v0, e1, e2, each padded to a texel).
TriangleGeom triangleGeom(uint i) {
    int at = int(GDPT_FRAME_TRIANGLE(i) * kTriangleGeomTexels);
    TriangleGeom g;
    g.v0 = texelFetch(triGeomTexels, at).xyz;
    g.e1 = texelFetch(triGeomTexels, at + 1).xyz;
    g.e2 = texelFetch(triGeomTexels, at + 2).xyz;
    g.pad0 = 0.0;
    g.pad1 = 0.0;
    g.pad2 = 0.0;
    return g;
}

// Unit normal of triangle i, normalize(e1 × e2) (counter-clockwise side; two fetches).
vec3 triangleUnitNormal(uint i) {
    int at = int(GDPT_FRAME_TRIANGLE(i) * kTriangleGeomTexels);
    return normalize(cross(texelFetch(triGeomTexels, at + 1).xyz, texelFetch(triGeomTexels, at + 2).xyz));
}

#endif  // GDPT_LIB_SCENE_GEOMETRY
