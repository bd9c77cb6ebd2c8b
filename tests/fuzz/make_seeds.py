"""Writes the fuzzers' seed inputs into corpus/<target>/seed-* (run once per target; the seeds
are kept in the repository with the inputs the fuzzers found)."""

from __future__ import annotations

import gzip
import io
import sys
import tempfile
import textwrap
from pathlib import Path

import numpy as np
from PIL import Image

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
from helpers.volume_files import nrrd_bytes, segment_keys  # noqa: E402

SEPARATOR = b"\n--8<--\n"


def write(target: str, name: str, data: bytes) -> None:
    folder = HERE / "corpus" / target
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"seed-{name}").write_bytes(data)


def nrrd_seeds() -> None:
    labels = np.zeros((6, 5, 4), dtype=np.uint8)
    labels[1:4, 1:4, 1:3] = 1
    labels[2, 2, 2] = 2
    write("nrrd", "raw.nrrd", nrrd_bytes(labels, "uint8", encoding="raw"))
    write("nrrd", "gzip.nrrd", nrrd_bytes(labels, "uint8", directions=np.diag([0.5, -0.5, 1.0])))
    keys = segment_keys([("Bone", (200, 200, 200), 1, 0), ("Nerve", (250, 200, 0), 2, 0)])
    write("nrrd", "seg.nrrd", nrrd_bytes(labels, "uint8", extra=keys, encoding="raw"))
    layered = np.stack([labels == 1, labels == 2]).astype(np.uint8)
    keys = segment_keys([("Bone", (200, 200, 200), 1, 0), ("Nerve", (250, 200, 0), 1, 1)])
    write("nrrd", "layers.nrrd",
          nrrd_bytes(layered, "uint8", extra=keys, kinds="list domain domain domain"))  # fmt: skip
    ct = (labels.astype(np.int16) * 400 - 100).astype(np.int16)
    write("nrrd", "ct.nrrd", nrrd_bytes(ct, "short", encoding="raw"))
    big = labels.astype(">u2").tobytes(order="F")
    header = (
        "NRRD0004\ntype: ushort\ndimension: 3\nsizes: 6 5 4\nendian: big\nencoding: raw\n"
        'spacings: 0.5 0.5 1\nspace units: "mm" "mm" "mm"\nbyte skip: -1\n\n'
    )
    write("nrrd", "big-endian.nrrd", header.encode() + b"padding" + big)
    header = (
        "NRRD0005\ntype: uchar\ndimension: 3\nsizes: 6 5 4\nencoding: gzip\nline skip: 1\n"
        "byte skip: 2\ndata file: data.raw\nspace origin: (1,2,3)\n"
        "space directions: (0.5,0,0) (0,0.5,0) (0,0,1)\n"
    )
    detached = b"a line\n" + gzip.compress(b"xx" + labels.tobytes(order="F"))
    write("nrrd", "detached.nhdr", header.encode() + SEPARATOR + detached)


def png(array: np.ndarray, mode: str) -> bytes:
    out = io.BytesIO()
    Image.fromarray(array, mode).save(out, "PNG")
    return out.getvalue()


def slice_stack_seeds() -> None:
    rgba = np.zeros((5, 6, 4), dtype=np.uint8)
    rgba[1:4, 1:5] = (200, 200, 200, 255)
    other = rgba.copy()
    other[2, 2] = (250, 200, 0, 255)
    write(
        "slice_stack", "rgba", bytes([0]) + SEPARATOR.join([png(rgba, "RGBA"), png(other, "RGBA")])
    )
    grey = np.zeros((5, 6), dtype=np.uint8)
    grey[1:3, 1:3] = 3
    write("slice_stack", "grey", bytes([1]) + SEPARATOR.join([png(grey, "L")] * 3))
    write("slice_stack", "rgb", bytes([8]) + png(rgba[..., :3].copy(), "RGB"))


def recording_seeds() -> None:
    from ambfplus.recording import Recorder

    rng = np.random.default_rng(0)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "session.h5"

        def frame(camera: str, i: int, x: float) -> dict:
            pose = np.eye(4)
            pose[0, 3] = x
            return {
                "camera": camera, "time": i * 0.01, "step": i * 10,
                "rgb": rng.integers(0, 255, (4, 6, 3), dtype=np.uint8),
                "depth": rng.random((4, 6), dtype=np.float32),
                "label": np.ones((4, 6), np.uint16), "instance": np.ones((4, 6), np.int32),
                "voxel": np.arange(24, dtype=np.int32).reshape(4, 6),
                "intrinsics": np.array([[5.0, 0, 3], [0, 5, 2], [0, 0, 1]]), "pose": pose,
            }  # fmt: skip

        class Pair:
            def __init__(self, i):
                self.left, self.right = frame("left", i, 0.0), frame("right", i, 0.065)
                self.baseline, self.dcx, self.time, self.step = 0.065, 0.0, i * 0.01, i * 10

        legend = {1: {"name": "ear", "kind": "volume", "labels": {1: {"name": "Bone"}},
                      "shape": [4, 4, 4]}}  # fmt: skip
        with Recorder(path, metadata={"scene": "seed"}, compression="gzip",
                      recording_id="seed", created="2026-01-01T00:00:00+00:00") as rec:  # fmt: skip
            rec.set_legend(legend)
            for i in range(2):
                rec.add_stereo("rig", Pair(i))
                rec.add_steps({"step": [i * 10], "time": [i * 0.01], "force": [[0.0, 0, 1]]})
            rec.add_removed({"step": [5], "voxel": [[1, 2, 3]], "label": [1]}, volume="ear")
            rec.add_events([{"step": 5, "kind": "contact", "label": 1}])
        parts = sorted(Path(folder).glob("session.h5.part*"))
        files = [path.read_bytes()] + [p.read_bytes() for p in parts[:2]]
        write("recording", "complete", SEPARATOR.join(files))


