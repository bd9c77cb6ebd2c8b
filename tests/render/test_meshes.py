"""Meshes read through assimp render exactly like the primitive they describe."""

from __future__ import annotations

import base64
import json
import struct

import numpy as np
import pytest

import ambfplus

# A unit cube centred on the origin: 8 corners, 12 outward counter-clockwise triangles.
CORNERS = np.array(
    [[x, y, z] for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)], dtype=np.float32
)
TRIANGLES = np.array(
    [
        [0, 2, 1],
        [1, 2, 3],  # z = -0.5
        [4, 5, 6],
        [5, 7, 6],  # z = +0.5
        [0, 1, 4],
        [1, 5, 4],  # y = -0.5
        [2, 6, 3],
        [3, 6, 7],  # y = +0.5
        [0, 4, 2],
        [2, 4, 6],  # x = -0.5
        [1, 3, 5],
        [3, 7, 5],  # x = +0.5
    ],
    dtype=np.uint32,
)


def write_obj(path):
    lines = [f"v {x} {y} {z}" for x, y, z in CORNERS]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in TRIANGLES]
    path.write_text("\n".join(lines) + "\n")


def face_normal(tri):
    a, b, c = CORNERS[tri]
    n = np.cross(b - a, c - a)
    return n / np.linalg.norm(n)


def write_stl_ascii(path):
    out = ["solid cube"]
    for tri in TRIANGLES:
        out.append("facet normal {} {} {}".format(*face_normal(tri)))
        out.append("outer loop")
        out += ["vertex {} {} {}".format(*CORNERS[i]) for i in tri]
        out += ["endloop", "endfacet"]
    out.append("endsolid cube")
    path.write_text("\n".join(out) + "\n")


def write_stl_binary(path):
    data = bytearray(b"binary cube".ljust(80, b" "))
    data += struct.pack("<I", len(TRIANGLES))
    for tri in TRIANGLES:
        data += struct.pack("<3f", *face_normal(tri))
        for i in tri:
            data += struct.pack("<3f", *CORNERS[i])
        data += struct.pack("<H", 0)
    path.write_bytes(bytes(data))


def write_ply(path):
    header = [
        "ply",
        "format ascii 1.0",
        f"element vertex {len(CORNERS)}",
        "property float x",
        "property float y",
        "property float z",
        f"element face {len(TRIANGLES)}",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    body = [f"{x} {y} {z}" for x, y, z in CORNERS] + [f"3 {a} {b} {c}" for a, b, c in TRIANGLES]
    path.write_text("\n".join(header + body) + "\n")


def write_gltf(path):
    positions = CORNERS.tobytes()
    indices = TRIANGLES.astype(np.uint32).tobytes()
    blob = positions + indices
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [
            {
                "byteLength": len(blob),
                "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode(),
            }
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(positions)},
            {"buffer": 0, "byteOffset": len(positions), "byteLength": len(indices)},
        ],
        "accessors": [
            {
                "bufferView": 0,
                "componentType": 5126,
                "count": len(CORNERS),
                "type": "VEC3",
                "min": [-0.5] * 3,
                "max": [0.5] * 3,
            },
            {"bufferView": 1, "componentType": 5125, "count": TRIANGLES.size, "type": "SCALAR"},
        ],
    }
    path.write_text(json.dumps(doc))


WRITERS = {
    "cube.obj": write_obj,
    "cube_ascii.stl": write_stl_ascii,
    "cube_binary.STL": write_stl_binary,  # upper-case extensions, as AMBF files have
    "cube.ply": write_ply,
    "cube.gltf": write_gltf,
}


def render_depth(**body):
    world = ambfplus.World()
    pose = ambfplus.make_pose((0.0, 0.0, 0.0), rpy=(0.3, 0.2, 0.5))
    world.add_body("cube", pose=pose, **body)
    camera = world.add_camera("cam", 160, 120, 0.8, 0.01, 10.0)
    camera.look_at((0.17, -0.2, 0.14), (0, 0, 0))
    return camera.capture().depth


@pytest.mark.parametrize("name", sorted(WRITERS))
def test_mesh_file_renders_like_the_box_primitive(tmp_path, name):
    path = tmp_path / name
    WRITERS[name](path)
    scale = 0.1
    mesh_depth = render_depth(mesh=str(path), scale=scale)
    box_depth = render_depth(shape="box", size=(scale, scale, scale))
    covered = box_depth > 0
    assert covered.mean() > 0.1
    # Silhouettes may differ by rasterisation of different triangulations along edges only.
    agree = (mesh_depth > 0) == covered
    assert agree.mean() > 0.995
    both = covered & (mesh_depth > 0)
    assert np.abs(mesh_depth[both] - box_depth[both]).max() < 1e-5


def test_fixture_meshes_from_ambf_load(fixtures):
    meshes = sorted((fixtures / "ambf" / "ambf_models" / "meshes").rglob("*.STL"))
    assert meshes, "the AMBF fixture meshes should include STL files"
    world = ambfplus.World()
    for i, path in enumerate(meshes[:6]):
        world.add_body(f"part{i}", mesh=str(path), pose=ambfplus.make_pose((0.3 * i, 0, 0)))
    camera = world.add_camera("cam", 320, 240, 0.9, 0.01, 50.0)
    camera.look_at((0.75, -3.0, 1.5), (0.75, 0, 0))
    assert (camera.capture().depth > 0).mean() > 0.001
