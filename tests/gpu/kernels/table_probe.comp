// table_probe.comp — test kernel: reads element 1 of every scene table through the texel-
// buffer accessors of shaders/lib/scene_geometry.glsl and scene_buffers.glsl and writes the
// structs back through a scalar storage block (whose layout test_layout_gpu.cpp pins), so
// the host can check that each accessor returns what it uploaded, field for field.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#include "gdpt_shared.h"
#include "lib/scene_buffers.glsl"

layout(local_size_x = 1) in;
layout(set = 0, binding = kBindTestOutput, scalar) writeonly buffer Out {
    TriangleGeom geom;
    BvhWideNode node;
    TriangleShading shading;
    Material material;
    TextureInfo tex;
    LightTriangle light;
    PunctualLight punctual;
    vec4 texel;
    vec3 unitNormal;
} probe;

void main() {
    probe.geom = triangleGeom(1u);
    probe.node = bvhNode(1u);
    probe.shading = triangleShading(1u);
    probe.material = material(1u);
    probe.tex = textureInfo(1u);
    probe.light = lightTriangle(1u);
    probe.punctual = punctualLight(1u);
    probe.texel = imageTexel(1u);
    probe.unitNormal = triangleUnitNormal(1u);
}
