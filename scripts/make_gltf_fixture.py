#!/usr/bin/env python3
"""Writes the round-trip fixture of tests/integration/import_gltf.rs with a glTF exporter that is not
ours: Python's trimesh (tested with trimesh 5.2.0, numpy 2.4).

A small scene: a box placed twice (one mesh under two nodes: instancing), one copy
rotated and scaled, and an icosphere with a glTF PBR material. trimesh writes it as a
binary .glb and as a .gltf with its buffer in an external .bin file. Beside them,
trimesh_scene.expected.json holds what the importer must find, as trimesh computes it:
every triangle in world space (the corners in trimesh's winding), the number of
instances of each mesh and the material factors.

Run from the repository root:

    python3 -m venv /tmp/gltf-venv && /tmp/gltf-venv/bin/pip install trimesh==5.2.0 numpy
    /tmp/gltf-venv/bin/python scripts/make_gltf_fixture.py
"""

import json
import logging
import os

import numpy as np
import trimesh
from trimesh.exchange.gltf import export_glb, export_gltf
from trimesh.visual.material import PBRMaterial

OUT = os.path.join(os.path.dirname(__file__), "..", "tests", "fixtures", "models")


def main():
    # Without scipy trimesh computes vertex normals by a slower path and logs why.
    logging.getLogger("trimesh").setLevel(logging.ERROR)
    box = trimesh.creation.box(extents=[1.0, 0.5, 2.0])
    box.visual = trimesh.visual.TextureVisuals(
        material=PBRMaterial(
            name="painted",
            baseColorFactor=[204, 51, 25, 255],
            metallicFactor=0.0,
            roughnessFactor=0.5,
        )
    )
    ball = trimesh.creation.icosphere(subdivisions=1, radius=0.75)
    ball.visual = trimesh.visual.TextureVisuals(
        material=PBRMaterial(
            name="brass",
            baseColorFactor=[230, 179, 51, 255],
            metallicFactor=1.0,
            roughnessFactor=0.25,
        )
    )

    scene = trimesh.Scene()
    scene.add_geometry(box, geom_name="box", node_name="box_a",
                       transform=trimesh.transformations.translation_matrix([-2.0, 0.25, 0.0]))
    turned = trimesh.transformations.concatenate_matrices(
        trimesh.transformations.translation_matrix([2.0, 0.5, -1.0]),
        trimesh.transformations.rotation_matrix(np.radians(30.0), [0, 1, 0]),
        trimesh.transformations.scale_matrix(1.5),
    )
    # The same geometry under a second node (not a copy): glTF gets one mesh, two nodes.
    scene.graph.update(frame_to="box_b", frame_from=scene.graph.base_frame,
                       matrix=turned, geometry="box")
    scene.add_geometry(ball, geom_name="ball", node_name="ball",
                       transform=trimesh.transformations.translation_matrix([0.0, 0.75, 1.0]))

    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "trimesh_scene.glb"), "wb") as f:
        f.write(export_glb(scene, include_normals=True))
    files = export_gltf(scene, include_normals=True, merge_buffers=True)
    for name, data in files.items():
        target = "trimesh_scene.gltf" if name.endswith(".gltf") else name
        with open(os.path.join(OUT, target), "wb") as f:
            f.write(data)

    triangles = []
    instances = {}
    for node in scene.graph.nodes_geometry:
        transform, geometry = scene.graph[node]
        mesh = scene.geometry[geometry]
        instances[geometry] = instances.get(geometry, 0) + 1
        world = trimesh.transform_points(mesh.vertices, transform)
        for face in mesh.faces:
            triangles.append([world[i].tolist() for i in face])
    expected = {
        "triangles": triangles,
        "instances": instances,
        "materials": {
            "painted": {"base_color": [204 / 255, 51 / 255, 25 / 255], "metallic": 0.0, "roughness": 0.5},
            "brass": {"base_color": [230 / 255, 179 / 255, 51 / 255], "metallic": 1.0, "roughness": 0.25},
        },
        "bounds": [scene.bounds[0].tolist(), scene.bounds[1].tolist()],
    }
    with open(os.path.join(OUT, "trimesh_scene.expected.json"), "w") as f:
        json.dump(expected, f, indent=1)
        f.write("\n")
    print(f"{len(triangles)} triangles, instances {instances}, files {sorted(files)}")


if __name__ == "__main__":
    main()
