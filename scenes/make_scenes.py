#!/usr/bin/env python3
"""Writes gdpt's small test scenes as glTF 2.0 JSON files with embedded (data: URI) buffers.

    python3 scenes/make_scenes.py [output_dir]   (default: the folder of this script)

Outputs (see scenes/README.md):
  cornell_box.gltf    the Cornell box of ../shared/scenes/cbox (same vertices, materials, camera)
  glossy_cornell.gltf the same room, tall box rough metal (roughness 0.3), a mirror sphere
                      (roughness 0) in place of the short box
  furnace.gltf        closed inward-facing sphere, albedo 0.5, emission 0.5, camera at centre
  small_light.gltf    the Cornell box with the ceiling light shrunk to 5 % of its area and
                      20x its radiance (same power)
  indirect_gap.gltf   a Cornell room lit only through a door-like slit in its back wall from a
                      hidden light in a compartment behind it ("Veach ajar door")
  textured.gltf       the Cornell box with a fine sRGB checker/noise PNG texture on the floor
                      and back wall (texels ~1.2-1.6 pixels at 256x256)
  moving_box.gltf     the Cornell box whose short box slides and turns on the floor (3 s
                      animation: an object moving under a fixed camera)
  camera_move.gltf    the Cornell box seen by a camera that moves in and pans (2 s animation,
                      CUBICSPLINE)
  open_scene.gltf     48 small boxes on a large floor under a constant sky (an emissive dome)
                      and one small, bright area light

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
import zlib

FLOAT, UINT = 5126, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
LINEAR, REPEAT = 9729, 10497


class GltfWriter:
    """Accumulates meshes, materials and nodes and packs all data into one buffer."""

    def __init__(self):
        self.blob = bytearray()
        self.doc = {"asset": {"version": "2.0", "generator": "gdpt scenes/make_scenes.py"},
                    "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [],
                    "materials": [], "accessors": [], "bufferViews": [], "cameras": []}
        self.extensions = set()

    def _view(self, data, target=None):
        while len(self.blob) % 4:
            self.blob.append(0)
        view = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if target is not None:
            view["target"] = target
        self.doc["bufferViews"].append(view)
        self.blob += data
        return len(self.doc["bufferViews"]) - 1

    def _accessor(self, values, kind):
        if kind in ("VEC2", "VEC3"):
            n = int(kind[3])
            flat = [c for v in values for c in v]
            view = self._view(struct.pack("<%df" % len(flat), *flat), ARRAY_BUFFER)
            acc = {"bufferView": view, "componentType": FLOAT, "count": len(values), "type": kind}
            if kind == "VEC3":  # min/max are required for POSITION only
                acc["min"] = [min(v[i] for v in values) for i in range(n)]
                acc["max"] = [max(v[i] for v in values) for i in range(n)]
        elif kind in ("TIME", "OUT3", "OUT4"):  # animation sampler input / outputs
            n = {"TIME": 1, "OUT3": 3, "OUT4": 4}[kind]
            flat = list(values) if n == 1 else [c for v in values for c in v]
            view = self._view(struct.pack("<%df" % len(flat), *flat))
            acc = {"bufferView": view, "componentType": FLOAT, "count": len(flat) // n,
                   "type": {1: "SCALAR", 3: "VEC3", 4: "VEC4"}[n]}
            if n == 1:  # glTF 2.0 §3.11: an input accessor MUST have min and max
                acc["min"], acc["max"] = [min(flat)], [max(flat)]
        else:
            view = self._view(struct.pack("<%dI" % len(values), *values), ELEMENT_ARRAY_BUFFER)
            acc = {"bufferView": view, "componentType": UINT, "count": len(values), "type": "SCALAR"}
        # Unpacked float32 bounds so that min/max match the stored data exactly.
        if "min" in acc:
            acc["min"] = [struct.unpack("<f", struct.pack("<f", x))[0] for x in acc["min"]]
            acc["max"] = [struct.unpack("<f", struct.pack("<f", x))[0] for x in acc["max"]]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def texture(self, name, png):
        """An embedded PNG (sRGB when used as baseColorTexture) with a REPEAT/linear sampler."""
        self.doc.setdefault("images", []).append({"name": name, "mimeType": "image/png",
                                                  "bufferView": self._view(png)})
        samplers = self.doc.setdefault("samplers", [])
        if not samplers:
            samplers.append({"magFilter": LINEAR, "minFilter": LINEAR,
                             "wrapS": REPEAT, "wrapT": REPEAT})
        self.doc.setdefault("textures", []).append(
            {"name": name, "sampler": 0, "source": len(self.doc["images"]) - 1})
        return len(self.doc["textures"]) - 1

    def material(self, name, base, metallic=0.0, roughness=1.0, specular=0.0, emission=None,
                 texture=None):
        """specular=None leaves KHR_materials_specular out (its default factor is 1).
        texture: index of a baseColorTexture (TEXCOORD_0), multiplied by base."""
        m = {"name": name, "doubleSided": False,
             "pbrMetallicRoughness": {"baseColorFactor": list(base) + [1.0],
                                      "metallicFactor": metallic, "roughnessFactor": roughness}}
        if texture is not None:
            m["pbrMetallicRoughness"]["baseColorTexture"] = {"index": texture}
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

    def animation(self, name, channels):
        """channels: (node index, path, interpolation, key times, output values)."""
        anim = {"name": name, "channels": [], "samplers": []}
        for node, path, interpolation, times, values in channels:
            anim["samplers"].append({"input": self._accessor(times, "TIME"),
                                     "output": self._accessor(values,
                                                              "OUT4" if path == "rotation" else "OUT3"),
                                     "interpolation": interpolation})
            anim["channels"].append({"sampler": len(anim["samplers"]) - 1,
                                     "target": {"node": node, "path": path}})
        self.doc.setdefault("animations", []).append(anim)

    def mesh(self, name, positions, normals, indices, material, uvs=None):
        prim = {"attributes": {"POSITION": self._accessor(positions, "VEC3"),
                               "NORMAL": self._accessor(normals, "VEC3")},
                "indices": self._accessor(indices, "SCALAR"), "material": material, "mode": 4}
        if uvs is not None:
            prim["attributes"]["TEXCOORD_0"] = self._accessor(uvs, "VEC2")
        self.doc["meshes"].append({"name": name, "primitives": [prim]})
        return self.node({"name": name, "mesh": len(self.doc["meshes"]) - 1})

    def node(self, node, root=True):
        """Adds a node (a root of the scene unless root=False); returns its index."""
        self.doc["nodes"].append(node)
        index = len(self.doc["nodes"]) - 1
        if root:
            self.doc["scenes"][0]["nodes"].append(index)
        return index

    def camera(self, name, position, yfov, aspect=1.0, rotation=(0.0, 0.0, 0.0, 1.0)):
        self.doc["cameras"].append({"name": name, "type": "perspective",
                                    "perspective": {"yfov": yfov, "aspectRatio": aspect,
                                                    "znear": 0.01}})
        return self.node({"name": name, "camera": len(self.doc["cameras"]) - 1,
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


def png_rgb(width, height, rows):
    """8-bit RGB PNG bytes (no interlace, filter type 1 'Sub' on every row) of rows of
    (r, g, b) tuples, written with zlib and struct only."""
    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    raw = bytearray()
    for row in rows:
        raw.append(1)
        prev = (0, 0, 0)
        for px in row:
            raw += bytes((px[i] - prev[i]) & 0xFF for i in range(3))
            prev = px
    return (b"\x89PNG\r\n\x1a\n" +
            chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b""))


def hash32(x):
    """A fixed integer hash (lowbias32), so the texture never depends on Python's RNG."""
    x &= 0xFFFFFFFF
    x ^= x >> 16
    x = (x * 0x7FEB352D) & 0xFFFFFFFF
    x ^= x >> 15
    x = (x * 0x846CA68B) & 0xFFFFFFFF
    return x ^ (x >> 16)


