#!/usr/bin/env python3
"""Renders a gpu-render scene file with Mitsuba 3's path tracer, as the independent
reference of tests/integration/path_reference.rs (the path integrator against another renderer).

Reads the subset of the scene format the reference scenes use: [render], [camera],
Lambert and emissive materials, polygons (as triangle fans of convex quads) and
spheres; point lights, planes and other materials are refused. Writes a linear RGB
OpenEXR of the given size.

Mapping (docs/path-tracing.md): our Lambert surfaces reflect on both sides, so the
diffuse BSDF is wrapped in Mitsuba's `twosided`; our `max_depth` counts bounces after
the camera ray;
Mitsuba's counts path vertices, so it is ours + 2 (camera ray, hit, d bounces, the
light). Our flat emitters emit on the side their vertex order's right-hand normal
points to, as Mitsuba's area emitters do on their mesh's face normals. Both use a box
pixel filter. Mitsuba's Russian roulette starts at depth 5 (ours at 3): both are
unbiased, so the expectations agree.

Run from the repository root (tested with mitsuba 3.6.4):

    python3 -m venv /tmp/mi-venv && /tmp/mi-venv/bin/pip install mitsuba==3.6.4 numpy
    /tmp/mi-venv/bin/python scripts/mitsuba/path_reference.py scenes/cornell-box.toml \\
        tests/fixtures/mitsuba/cornell-box-32.exr --size 32 --spp 65536
"""

import argparse
import os
import sys
import tempfile
import tomllib

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")


def fail(message):
    sys.exit(f"path_reference.py: {message}")


def material_dict(name, material):
    kind = material.get("type")
    if kind == "lambert":
        albedo = material["albedo"]
        albedo = albedo if isinstance(albedo, list) else [albedo] * 3
        # Our surfaces reflect on both sides (shading happens on the side the ray
        # comes from); Mitsuba's BSDFs are one-sided unless wrapped.
        diffuse = {"type": "diffuse", "reflectance": {"type": "rgb", "value": albedo}}
        return {"type": "twosided", "material": diffuse}, None
    if kind == "emissive":
        radiance = material["radiance"]
        radiance = radiance if isinstance(radiance, list) else [radiance] * 3
        black = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0, 0, 0]}}
        return black, {"type": "area", "radiance": {"type": "rgb", "value": radiance}}
    fail(f"material {name}: type {kind!r} is not supported by this script")


def polygon_mesh(name, vertices):
    if len(vertices) < 3:
        fail(f"{name}: a polygon needs 3 vertices")
    faces = [[0, i, i + 1] for i in range(1, len(vertices) - 1)]
    mesh = mi.Mesh(name, vertex_count=len(vertices), face_count=len(faces),
                   has_vertex_normals=False, has_vertex_texcoords=False)
    params = mi.traverse(mesh)
    params["vertex_positions"] = np.array(vertices, dtype=np.float32).ravel()
    params["faces"] = np.array(faces, dtype=np.uint32).ravel()
    params.update()
    return mesh


def scene_dict(scene, size, spp):
    render = scene.get("render", {})
    depth = render.get("max_depth", 5)
    camera = scene["camera"]
    result = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": depth + 2, "hide_emitters": False},
        "sensor": {
            "type": "perspective",
            "fov_axis": "y",
            "fov": camera.get("fov_y_degrees", 45.0),
            "to_world": mi.ScalarTransform4f().look_at(
                origin=camera["eye"], target=camera["look_at"], up=camera.get("up", [0, 1, 0])
            ),
            "sampler": {"type": "independent", "sample_count": spp},
            "film": {
                "type": "hdrfilm",
                "width": size,
                "height": size * render.get("height", 480) // render.get("width", 640),
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
            },
        },
    }
    if scene.get("lights"):
        fail("point and directional lights are not supported by this script")
    materials = scene.get("materials", {})
    for i, obj in enumerate(scene.get("objects", [])):
        bsdf, emitter = material_dict(obj["material"], materials[obj["material"]])
        if obj["type"] == "polygon":
            # Written as a PLY file by main(): a mesh made in Python cannot take its
            # BSDF and emitter through load_dict.
            result[f"object{i}"] = (polygon_mesh(f"object{i}", obj["vertices"]), bsdf, emitter)
        elif obj["type"] == "sphere":
            entry = {
                "type": "sphere",
                "center": obj["center"],
                "radius": obj["radius"],
                "bsdf": bsdf,
            }
            if emitter:
                entry["emitter"] = emitter
            result[f"object{i}"] = entry
        else:
            fail(f"objects[{i}]: type {obj['type']!r} is not supported by this script")
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("output")
    parser.add_argument("--size", type=int, default=32, help="image width in pixels")
    parser.add_argument("--spp", type=int, default=65536)
    args = parser.parse_args()
    with open(args.scene, "rb") as f:
        scene = tomllib.load(f)
    description = scene_dict(scene, args.size, args.spp)
    work = tempfile.mkdtemp()
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
