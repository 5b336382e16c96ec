#!/usr/bin/env python3
"""Write a gdpt glTF scene as a Mitsuba 0.5 scene, for side-by-side benchmarks against the
reference G-PT (Kettunen et al. 2015), whose published implementation is a Mitsuba 0.5 plugin.

Usage: export-mitsuba.py SCENE.gltf OUTDIR

Writes OUTDIR/scene.xml (the geometry, materials and emitters), one OBJ per mesh instance and
OUTDIR/int_{path,gpt_L1,gpt_L2}.xml (integrator + sensor, included by scene.xml through
`-D integrator=...`; also -D spp, width, height). Run as
    mitsuba -p 2 -D integrator=gpt_L1 -D spp=32 -o OUT OUTDIR/scene.xml     (-> OUT-final.exr)

The subset of glTF that the scenes of gdpt's set use, exactly: triangle meshes (positions,
optional normals, indices) under node transforms (matrix or TRS, nested), one-sided
materials, the first perspective camera, and
  - Lambertian materials (metallicFactor 0, KHR_materials_specular specularFactor 0) as
    Mitsuba `diffuse` with reflectance = baseColorFactor: the same BSDF;
  - emission (emissiveFactor x KHR_materials_emissive_strength) as an `area` emitter of that
    radiance on the mesh, emitting from the counter-clockwise side (the same side in both);
  - metals (metallicFactor 1) as `roughconductor` (GGX, alpha = roughness^2) or `conductor`
    (roughness 0) with material "none" and specularReflectance = baseColorFactor. Only an
    approximation: gdpt's metal uses Schlick's Fresnel with F0 = baseColorFactor, Mitsuba
    this constant reflectance; the script says so, and such a scene needs references from each
    renderer.
Anything else (textures, dielectric specular layers, alpha, cameras other than perspective,
environments given by `--env`) is refused with a message and exit status 2.
"""
import base64
import json
import math
import os
import struct
import sys

COMPONENT = {5126: ("f", 4), 5125: ("I", 4), 5123: ("H", 2), 5121: ("B", 1)}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def fail(message):
    print("export-mitsuba: " + message, file=sys.stderr)
    sys.exit(2)


def load_buffers(gltf, directory):
    out = []
    for b in gltf.get("buffers", []):
        uri = b.get("uri", "")
        if uri.startswith("data:"):
            out.append(base64.b64decode(uri.split(",", 1)[1]))
        elif uri:
            with open(os.path.join(directory, uri), "rb") as f:
                out.append(f.read())
        else:
            fail("binary glTF (.glb) buffers are not supported; use a .gltf")
    return out


def read_accessor(gltf, buffers, index):
    a = gltf["accessors"][index]
    if "bufferView" not in a or a.get("sparse"):
        fail("accessor %d: sparse or view-less accessors are not supported" % index)
    view = gltf["bufferViews"][a["bufferView"]]
    code, size = COMPONENT[a["componentType"]]
    n = WIDTH[a["type"]]
    stride = view.get("byteStride", size * n)
    base = view.get("byteOffset", 0) + a.get("byteOffset", 0)
    data = buffers[view["buffer"]]
    return [struct.unpack_from("<%d%s" % (n, code), data, base + i * stride) for i in range(a["count"])]


def mat_mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def node_matrix(node):
    if "matrix" in node:
        m = node["matrix"]  # column-major
        return [[m[c * 4 + r] for c in range(4)] for r in range(4)]
    tx, ty, tz = node.get("translation", [0, 0, 0])
    x, y, z, w = node.get("rotation", [0, 0, 0, 1])
    sx, sy, sz = node.get("scale", [1, 1, 1])
    r = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
         [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
         [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    s = [sx, sy, sz]
    t = [tx, ty, tz]
    return [[r[i][0] * s[0], r[i][1] * s[1], r[i][2] * s[2], t[i]] for i in range(3)] + [[0, 0, 0, 1]]


def apply_point(m, p):
    return [sum(m[i][k] * p[k] for k in range(3)) + m[i][3] for i in range(3)]


def apply_normal(m, n):
    # inverse transpose of the upper 3x3
    a = [row[:3] for row in m[:3]]
    det = (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]))
    cof = [[(a[(i + 1) % 3][(j + 1) % 3] * a[(i + 2) % 3][(j + 2) % 3] -
             a[(i + 1) % 3][(j + 2) % 3] * a[(i + 2) % 3][(j + 1) % 3]) / det for j in range(3)] for i in range(3)]
    v = [sum(cof[i][k] * n[k] for k in range(3)) for i in range(3)]
    length = math.sqrt(sum(c * c for c in v)) or 1.0
    return [c / length for c in v]