TEX_SIZE = 256
# Texture repeats per metre: a texel is 1 / (0.3 * 256) = 1.3 cm, about 1.24 pixels on the
# back wall (7.8 m from the camera, 2 * 7.8 * tan(9.75 deg) = 2.68 m over 256 pixels) and
# 1.2-1.6 pixels across the floor, whose depth is foreshortened to a fraction of a pixel.
TEX_PER_METRE = 0.3


def detail_texture():
    """256 x 256 sRGB texels: a checkerboard of 4-texel cells (warm light / cool dark) times
    per-texel hashed noise (four levels, 0.78..1.0) and a 1-texel dark line every 32 texels.
    Every period divides 256, so the texture tiles seamlessly under REPEAT."""
    light, dark = (225, 212, 190), (70, 84, 110)
    rows = []
    for y in range(TEX_SIZE):
        row = []
        for x in range(TEX_SIZE):
            base = light if ((x >> 2) + (y >> 2)) & 1 == 0 else dark
            k = 0.78 + 0.0733 * (hash32(y * TEX_SIZE + x) & 3)
            if x % 32 == 0 or y % 32 == 0:
                k *= 0.45
            row.append(tuple(min(255, int(round(c * k))) for c in base))
        rows.append(row)
    return png_rgb(TEX_SIZE, TEX_SIZE, rows)


