#!/usr/bin/env python3
"""Renders an environment-lit gpu-render scene with Mitsuba 3's path tracer, as the
independent reference of tests/integration/environment_reference.rs: path_reference.py's scene
subset (Lambert and emissive materials, polygons, spheres) plus `[environment] map`
with `rotation` and `scale`, as Mitsuba's `envmap` emitter.

Mapping (docs/path-tracing.md, "Environment maps"): our direction-to-(u, v)
convention is Mitsuba's envmap's, u = atan2(x, -z) / 2pi, v = acos(y) / pi, and our
`rotation` (degrees about +y, right-handed) is its `to_world` rotate([0, 1, 0],
rotation). Both look the map up bilinearly with Mitsuba's texel convention (column i's
centre at u = (i + 1/2)/width, wrapping; row j at v = j/(height - 1)), so the map is
given to Mitsuba as it is. (Until gpu-render interpolated, the map went to Mitsuba
enlarged 8 times by texel replication, to approximate a nearest lookup.)

Run from the repository root (tested with mitsuba 3.6.4):

    python3 -m venv /tmp/mi-venv && /tmp/mi-venv/bin/pip install mitsuba==3.6.4 numpy
    /tmp/mi-venv/bin/python scripts/mitsuba/environment_reference.py \\
        tests/fixtures/mitsuba/env-lambert.toml tests/fixtures/mitsuba/env-lambert-48.exr \\
        --size 48 --spp 65536
"""

import argparse
import os
import sys
import tempfile
import tomllib

import mitsuba as mi
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import path_reference  # noqa: E402  (sets the scalar_rgb variant)

def environment_emitter(scene_path, environment, work):
    """The envmap emitter of `[environment]`, its map (as RGB float) written into `work`."""
    unknown = set(environment) - {"map", "rotation", "scale", "ambient"}
    if unknown:
        path_reference.fail(f"[environment]: {sorted(unknown)} not supported")
    source = os.path.join(os.path.dirname(scene_path), environment["map"])
    texels = np.array(mi.Bitmap(source).convert(mi.Bitmap.PixelFormat.RGB,
                                                mi.Struct.Type.Float32, False))
    path = os.path.join(work, "map.exr")
    mi.Bitmap(texels.astype(np.float32)).write(path)
    scale = environment.get("scale", 1.0)
    if isinstance(scale, list):
        if len(set(scale)) != 1:
            path_reference.fail("a coloured scale is not supported (Mitsuba's is a number)")
        scale = scale[0]
    return {
        "type": "envmap",
        "filename": path,
        "scale": float(scale),
        "to_world": mi.ScalarTransform4f().rotate([0, 1, 0], environment.get("rotation", 0.0)),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("output")
    parser.add_argument("--size", type=int, default=48, help="image width in pixels")
    parser.add_argument("--spp", type=int, default=32768)
    args = parser.parse_args()
    with open(args.scene, "rb") as f:
        scene = tomllib.load(f)
    environment = scene.pop("environment", None)
    if not environment or "map" not in environment:
        path_reference.fail("the scene has no [environment] map")
    description = path_reference.scene_dict(scene, args.size, args.spp)
    work = tempfile.mkdtemp()
    description["environment"] = environment_emitter(args.scene, environment, work)
    for key, value in list(description.items()):
        if isinstance(value, tuple):
            mesh, bsdf, emitter = value
            path = os.path.join(work, f"{key}.ply")
            mesh.write_ply(path)
            entry = {"type": "ply", "filename": path, "bsdf": bsdf, "face_normals": True}
            if emitter:
                entry["emitter"] = emitter
            description[key] = entry
    image = mi.render(mi.load_dict(description))
    mi.Bitmap(image).write(args.output)
    array = np.array(image)
    print(f"wrote {args.output}: {array.shape[1]}x{array.shape[0]}, {args.spp} spp, "
          f"mean {array.mean(axis=(0, 1))}")


if __name__ == "__main__":
    main()
