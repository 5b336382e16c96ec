#!/usr/bin/env python3
"""Writes a large textured glTF 2.0 binary (.glb) for size tests and benchmarks.

A rippled terrain of about N triangles (a square grid of shared vertices, two triangles per
cell) under a camera, textured with a procedural checker image (PNG, embedded) through
TEXCOORD_0, and lit by an emissive quad above it. Python's standard library only, so that it
runs wherever the project's packages are installed; gdpt's loader is not involved in writing it.

  scripts/make-large-scene.py --triangles 5000000 -o terrain_5m.glb
"""
import argparse
import array
import json
import math
import struct
import sys
import zlib


def png_rgb(width, height, pixel):
    """An 8-bit RGB PNG of pixel(x, y) -> (r, g, b)."""
    rows = bytearray()
    for y in range(height):
        rows.append(0)  # filter: none
        for x in range(width):
            rows.extend(pixel(x, y))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(bytes(rows), 6)) +
            chunk(b"IEND", b""))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--triangles", type=int, default=5_000_000,
                        help="about this many terrain triangles (default 5000000)")
    parser.add_argument("--texture", type=int, default=256, help="texture width and height in pixels (256)")
    parser.add_argument("-o", "--output", required=True, help="the .glb to write")
    args = parser.parse_args()
    if args.triangles < 2 or args.texture < 1:
        parser.error("--triangles must be at least 2 and --texture at least 1")
    if not args.output.endswith(".glb"):
        parser.error("-o must name a .glb file")

    n = max(1, int(math.sqrt(args.triangles / 2.0)))  # cells per side
    side = n + 1
    step = 2.0 / n
    positions = array.array("f")
    uvs = array.array("f")
    for j in range(side):
        z = -1.0 + j * step
        cz = math.cos(7.0 * z)
        for i in range(side):
            x = -1.0 + i * step
            y = 0.05 * math.sin(9.0 * x) * cz + 0.01 * math.sin(53.0 * x + 31.0 * z)
            positions.extend((x, y, z))
            uvs.extend((i / n, j / n))
    indices = array.array("I")
    for j in range(n):
        row = j * side
        for i in range(n):
            a = row + i
            indices.extend((a, a + side, a + 1, a + 1, a + side, a + side + 1))
    # The light: a quad above the middle, facing down.
    light_positions = array.array("f", [-0.3, 1.5, -0.3, 0.3, 1.5, -0.3, 0.3, 1.5, 0.3, -0.3, 1.5, 0.3])
    light_indices = array.array("I", [0, 1, 2, 0, 2, 3])
    cells = 8
    texture = png_rgb(args.texture, args.texture,
                      lambda x, y: (200, 180, 60) if ((x * cells // args.texture) + (y * cells // args.texture)) % 2
                      else (40, 90, 160))
    if sys.byteorder != "little":
        for a in (positions, uvs, indices, light_positions, light_indices):
            a.byteswap()

    blob = bytearray()
    views = []

    def add_view(data, target=None):
        while len(blob) % 4:
            blob.append(0)
        view = {"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)}
        if target:
            view["target"] = target
        blob.extend(data)
        views.append(view)
        return len(views) - 1

    def bounds(values):
        return ([min(values[k::3]) for k in range(3)], [max(values[k::3]) for k in range(3)])

    lo, hi = bounds(positions)
    llo, lhi = bounds(light_positions)
    accessors = [
        {"bufferView": add_view(positions.tobytes(), 34962), "componentType": 5126, "count": len(positions) // 3,
         "type": "VEC3", "min": lo, "max": hi},
        {"bufferView": add_view(uvs.tobytes(), 34962), "componentType": 5126, "count": len(uvs) // 2, "type": "VEC2"},
        {"bufferView": add_view(indices.tobytes(), 34963), "componentType": 5125, "count": len(indices),
         "type": "SCALAR"},
        {"bufferView": add_view(light_positions.tobytes(), 34962), "componentType": 5126, "count": 4,
         "type": "VEC3", "min": llo, "max": lhi},
        {"bufferView": add_view(light_indices.tobytes(), 34963), "componentType": 5125, "count": 6,
         "type": "SCALAR"},
    ]
    image_view = add_view(texture)
    while len(blob) % 4:
        blob.append(0)
    doc = {
        "asset": {"version": "2.0", "generator": "gdpt scripts/make-large-scene.py"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            {"mesh": 0},
            {"mesh": 1},
            {"camera": 0, "translation": [0.0, 1.2, 2.2], "rotation": [-0.2588190, 0.0, 0.0, 0.9659258]},
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01, "aspectRatio": 1.0}}],
        "meshes": [
            {"name": "terrain", "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2,
                                                 "material": 0}]},
            {"name": "light", "primitives": [{"attributes": {"POSITION": 3}, "indices": 4, "material": 1}]},
        ],
        "materials": [
            {"name": "checker", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0,
                                                          "roughnessFactor": 1.0}},
            {"name": "light", "emissiveFactor": [1.0, 1.0, 1.0],
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 20.0}},
             "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0}},
        ],
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "textures": [{"source": 0}],
        "images": [{"bufferView": image_view, "mimeType": "image/png"}],
        "bufferViews": views,
        "accessors": accessors,
        "buffers": [{"byteLength": len(blob)}],
    }
    text = json.dumps(doc, separators=(",", ":")).encode()
    while len(text) % 4:
        text += b" "
    total = 12 + 8 + len(text) + 8 + len(blob)
    tmp = args.output + ".tmp"
    with open(tmp, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, total))
        f.write(struct.pack("<II", len(text), 0x4E4F534A) + text)
        f.write(struct.pack("<II", len(blob), 0x004E4942) + bytes(blob))
    import os
    os.replace(tmp, args.output)
    print(f"{args.output}: {len(indices) // 3 + 2} triangles ({n}x{n} cells), {len(positions) // 3 + 4} vertices, "
          f"{total / 2**20:.1f} MiB", file=sys.stderr)


if __name__ == "__main__":
    main()