# Ceiling light of the Cornell box (cbox.gltf) and its radiance, W/(m^2 sr).
CORNELL_LIGHT = [(-0.235, 1.98, -0.22), (0.235, 1.98, -0.22), (0.235, 1.98, 0.16),
                 (-0.235, 1.98, 0.16)]
CORNELL_RADIANCE = (17.0, 12.0, 4.0)


def cornell(glossy, light_area=1.0, textured=False, short_box=True):
    """light_area: fraction of the original light's area; the light shrinks about its centre
    and its radiance grows by 1 / light_area, so its power stays the same.
    textured: floor and back wall get detail_texture() (white factor) instead of white."""
    w = GltfWriter()
    white = w.material("white", (0.725, 0.71, 0.68))
    red = w.material("red", (0.63, 0.065, 0.05))
    green = w.material("green", (0.14, 0.45, 0.091))
    light = w.material("light", (0.0, 0.0, 0.0),
                       emission=[c / light_area for c in CORNELL_RADIANCE])
    floor = quads([[(-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)]])
    back = quads([[(-1, 0, -1), (1, 0, -1), (1, 2, -1), (-1, 2, -1)]])
    if textured:
        detail = w.material("white_detail", (1.0, 1.0, 1.0),
                            texture=w.texture("checker_noise", detail_texture()))
        # uv = world * TEX_PER_METRE; v runs down the back wall and on towards the camera
        # across the floor, so the pattern folds continuously over the edge between them.
        # u crosses 0 at x = 0, so REPEAT wrapping is used.
        w.mesh("floor", *floor, detail,
               uvs=[(TEX_PER_METRE * p[0], TEX_PER_METRE * (3.0 + p[2])) for p in floor[0]])
    else:
        w.mesh("floor", *floor, white)
    w.mesh("ceiling", *quads([[(-1, 2, -1), (1, 2, -1), (1, 2, 1), (-1, 2, 1)]]), white)
    if textured:
        w.mesh("back", *back, detail,
               uvs=[(TEX_PER_METRE * p[0], TEX_PER_METRE * (2.0 - p[1])) for p in back[0]])
    else:
        w.mesh("back", *back, white)
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
        if short_box:
            w.mesh("shortbox", *box(SHORT_BOX), white)
        w.mesh("tallbox", *box(TALL_BOX), white)
    s = math.sqrt(light_area)
    centre = [sum(p[i] for p in CORNELL_LIGHT) / 4.0 for i in range(3)]
    w.mesh("light", *quads([[[centre[i] + s * (p[i] - centre[i]) for i in range(3)]
                             for p in CORNELL_LIGHT]]), light)
    w.camera("camera", (0.0, 1.0, 6.8), math.radians(19.5))
    return w


