#!/usr/bin/env python3
"""Writes the models shipped in scenes/models/ (ours, MIT OR Apache-2.0), with nothing
but the Python standard library:

- torus.obj + torus.mtl: a low-poly torus of 16 x 8 quads (per-vertex normals and
  texture coordinates) in a glazed Blinn-Phong material, standing on a hexagonal
  plinth whose top and bottom are single six-sided faces, with the checker texture.
- vase.gltf: a faceted vase (a lathe of 10 sides, flat-shaded: each facet has its own
  vertices and normal; the bottom is a TRIANGLE_FAN primitive), placed twice by nodes
  under a common parent (one mesh, two instances), in a glazed glTF PBR material; one
  buffer embedded as a base64 data URI.

Run from the repository root: python3 scripts/make_models.py
"""

import base64
import json
import math
import os
import struct

OUT = os.path.join(os.path.dirname(__file__), "..", "scenes", "models")


def torus_obj():
    major, minor, around, across = 1.0, 0.35, 16, 8
    lines = [
        "# A low-poly torus on a hexagonal plinth, made by scripts/make_models.py.",
        "# Ours: MIT OR Apache-2.0.",
        "mtllib torus.mtl",
        "o torus",
    ]
    # (around + 1) x (across + 1) vertices: the seams are duplicated for the UVs.
    for i in range(around + 1):
        u = i / around
        phi = 2 * math.pi * u
        for j in range(across + 1):
            v = j / across
            theta = 2 * math.pi * v
            cx, cz = math.cos(phi), math.sin(phi)
            x = (major + minor * math.cos(theta)) * cx
            y = minor * math.sin(theta) + 0.55
            z = (major + minor * math.cos(theta)) * cz
            lines.append(f"v {x:.6f} {y:.6f} {z:.6f}")
            lines.append(f"vn {math.cos(theta) * cx:.6f} {math.sin(theta):.6f} {math.cos(theta) * cz:.6f}")
            lines.append(f"vt {u:.6f} {v:.6f}")
    lines.append("usemtl glaze")
    stride = across + 1
    for i in range(around):
        for j in range(across):
            a = i * stride + j + 1
            b = (i + 1) * stride + j + 1
            # Counter-clockwise seen from outside the tube.
            quad = [a, a + 1, b + 1, b]
            lines.append("f " + " ".join(f"{k}/{k}/{k}" for k in quad))
    # The plinth: a hexagonal prism, radius 0.9, from y = -0.2 to y = 0.2.
    base = (around + 1) * (across + 1)
    lines.append("o plinth")
    for y in (-0.2, 0.2):
        for k in range(6):
            angle = 2 * math.pi * k / 6
            lines.append(f"v {0.9 * math.cos(angle):.6f} {y:.6f} {0.9 * math.sin(angle):.6f}")
            lines.append(f"vt {0.5 + 0.5 * math.cos(angle):.6f} {0.5 + 0.5 * math.sin(angle):.6f}")
    lines.append("usemtl stone")
    bottom = [base + k + 1 for k in range(6)]
    top = [base + 6 + k + 1 for k in range(6)]
    lines.append("f " + " ".join(f"{k}/{k}" for k in reversed(top)))
    lines.append("f " + " ".join(f"{k}/{k}" for k in bottom))
    for k in range(6):
        n = (k + 1) % 6
        quad = [bottom[k], top[k], top[n], bottom[n]]
        lines.append("f " + " ".join(f"{q}/{q}" for q in quad))
    mtl = [
        "# Materials of torus.obj, made by scripts/make_models.py. Ours: MIT OR Apache-2.0.",
        "newmtl glaze",
        "Kd 0.60 0.18 0.08",
        "Ks 0.30 0.30 0.30",
        "Ns 80",
        "illum 2",
        "",
        "newmtl stone",
        "Kd 0.9 0.9 0.9",
        "illum 1",
        "map_Kd ../textures/checker.png",
    ]
    with open(os.path.join(OUT, "torus.obj"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(OUT, "torus.mtl"), "w") as f:
        f.write("\n".join(mtl) + "\n")


def vase_gltf():
    profile = [(0.30, 0.0), (0.42, 0.12), (0.50, 0.40), (0.42, 0.70),
               (0.24, 0.92), (0.20, 1.05), (0.28, 1.20)]
    sides = 10
    positions, normals, indices = [], [], []

    def ring(r, y, k):
        a = 2 * math.pi * k / sides
        return (r * math.cos(a), y, -r * math.sin(a))

    for s in range(len(profile) - 1):
        (r0, y0), (r1, y1) = profile[s], profile[s + 1]
        for k in range(sides):
            quad = [ring(r0, y0, k), ring(r0, y0, k + 1), ring(r1, y1, k + 1), ring(r1, y1, k)]
            e1 = [quad[1][i] - quad[0][i] for i in range(3)]
            e2 = [quad[3][i] - quad[0][i] for i in range(3)]
            n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
            length = math.sqrt(sum(c * c for c in n))
            n = [c / length for c in n]
            first = len(positions)
            positions.extend(quad)
            normals.extend([n] * 4)
            indices.extend([first, first + 1, first + 2, first, first + 2, first + 3])
    # The bottom: a fan around its centre, facing down.
    fan_first = len(positions)
    positions.append((0.0, 0.0, 0.0))
    for k in range(sides, -1, -1):
        positions.append(ring(profile[0][0], 0.0, k))
    normals.extend([(0.0, -1.0, 0.0)] * (sides + 2))
    fan = list(range(fan_first, fan_first + sides + 2))

    def pack(fmt, rows):
        return b"".join(struct.pack(fmt, *row) for row in rows)

    chunks = [
        pack("<3f", positions),
        pack("<3f", normals),
        pack("<H", [(i,) for i in indices]),
        pack("<H", [(i,) for i in fan]),
    ]
    blob, views = b"", []
    for chunk in chunks:
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(chunk)})
        blob += chunk + b"\0" * (-len(chunk) % 4)
    low = [min(p[i] for p in positions) for i in range(3)]
    high = [max(p[i] for p in positions) for i in range(3)]
    count = len(positions)
    gltf = {
        "asset": {"version": "2.0", "generator": "gpu-render scripts/make_models.py",
                  "copyright": "gpu-render authors, MIT OR Apache-2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {"name": "shelf", "translation": [0.0, 0.0, 0.0], "children": [1, 2]},
            {"name": "vase", "mesh": 0},
            {"name": "small vase", "mesh": 0, "translation": [0.9, 0.0, 0.3],
             "rotation": [0.0, math.sin(math.radians(18) / 2), 0.0, math.cos(math.radians(18) / 2)],
             "scale": [0.6, 0.6, 0.6]},
        ],
        "meshes": [{"name": "vase", "primitives": [
            {"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0},
            {"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 3, "material": 0, "mode": 6},
        ]}],
        "materials": [{"name": "celadon glaze", "pbrMetallicRoughness": {
            "baseColorFactor": [0.36, 0.62, 0.55, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.3}}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3", "min": low, "max": high},
            {"bufferView": 1, "componentType": 5126, "count": count, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5123, "count": len(indices), "type": "SCALAR"},
            {"bufferView": 3, "componentType": 5123, "count": len(fan), "type": "SCALAR"},
        ],
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    }
    with open(os.path.join(OUT, "vase.gltf"), "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    torus_obj()
    vase_gltf()
