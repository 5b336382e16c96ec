#!/usr/bin/env python3
"""Writes gdpt's small test scenes as glTF 2.0 JSON files with embedded (data: URI) buffers.

    python3 scenes/make_scenes.py [output_dir]   (default: the folder of this script)

Outputs (see scenes/README.md):
  cornell_box.gltf    the Cornell box of ../shared/scenes/cbox (same vertices, materials, camera)
  glossy_cornell.gltf the same room, tall box rough metal (roughness 0.3), a mirror sphere
                      (roughness 0) in place of the short box
  furnace.gltf        closed inward-facing sphere, albedo 0.5, emission 0.5, camera at centre

Python standard library only, so that anyone can regenerate the files. Conventions follow
../shared/scenes/README.md: Y up, metres, radiance = emissiveFactor x emissive_strength,
one-sided materials, pure Lambertian = metallicFactor 0 + KHR_materials_specular factor 0.
"""
import base64
import json
import math
import os
import struct
import sys

FLOAT, UINT = 5126, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963


class GltfWriter:
    """Accumulates meshes, materials and nodes and packs all data into one buffer."""

    def __init__(self):
        self.blob = bytearray()
        self.doc = {"asset": {"version": "2.0", "generator": "gdpt scenes/make_scenes.py"},
                    "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [],
                    "materials": [], "accessors": [], "bufferViews": [], "cameras": []}
        self.extensions = set()

    def _view(self, data, target):
        while len(self.blob) % 4:
            self.blob.append(0)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.blob),
                                        "byteLength": len(data), "target": target})
        self.blob += data
        return len(self.doc["bufferViews"]) - 1

    def _accessor(self, values, kind):
        if kind == "VEC3":
            flat = [c for v in values for c in v]
            view = self._view(struct.pack("<%df" % len(flat), *flat), ARRAY_BUFFER)
            acc = {"bufferView": view, "componentType": FLOAT, "count": len(values), "type": "VEC3",
                   "min": [min(v[i] for v in values) for i in range(3)],
                   "max": [max(v[i] for v in values) for i in range(3)]}
        else:
            view = self._view(struct.pack("<%dI" % len(values), *values), ELEMENT_ARRAY_BUFFER)
            acc = {"bufferView": view, "componentType": UINT, "count": len(values), "type": "SCALAR"}
        # Unpacked float32 bounds so that min/max match the stored data exactly.
        if "min" in acc:
            acc["min"] = [struct.unpack("<f", struct.pack("<f", x))[0] for x in acc["min"]]
            acc["max"] = [struct.unpack("<f", struct.pack("<f", x))[0] for x in acc["max"]]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def material(self, name, base, metallic=0.0, roughness=1.0, specular=0.0, emission=None):
        """specular=None leaves KHR_materials_specular out (its default factor is 1)."""
        m = {"name": name, "doubleSided": False,
             "pbrMetallicRoughness": {"baseColorFactor": list(base) + [1.0],
                                      "metallicFactor": metallic, "roughnessFactor": roughness}}
        ext = {}
        if specular is not None:
            ext["KHR_materials_specular"] = {"specularFactor": specular}
        if emission is not None:
            strength = max(emission)
            m["emissiveFactor"] = [c / strength for c in emission]
            if strength != 1.0:
                ext["KHR_materials_emissive_strength"] = {"emissiveStrength": strength}
        if ext:
            m["extensions"] = ext
            self.extensions.update(ext)
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def mesh(self, name, positions, normals, indices, material):
        prim = {"attributes": {"POSITION": self._accessor(positions, "VEC3"),
                               "NORMAL": self._accessor(normals, "VEC3")},
                "indices": self._accessor(indices, "SCALAR"), "material": material, "mode": 4}
        self.doc["meshes"].append({"name": name, "primitives": [prim]})
        self.node({"name": name, "mesh": len(self.doc["meshes"]) - 1})

    def node(self, node):
        self.doc["nodes"].append(node)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def camera(self, name, position, yfov, aspect=1.0, rotation=(0.0, 0.0, 0.0, 1.0)):
        self.doc["cameras"].append({"name": name, "type": "perspective",
                                    "perspective": {"yfov": yfov, "aspectRatio": aspect,
                                                    "znear": 0.01}})
        self.node({"name": name, "camera": len(self.doc["cameras"]) - 1,
                   "translation": list(position), "rotation": list(rotation)})

    def write(self, path):
        while len(self.blob) % 4:
            self.blob.append(0)
        self.doc["buffers"] = [{"byteLength": len(self.blob),
                                "uri": "data:application/octet-stream;base64," +
                                       base64.b64encode(bytes(self.blob)).decode("ascii")}]
        if self.extensions:
            self.doc["extensionsUsed"] = sorted(self.extensions)
        if not self.doc["cameras"]:
            del self.doc["cameras"]
        with open(path, "w") as f:
            json.dump(self.doc, f, indent=1)
            f.write("\n")


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def quads(quad_list):
    """Quads (a,b,c,d) -> triangles (a,b,c),(a,c,d) with six own vertices and face normals."""
    pos, nrm = [], []
    for a, b, c, d in quad_list:
        n = normalize(cross(sub(b, a), sub(c, a)))
        pos += [a, b, c, a, c, d]
        nrm += [n] * 6
    return pos, nrm, list(range(len(pos)))