# indirect_gap: a door-like slit in the back wall (x in GAP_X, floor to GAP_TOP) of a Cornell
# room; behind the wall (thickness WALL) lies a closed compartment (z down to COMP_BACK).
GAP_X, GAP_TOP, WALL, COMP_BACK = (0.46, 0.54), 1.6, 0.02, -1.6


def wall_with_gap(z, facing_back):
    """The wall plane z (x in [-1, 1], y in [0, 2]) minus the slit, as three quads facing
    +Z (into the room), or -Z (into the compartment) when facing_back."""
    g0, g1 = GAP_X
    rects = [(-1, g0, 0, 2), (g1, 1, 0, 2), (g0, g1, GAP_TOP, 2)]
    out = []
    for x0, x1, y0, y1 in rects:
        q = [(x0, y0, z), (x1, y0, z), (x1, y1, z), (x0, y1, z)]
        out.append(q[::-1] if facing_back else q)
    return out


def indirect_gap():
    """Veach's "ajar door" situation: the only light hangs on the compartment side of the
    back wall, facing away from the room, and lights the compartment; light reaches the room
    only through the slit, after at least one bounce in the compartment. The camera sees
    through the slit to the lit compartment wall but never sees the light."""
    w = GltfWriter()
    white = w.material("white", (0.725, 0.71, 0.68))
    red = w.material("red", (0.63, 0.065, 0.05))
    green = w.material("green", (0.14, 0.45, 0.091))
    light = w.material("light", (0.0, 0.0, 0.0), emission=(1275.0, 900.0, 300.0))
    g0, g1 = GAP_X
    zb = -1.0 - WALL  # compartment side of the wall
    w.mesh("floor", *quads([[(-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)]]), white)
    w.mesh("ceiling", *quads([[(-1, 2, -1), (1, 2, -1), (1, 2, 1), (-1, 2, 1)]]), white)
    w.mesh("back", *quads(wall_with_gap(-1.0, False)), white)
    w.mesh("left", *quads([[(-1, 0, 1), (-1, 0, -1), (-1, 2, -1), (-1, 2, 1)]]), red)
    w.mesh("right", *quads([[(1, 0, -1), (1, 0, 1), (1, 2, 1), (1, 2, -1)]]), green)
    w.mesh("shortbox", *box(SHORT_BOX), white)
    w.mesh("tallbox", *box(TALL_BOX), white)
    # The slit's jambs and lintel close the wall's thickness.
    w.mesh("gap_jambs", *quads([[(g0, 0, -1), (g0, 0, zb), (g0, GAP_TOP, zb), (g0, GAP_TOP, -1)],
                                [(g1, 0, zb), (g1, 0, -1), (g1, GAP_TOP, -1), (g1, GAP_TOP, zb)],
                                [(g0, GAP_TOP, -1), (g0, GAP_TOP, zb), (g1, GAP_TOP, zb),
                                 (g1, GAP_TOP, -1)]]), white)
    # The compartment: its walls span z in [COMP_BACK, -1], which also closes the wall's
    # thickness along its outer edges.
    c = COMP_BACK
    w.mesh("compartment", *quads(wall_with_gap(zb, True) + [
        [(-1, 0, -1), (1, 0, -1), (1, 0, c), (-1, 0, c)],      # floor (+Y)
        [(-1, 2, c), (1, 2, c), (1, 2, -1), (-1, 2, -1)],      # ceiling (-Y)
        [(-1, 0, c), (1, 0, c), (1, 2, c), (-1, 2, c)],        # back wall (+Z)
        [(-1, 0, -1), (-1, 0, c), (-1, 2, c), (-1, 2, -1)],    # left (+X)
        [(1, 0, c), (1, 0, -1), (1, 2, -1), (1, 2, c)]]), white)  # right (-X)
    # The light: 5 mm in front of the compartment side of the wall, facing -Z, left of the
    # slit so that no camera ray through the slit can touch it.
    zl = zb - 0.005
    w.mesh("light", *quads([[(0.2, 1.2, zl), (-0.8, 1.2, zl), (-0.8, 1.8, zl), (0.2, 1.8, zl)]]),
           light)
    w.camera("camera", (0.0, 1.0, 6.8), math.radians(19.5))
    return w


