// layout_probe.comp — test kernel: writes a distinct sentinel into every field of the shared
// structs, so the host can check that C++ and GLSL agree on every offset
// (tests/gpu/device_scene/test_layout_gpu.cpp).
// Sentinel of field k (counting scalar components in declaration order from 1) is k.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require
#include "gdpt_shared.h"

layout(local_size_x = 1) in;
layout(set = 0, binding = kBindTestInput, scalar) writeonly buffer A { BvhNode node; TriangleShading shading; Material material; };
layout(set = 0, binding = kBindTestOutput, scalar) writeonly buffer B { SceneConstants sc; PixelStats stats; PunctualLight light; BvhWideNode wide; };

void main() {
    node.lmin = vec3(1, 2, 3); node.left = 4u; node.lmax = vec3(5, 6, 7); node.leftCount = 8u;
    node.rmin = vec3(9, 10, 11); node.right = 12u; node.rmax = vec3(13, 14, 15); node.rightCount = 16u;

    shading.n0 = vec3(1, 2, 3); shading.material = 4u; shading.n1 = vec3(5, 6, 7); shading.area = 8.0;
    shading.n2 = vec3(9, 10, 11); shading.flags = 12u; shading.uv0 = vec2(13, 14); shading.uv1 = vec2(15, 16);
    shading.uv2 = vec2(17, 18); shading.lightIndex = 19u; shading.pad3 = 20u;

    material.baseColor = vec4(1, 2, 3, 4); material.emissive = vec3(5, 6, 7); material.metallic = 8.0;
    material.specularColor = vec3(9, 10, 11); material.roughness = 12.0; material.specular = 13.0;
    material.ior = 14.0; material.alphaCutoff = 15.0; material.flags = 16u; material.baseColorTex = 17;
    material.metallicRoughnessTex = 18; material.emissiveTex = 19; material.normalTex = 20;

    sc.camPosition = vec3(1, 2, 3); sc.tanHalfFovY = 4.0; sc.camRight = vec3(5, 6, 7); sc.aspect = 8.0;
    sc.camUp = vec3(9, 10, 11); sc.width = 12u; sc.camForward = vec3(13, 14, 15); sc.height = 16u;
    sc.envRadiance = vec3(17, 18, 19); sc.numLightTriangles = 20u; sc.numPunctualLights = 21u;
    sc.lightTrianglePower = 22.0; sc.punctualPower = 23.0; sc.maxDepth = 24u; sc.sceneRadius = 25.0;
    sc.rrDepth = 26u; sc.numTriangles = 27u; sc.pad = 28u;

    stats.mean = vec3(1, 2, 3); stats.count = 4u; stats.m2 = vec3(5, 6, 7); stats.pad = 8u;

    light.position = vec3(1, 2, 3); light.type = 4u; light.intensity = vec3(5, 6, 7); light.cosInner = 8.0;
    light.direction = vec3(9, 10, 11); light.cosOuter = 12.0;

    wide.origin = vec3(1, 2, 3); wide.exponents = 4u;
    wide.qMin = uvec4(5, 6, 7, 8); wide.qMax = uvec4(9, 10, 11, 12); wide.child = uvec4(13, 14, 15, 16);
}