# Box corners of the shared cbox.gltf (float32 values); faces index them as in that file.
SHORT_BOX = [(0.704602957, 0.0, 0.170820087), (0.704602957, 0.600000024, 0.170820087),
             (0.529179931, 0.600000024, 0.744602919), (0.529179931, 0.0, 0.744602919),
             (0.130820081, 0.0, -0.00460293842), (-0.044602938, 0.0, 0.569179893),
             (-0.044602938, 0.600000024, 0.569179893), (0.130820081, 0.600000024, -0.00460293842)]
TALL_BOX = [(-0.135820091, 0.0, -0.664602935), (-0.135820091, 1.20000005, -0.664602935),
            (0.039602939, 1.20000005, -0.0908200815), (0.039602939, 0.0, -0.0908200815),
            (-0.709602952, 0.0, -0.489179909), (-0.534179926, 0.0, 0.0846029371),
            (-0.534179926, 1.20000005, 0.0846029371), (-0.709602952, 1.20000005, -0.489179909)]
BOX_FACES = [(0, 1, 2, 3), (4, 5, 6, 7), (7, 6, 2, 1), (4, 0, 3, 5), (5, 3, 2, 6), (4, 7, 1, 0)]


def box(corners):
    return quads([[corners[i] for i in f] for f in BOX_FACES])


def icosphere(level):
    """Unit icosphere, counter-clockwise seen from outside, shared vertices (closed)."""
    t = (1.0 + math.sqrt(5.0)) / 2.0
    verts = [normalize(v) for v in [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t),
                                    (0, 1, t), (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1),
                                    (-t, 0, -1), (-t, 0, 1)]]
    tris = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
            (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
            (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        cache = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                verts.append(normalize([verts[a][i] + verts[b][i] for i in range(3)]))
                cache[key] = len(verts) - 1
            return cache[key]

        nxt = []
        for a, b, c in tris:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            nxt += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        tris = nxt
    return verts, tris


def cornell(glossy):
    w = GltfWriter()
    white = w.material("white", (0.725, 0.71, 0.68))
    red = w.material("red", (0.63, 0.065, 0.05))
    green = w.material("green", (0.14, 0.45, 0.091))
    light = w.material("light", (0.0, 0.0, 0.0), emission=(17.0, 12.0, 4.0))
    w.mesh("floor", *quads([[(-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)]]), white)
    w.mesh("ceiling", *quads([[(-1, 2, -1), (1, 2, -1), (1, 2, 1), (-1, 2, 1)]]), white)
    w.mesh("back", *quads([[(-1, 0, -1), (1, 0, -1), (1, 2, -1), (-1, 2, -1)]]), white)
    w.mesh("left", *quads([[(-1, 0, 1), (-1, 0, -1), (-1, 2, -1), (-1, 2, 1)]]), red)
    w.mesh("right", *quads([[(1, 0, -1), (1, 0, 1), (1, 2, 1), (1, 2, -1)]]), green)
    if glossy:
        # Metals have no dielectric layer, so KHR_materials_specular is left at its default.
        metal = w.material("rough_metal", (0.9, 0.9, 0.9), metallic=1.0, roughness=0.3,
                           specular=None)
        mirror = w.material("mirror", (0.95, 0.95, 0.95), metallic=1.0, roughness=0.0,
                            specular=None)
        verts, tris = icosphere(3)
        centre, radius = (0.33, 0.3, 0.37), 0.3
        pos = [[centre[i] + radius * v[i] for i in range(3)] for v in verts]
        w.mesh("mirror_sphere", pos, verts, [i for t in tris for i in t], mirror)
        w.mesh("tallbox", *box(TALL_BOX), metal)
    else:
        w.mesh("shortbox", *box(SHORT_BOX), white)
        w.mesh("tallbox", *box(TALL_BOX), white)
    w.mesh("light", *quads([[(-0.235, 1.98, -0.22), (0.235, 1.98, -0.22), (0.235, 1.98, 0.16),
                             (-0.235, 1.98, 0.16)]]), light)
    w.camera("camera", (0.0, 1.0, 6.8), math.radians(19.5))
    return w


def furnace():
    w = GltfWriter()
    mat = w.material("furnace", (0.5, 0.5, 0.5), emission=(0.5, 0.5, 0.5))
    verts, tris = icosphere(3)
    # Inward-facing: reversed winding and normals pointing to the centre.
    w.mesh("sphere", verts, [[-c for c in v] for v in verts],
           [i for a, b, c in tris for i in (a, c, b)], mat)
    w.camera("centre", (0.0, 0.0, 0.0), math.radians(45.0))
    return w


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    cornell(False).write(os.path.join(out, "cornell_box.gltf"))
    cornell(True).write(os.path.join(out, "glossy_cornell.gltf"))
    furnace().write(os.path.join(out, "furnace.gltf"))


if __name__ == "__main__":
    main()