def yaw(degrees):
    """The quaternion (x, y, z, w) of a rotation about +Y."""
    h = math.radians(degrees) / 2.0
    return (0.0, math.sin(h), 0.0, math.cos(h))


def moving_box():
    """The Cornell box whose short box slides across the floor and turns: its mesh is stored
    about its centre under a node whose translation (LINEAR) and rotation (LINEAR, slerp) are
    animated over 3 s; at time 0 the box is where cornell_box.gltf has it."""
    w = cornell(False, short_box=False)
    white = w.doc["materials"].index(next(m for m in w.doc["materials"] if m["name"] == "white"))
    centre = [sum(p[i] for p in SHORT_BOX) / 8.0 for i in range(3)]
    pos, nrm, idx = box([[p[i] - centre[i] for i in range(3)] for p in SHORT_BOX])
    child = w.mesh("shortbox", pos, nrm, idx, white)
    w.doc["scenes"][0]["nodes"].remove(child)
    mover = w.node({"name": "shortbox_motion", "translation": centre, "children": [child]})
    c = centre
    w.animation("slide", [
        (mover, "translation", "LINEAR", [0.0, 1.0, 2.0, 3.0],
         [c, (c[0] - 0.35, c[1], c[2] - 0.1), (c[0] - 0.5, c[1], c[2] + 0.15), (c[0] - 0.2, c[1], c[2] + 0.2)]),
        (mover, "rotation", "LINEAR", [0.0, 1.5, 3.0], [yaw(0.0), yaw(45.0), yaw(90.0)])])
    return w


def camera_move():
    """The Cornell box seen by a camera that moves in and to the right while it turns left
    (CUBICSPLINE translation and rotation over 2 s, zero tangents at both ends: it starts and
    stops smoothly); at time 0 the view is cornell_box.gltf's."""
    w = cornell(False)
    cam = next(i for i, n in enumerate(w.doc["nodes"]) if n.get("name") == "camera")
    zero3, zero4 = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0)
    start, end = (0.0, 1.0, 6.8), (0.45, 1.05, 5.6)
    w.animation("move_in", [
        (cam, "translation", "CUBICSPLINE", [0.0, 2.0], [zero3, start, zero3, zero3, end, zero3]),
        (cam, "rotation", "CUBICSPLINE", [0.0, 2.0], [zero4, yaw(0.0), zero4, zero4, yaw(6.0), zero4])])
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


def oriented_box(centre, size, yaw_deg):
    """A closed box of `size` (x, y, z) standing on y = 0 at `centre` (x, z), turned by yaw_deg
    about +Y; faces wound counter-clockwise seen from outside."""
    c, s_ = math.cos(math.radians(yaw_deg)), math.sin(math.radians(yaw_deg))
    hx, hz = size[0] / 2.0, size[2] / 2.0

    def corner(ix, iy, iz):
        x, z = (2 * ix - 1) * hx, (2 * iz - 1) * hz
        return (centre[0] + c * x + s_ * z, iy * size[1], centre[1] - s_ * x + c * z)

    faces = []
    for axis in range(3):
        for side in (0, 1):
            quad = []
            for u, v in ((0, 0), (1, 0), (1, 1), (0, 1)):
                idx = [0, 0, 0]
                idx[axis] = side
                idx[(axis + 1) % 3], idx[(axis + 2) % 3] = u, v
                quad.append(corner(*idx))
            # Wind it so that its normal points away from the box's centre.
            mid = [sum(q[i] for q in quad) / 4.0 for i in range(3)]
            n = cross(sub(quad[1], quad[0]), sub(quad[2], quad[0]))
            centre3 = (centre[0], size[1] / 2.0, centre[1])
            if sum(n[i] * (mid[i] - centre3[i]) for i in range(3)) < 0.0:
                quad.reverse()
            faces.append(quad)
    return quads(faces)