def bsdf_xml(material, name):
    pbr = material.get("pbrMetallicRoughness", {})
    if "baseColorTexture" in pbr or "metallicRoughnessTexture" in pbr or "emissiveTexture" in material \
            or "normalTexture" in material:
        fail("material '%s': textures are not supported" % name)
    if material.get("doubleSided", False):
        fail("material '%s': double-sided materials are not supported" % name)
    if material.get("alphaMode", "OPAQUE") != "OPAQUE":
        fail("material '%s': alpha modes are not supported" % name)
    base = pbr.get("baseColorFactor", [1, 1, 1, 1])[:3]
    metallic = pbr.get("metallicFactor", 1.0)
    roughness = pbr.get("roughnessFactor", 1.0)
    specular = material.get("extensions", {}).get("KHR_materials_specular", {}).get("specularFactor", 1.0)
    rgb = "%.9g, %.9g, %.9g" % tuple(base)
    if metallic == 0.0 and specular == 0.0:
        return '<bsdf type="diffuse"><rgb name="reflectance" value="%s"/></bsdf>' % rgb, False
    if metallic == 1.0:
        if roughness == 0.0:
            return ('<bsdf type="conductor"><string name="material" value="none"/>'
                    '<rgb name="specularReflectance" value="%s"/></bsdf>' % rgb), True
        return ('<bsdf type="roughconductor"><string name="distribution" value="ggx"/>'
                '<float name="alpha" value="%.9g"/><string name="material" value="none"/>'
                '<rgb name="specularReflectance" value="%s"/></bsdf>' % (roughness * roughness, rgb)), True
    fail("material '%s': only Lambertian (metallic 0, specular 0) and metallic 1 materials are supported" % name)


SENSOR = """	<sensor type="perspective">
		<float name="fov" value="%(fov).9g"/>
		<string name="fovAxis" value="y"/>
		<float name="nearClip" value="0.01"/>
		<float name="farClip" value="100000"/>
		<transform name="toWorld"><matrix value="%(matrix)s"/></transform>
		<sampler type="independent"><integer name="sampleCount" value="$spp"/></sampler>
		<film type="%(film)s">
			<integer name="width" value="$width"/>
			<integer name="height" value="$height"/>
			<string name="pixelFormat" value="rgb"/>
			<string name="componentFormat" value="float32"/>
			<boolean name="banner" value="false"/>
			<rfilter type="box"/>
		</film>
	</sensor>
"""

INTEGRATORS = {
    "path": ('<integrator type="path"><integer name="maxDepth" value="-1"/>'
             '<integer name="rrDepth" value="5"/></integrator>', "hdrfilm"),
    "gpt_L1": ('<integrator type="gpt"><integer name="maxDepth" value="-1"/><integer name="rrDepth" value="5"/>'
               '<float name="shiftThreshold" value="0.001"/><boolean name="reconstructL1" value="true"/>'
               '<boolean name="reconstructL2" value="false"/><float name="reconstructAlpha" value="0.2"/>'
               '</integrator>', "multifilm"),
    "gpt_L2": ('<integrator type="gpt"><integer name="maxDepth" value="-1"/><integer name="rrDepth" value="5"/>'
               '<float name="shiftThreshold" value="0.001"/><boolean name="reconstructL1" value="false"/>'
               '<boolean name="reconstructL2" value="true"/><float name="reconstructAlpha" value="0.2"/>'
               '</integrator>', "multifilm"),
}


