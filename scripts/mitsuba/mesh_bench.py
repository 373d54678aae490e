#!/usr/bin/env python3
"""Times Mitsuba 3 on the mesh benchmark of BENCHMARKS.md (issue 30): the scene of
scenes/bench/bunny.toml (the corpus's Stanford bunny, 69,451 triangles, on a floor
under one point light), camera and one shadow ray per sample (Mitsuba's `direct`
integrator with one emitter sample and no BSDF sample: the work of our Whitted
integrator at max_depth 0), 320x240 at 256 samples per pixel, in the `llvm_ad_rgb`
variant on all cores. Prints the median of `--runs` render times (the first render,
which compiles the kernels, is not counted) and writes the last image.

Run from the repository root (tested with mitsuba 3.9.1):

    python3 -m venv /tmp/mi-venv && /tmp/mi-venv/bin/pip install mitsuba numpy
    /tmp/mi-venv/bin/python scripts/mitsuba/mesh_bench.py --runs 3
"""

import argparse
import os
import statistics
import time

import mitsuba as mi

BUNNY = "../shared/realworld/common3d/data/stanford-bunny.obj"


def scene_dict(obj, width, height, spp):
    """The bunny scene: the camera, light and materials of scenes/bench/bunny.toml."""
    floor = mi.ScalarTransform4f().translate([0.0, 0.033, 0.0]).rotate([1, 0, 0], -90).scale(50.0)
    return {
        "type": "scene",
        "integrator": {"type": "direct", "emitter_samples": 1, "bsdf_samples": 0},
        "sensor": {
            "type": "perspective",
            "fov": 40.0,
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(
                origin=[-0.02, 0.16, 0.32], target=[-0.02, 0.1, 0.0], up=[0, 1, 0]
            ),
            "sampler": {"type": "independent", "sample_count": spp},
            "film": {
                "type": "hdrfilm",
                "width": width,
                "height": height,
                "rfilter": {"type": "box"},
            },
        },
        "light": {"type": "point", "position": [0.3, 0.6, 0.5], "intensity": {"type": "rgb", "value": 0.4}},
        "background": {"type": "constant", "radiance": {"type": "rgb", "value": [0.25, 0.3, 0.4]}},
        "bunny": {
            "type": "obj",
            "filename": obj,
            "face_normals": True,
            "bsdf": {"type": "twosided", "material": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.8, 0.7, 0.6]}}},
        },
        "floor": {
            "type": "rectangle",
            "to_world": floor,
            "bsdf": {"type": "twosided", "material": {"type": "diffuse", "reflectance": {"type": "rgb", "value": 0.5}}},
        },
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--spp", type=int, default=256)
    parser.add_argument("--out", default="target/mitsuba-bunny.exr")
    parser.add_argument("--variant", default="llvm_ad_rgb")
    args = parser.parse_args()
    mi.set_variant(args.variant)
    scene = mi.load_dict(scene_dict(os.path.abspath(BUNNY), 320, 240, args.spp))
    times = []
    for run in range(args.runs + 1):
        start = time.perf_counter()
        image = mi.render(scene, spp=args.spp, seed=run)
        mi.Bitmap(image)  # waits for the render to finish
        elapsed = time.perf_counter() - start
        if run > 0:
            times.append(elapsed)
        print(f"run {run}: {elapsed:.3f} s{' (compiles, not counted)' if run == 0 else ''}")
    os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
    mi.util.write_bitmap(args.out, image)
    print(f"mitsuba {mi.__version__} {args.variant}: median {statistics.median(times):.3f} s of {len(times)} runs")


if __name__ == "__main__":
    main()