def open_scene():
    """Dozens of small boxes on a large floor under a constant sky (an emissive dome) and one
    small, bright area light: an outdoor-like scene, open to the sky."""
    w = GltfWriter()
    floor = w.material("floor", (0.5, 0.5, 0.5))
    albedos = [(0.7, 0.7, 0.7), (0.7, 0.25, 0.2), (0.25, 0.6, 0.25), (0.25, 0.35, 0.7), (0.75, 0.65, 0.3)]
    box_mats = [w.material("box%d" % i, a) for i, a in enumerate(albedos)]
    sky = w.material("sky", (0.0, 0.0, 0.0), emission=(0.25, 0.32, 0.45))
    lamp = w.material("lamp", (0.0, 0.0, 0.0), emission=(400.0, 330.0, 240.0))
    # The floor: 40 m x 40 m, facing up.
    pos, nrm, idx = quads([[(-20.0, 0.0, -20.0), (-20.0, 0.0, 20.0), (20.0, 0.0, 20.0), (20.0, 0.0, -20.0)]])
    w.mesh("floor", pos, nrm, idx, floor)
    # 48 boxes (0.15-0.6 m) scattered by a hash over a 7 m x 7 m patch in front of the camera.
    boxes = {m: ([], [], []) for m in range(len(box_mats))}
    for i in range(48):
        h = [hash32(i * 7 + k) / 2.0 ** 32 for k in range(6)]
        centre = (-3.5 + 7.0 * h[0], -4.0 + 7.0 * h[1])
        size = (0.15 + 0.45 * h[2], 0.15 + 0.6 * h[3], 0.15 + 0.45 * h[4])
        bp, bn, _ = oriented_box(centre, size, 90.0 * h[5])
        m = i % len(box_mats)
        base = len(boxes[m][0])
        boxes[m][0].extend(bp)
        boxes[m][1].extend(bn)
        boxes[m][2].extend(range(base, base + len(bp)))
    for m, (bp, bn, bi) in boxes.items():
        w.mesh("boxes%d" % m, bp, bn, bi, box_mats[m])
    # A 0.3 m x 0.3 m lamp 3 m above the patch, facing down.
    pos, nrm, idx = quads([[(-0.15, 3.0, -1.15), (0.15, 3.0, -1.15), (0.15, 3.0, -0.85), (-0.15, 3.0, -0.85)]])
    w.mesh("lamp", pos, nrm, idx, lamp)
    # The sky: an inward-facing dome of radius 60 m (icosphere, 320 triangles).
    verts, tris = icosphere(2)
    w.mesh("sky", [[60.0 * c for c in v] for v in verts], [[-c for c in v] for v in verts],
           [i for a, b, c in tris for i in (a, c, b)], sky)
    # Camera 2.2 m up, 6 m back, looking 22 degrees down at the patch.
    pitch = math.radians(-22.0)
    w.camera("camera", (0.0, 2.2, 5.0), math.radians(45.0),
             rotation=(math.sin(pitch / 2.0), 0.0, 0.0, math.cos(pitch / 2.0)))
    return w


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    cornell(False).write(os.path.join(out, "cornell_box.gltf"))
    cornell(True).write(os.path.join(out, "glossy_cornell.gltf"))
    furnace().write(os.path.join(out, "furnace.gltf"))
    cornell(False, light_area=0.05).write(os.path.join(out, "small_light.gltf"))
    indirect_gap().write(os.path.join(out, "indirect_gap.gltf"))
    cornell(False, textured=True).write(os.path.join(out, "textured.gltf"))
    moving_box().write(os.path.join(out, "moving_box.gltf"))
    camera_move().write(os.path.join(out, "camera_move.gltf"))
    open_scene().write(os.path.join(out, "open_scene.gltf"))


if __name__ == "__main__":
    main()