def main():
    if len(sys.argv) != 3:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        sys.exit(2)
    path, out = sys.argv[1], sys.argv[2]
    try:
        with open(path) as f:
            gltf = json.load(f)
    except (OSError, ValueError) as e:
        fail("cannot read %s: %s" % (path, e))
    buffers = load_buffers(gltf, os.path.dirname(path))
    os.makedirs(out, exist_ok=True)

    shapes = []
    camera = None
    approximate = []
    count = 0

    def visit(index, parent):
        nonlocal camera, count
        node = gltf["nodes"][index]
        m = mat_mul(parent, node_matrix(node))
        if "camera" in node and camera is None:
            camera = (gltf["cameras"][node["camera"]], m)
        if "mesh" in node:
            for prim in gltf["meshes"][node["mesh"]]["primitives"]:
                if prim.get("mode", 4) != 4:
                    fail("mesh %d: only triangle primitives are supported" % node["mesh"])
                if "targets" in prim:
                    fail("mesh %d: morph targets are not supported" % node["mesh"])
                positions = [apply_point(m, p) for p in read_accessor(gltf, buffers, prim["attributes"]["POSITION"])]
                normals = None
                if "NORMAL" in prim["attributes"]:
                    normals = [apply_normal(m, n) for n in read_accessor(gltf, buffers, prim["attributes"]["NORMAL"])]
                if "indices" in prim:
                    idx = [i[0] for i in read_accessor(gltf, buffers, prim["indices"])]
                else:
                    idx = list(range(len(positions)))
                if "material" not in prim:
                    fail("mesh %d: a primitive without a material is not supported" % node["mesh"])
                material = gltf["materials"][prim["material"]]
                name = material.get("name", "material%d" % prim["material"])
                bsdf, approx = bsdf_xml(material, name)
                if approx and name not in approximate:
                    approximate.append(name)
                emissive = material.get("emissiveFactor", [0, 0, 0])
                strength = material.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get(
                    "emissiveStrength", 1.0)
                radiance = [c * strength for c in emissive]
                obj = "mesh%03d.obj" % count
                count += 1
                with open(os.path.join(out, obj), "w") as f:
                    for p in positions:
                        f.write("v %.9g %.9g %.9g\n" % tuple(p))
                    if normals:
                        for n in normals:
                            f.write("vn %.9g %.9g %.9g\n" % tuple(n))
                    for t in range(0, len(idx), 3):
                        a, b, c = idx[t] + 1, idx[t + 1] + 1, idx[t + 2] + 1
                        if normals:
                            f.write("f %d//%d %d//%d %d//%d\n" % (a, a, b, b, c, c))
                        else:
                            f.write("f %d %d %d\n" % (a, b, c))
                xml = '\t<shape type="obj"><string name="filename" value="%s"/>' % obj
                if not normals:
                    xml += '<boolean name="faceNormals" value="true"/>'
                xml += "\n\t\t" + bsdf
                if any(c > 0 for c in radiance):
                    xml += '\n\t\t<emitter type="area"><rgb name="radiance" value="%.9g, %.9g, %.9g"/></emitter>' % \
                        tuple(radiance)
                shapes.append(xml + "\n\t</shape>\n")
        for child in node.get("children", []):
            visit(child, m)

    identity = [[1 if i == j else 0 for j in range(4)] for i in range(4)]
    scene = gltf.get("scenes", [{}])[gltf.get("scene", 0)]
    for root in scene.get("nodes", []):
        visit(root, identity)
    if camera is None:
        fail("the scene has no camera")
    cam, m = camera
    if cam.get("type") != "perspective":
        fail("only perspective cameras are supported")
    # glTF cameras look down -Z with +X right; Mitsuba's down +Z with +X left: flip X and Z.
    flip = [[-1, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1, 0], [0, 0, 0, 1]]
    to_world = mat_mul(m, flip)
    fov = math.degrees(cam["perspective"]["yfov"])
    matrix = " ".join("%.9g" % to_world[r][c] for r in range(4) for c in range(4))

    for name, (integrator, film) in INTEGRATORS.items():
        with open(os.path.join(out, "int_%s.xml" % name), "w") as f:
            f.write('<?xml version="1.0" encoding="utf-8"?>\n<scene version="0.5.0">\n\t%s\n' % integrator)
            f.write(SENSOR % {"fov": fov, "matrix": matrix, "film": film})
            f.write("</scene>\n")
    with open(os.path.join(out, "scene.xml"), "w") as f:
        f.write('<?xml version="1.0" encoding="utf-8"?>\n')
        f.write("<!-- %s, written by gdpt's scripts/export-mitsuba.py -->\n" % os.path.basename(path))
        f.write('<scene version="0.5.0">\n\t<default name="integrator" value="path"/>\n'
                '\t<default name="spp" value="16"/>\n\t<default name="width" value="256"/>\n'
                '\t<default name="height" value="256"/>\n\t<include filename="int_$integrator.xml"/>\n')
        for s in shapes:
            f.write(s)
        f.write("</scene>\n")
    note = ""
    if approximate:
        note = " (approximate metals: %s; compare against each renderer's own reference)" % ", ".join(approximate)
    print("export-mitsuba: %s -> %s/scene.xml, %d shapes%s" % (path, out, count, note))


if __name__ == "__main__":
    main()