ADF_SEEDS = {
    "bodies": """\
        bodies: [BODY base, BODY arm]
        joints: [JOINT base-arm]
        high resolution path: meshes/
        BODY base:
          name: base
          mass: 0.0
          location: {position: {x: 0, y: 0, z: 0}, orientation: {r: 0, p: 0, y: 0}}
          collision shape: BOX
          collision geometry: {x: 0.1, y: 0.1, z: 0.02}
          color rgba: {r: 0.5, g: 0.5, b: 0.5, a: 1}
        BODY arm:
          name: arm
          mass: 0.5
          location: {position: {x: 0, y: 0, z: 0.2}, orientation: {r: 0, p: 0.1, y: 0}}
          collision shape: CAPSULE
          collision geometry: {radius: 0.02, height: 0.2, axis: Z}
          inertia: {ix: 0.001, iy: 0.001, iz: 0.001}
          friction: {static: 0.5, rolling: 0.01}
          damping: {linear: 0.1, angular: 0.1}
        JOINT base-arm:
          name: base-arm
          parent: BODY base
          child: BODY arm
          parent axis: {x: 0, y: 0, z: 1}
          parent pivot: {x: 0, y: 0, z: 0.05}
          child axis: {x: 0, y: 0, z: 1}
          child pivot: {x: 0, y: 0, z: -0.1}
          joint limits: {high: 1.2, low: -1.2}
          type: revolute
          offset: 0.1
          controller: {P: 10, I: 0, D: 1}
        """,
    "camera": """\
        bodies: [BODY ball]
        cameras: [CAMERA cam]
        lights: [LIGHT sun]
        BODY ball:
          name: ball
          mass: 1
          location: {position: {x: 0, y: 0, z: 1}, orientation: {r: 0, p: 0, y: 0}}
          collision shape: SPHERE
          collision geometry: {radius: 0.05}
          color: red
        CAMERA cam:
          name: cam
          location: {x: 1, y: 0, z: 1}
          look at: {x: 0, y: 0, z: 1}
          up: {x: 0, y: 0, z: 1}
          clipping plane: {near: 0.01, far: 10}
          field view angle: 0.8
          monitor: 0
          parent: BODY ball
        LIGHT sun:
          name: sun
          location: {x: 0, y: 0, z: 2}
          direction: {x: 0, y: 0, z: -1}
          spot exponent: 0.3
          cutoff angle: 0.7
          parent: BODY ball
        """,
}


def adf_seeds() -> None:
    for name, text in ADF_SEEDS.items():
        write("adf", f"{name}.yaml", textwrap.dedent(text).encode())


# The first byte picks the format (targets.MESH_FORMATS: 0 PLY, 1 OBJ, 2 STL, 3 OFF).
PLY_TETRAHEDRON = """\
ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
element face 4
property list uchar int vertex_indices
end_header
0 0 0
0.01 0 0
0 0.01 0
0 0 0.01
3 0 2 1
3 0 1 3
3 0 3 2
3 1 2 3
"""
OBJ_TETRAHEDRON = """\
o tetra
v 0 0 0
v 0.01 0 0
v 0 0.01 0
v 0 0 0.01
vn 0 0 1
vt 0.5 0.5
f 1/1/1 3/1/1 2/1/1
f 1 2 4
f 1 4 3
f 2 3 4
"""
OFF_TETRAHEDRON = (
    "OFF\n4 4 0\n0 0 0\n0.01 0 0\n0 0.01 0\n0 0 0.01\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"
)


def binary_stl(triangles: np.ndarray) -> bytes:
    data = b"binary seed".ljust(80, b" ") + np.uint32(len(triangles)).tobytes()
    for triangle in triangles:
        data += np.zeros(3, "<f4").tobytes() + np.asarray(triangle, "<f4").tobytes() + bytes(2)
    return data


def mesh_seeds() -> None:
    write("mesh", "ascii.ply", bytes([0]) + PLY_TETRAHEDRON.encode())
    head, body = PLY_TETRAHEDRON.split("end_header\n")
    vertices = np.array([[0, 0, 0], [0.01, 0, 0], [0, 0.01, 0], [0, 0, 0.01]], "<f4")
    faces = b"".join(
        bytes([3]) + np.array(f, "<i4").tobytes()
        for f in [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
    )
    binary_head = head.replace("ascii", "binary_little_endian") + "end_header\n"
    write("mesh", "binary.ply", bytes([0]) + binary_head.encode() + vertices.tobytes() + faces)
    write("mesh", "tetra.obj", bytes([1]) + OBJ_TETRAHEDRON.encode())
    triangles = vertices[[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]]
    write("mesh", "binary.stl", bytes([2]) + binary_stl(triangles))
    facets = "".join(
        "facet normal 0 0 0\nouter loop\n"
        + "".join(f"vertex {x} {y} {z}\n" for x, y, z in t)
        + "endloop\nendfacet\n"
        for t in triangles.tolist()
    )
    write("mesh", "ascii.stl", bytes([2]) + f"solid seed\n{facets}endsolid seed\n".encode())
    write("mesh", "tetra.off", bytes([3]) + OFF_TETRAHEDRON.encode())


SEEDS = {
    "nrrd": nrrd_seeds,
    "slice_stack": slice_stack_seeds,
    "recording": recording_seeds,
    "adf": adf_seeds,
    "mesh": mesh_seeds,
}

if __name__ == "__main__":  # python make_seeds.py [TARGET ...]: those targets' seeds (default all)
    for name in sys.argv[1:] or SEEDS:
        SEEDS[name]()
