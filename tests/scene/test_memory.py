"""The memory contract: frame arrays are views of engine buffers that keep those buffers alive."""

from __future__ import annotations

import gc

import numpy as np
import pytest

import ambfplus


def small_scene(width=64, height=48):
    world = ambfplus.World()
    world.add_body("ball", "sphere", radius=0.1, pose=ambfplus.make_pose((0, 0, 0)))
    camera = world.add_camera("cam", width, height, 0.7, 0.01, 10.0)
    camera.look_at((0.5, 0, 0), (0, 0, 0))
    return world, camera


def data_pointer(a: np.ndarray) -> int:
    return a.__array_interface__["data"][0]


@pytest.mark.parametrize(
    ("name", "dtype", "shape", "strides"),
    [
        ("rgb", np.uint8, (48, 64, 3), (64 * 3, 3, 1)),
        ("depth", np.float32, (48, 64), (64 * 4, 4)),
    ],
)
def test_arrays_are_views_with_expected_layout(name, dtype, shape, strides):
    _, camera = small_scene()
    frame = camera.capture()
    a = getattr(frame, name)
    assert a.dtype == dtype
    assert a.shape == shape
    assert a.strides == strides
    assert not a.flags.owndata
    assert a.flags.c_contiguous and a.flags.writeable
    assert a.base is frame
    # Two views of the same buffer: a write through one is seen by the other.
    b = getattr(frame, name)
    assert data_pointer(a) == data_pointer(b)
    a[0, 0] = 7
    assert b[0, 0].flat[0] == 7


@pytest.mark.parametrize("name", ["rgb", "depth"])
def test_views_survive_their_frame_camera_and_world(name):
    world, camera = small_scene()
    view = getattr(camera.capture(), name)
    expected = view.copy()
    del camera, world
    gc.collect()
    # Allocate and fill fresh memory that would reuse a freed buffer.
    junk = [np.full(view.nbytes, 0xAB, np.uint8) for _ in range(8)]
    assert np.array_equal(view, expected)
    assert view.sum() > 0, "the view must still hold the rendered sphere"
    del junk


def test_capture_into_a_frame_refills_the_same_memory():
    world, camera = small_scene()
    frame = camera.capture()
    rgb, depth = frame.rgb, frame.depth
    pointers = data_pointer(rgb), data_pointer(depth)
    before = depth.copy()
    world.get("ball").pose = ambfplus.make_pose((0, 0.05, 0))
    world.step(3)
    again = camera.capture(out=frame)
    assert again is frame
    assert (data_pointer(frame.rgb), data_pointer(frame.depth)) == pointers
    # The old views see the new image: the buffers were filled in place.
    assert not np.array_equal(depth, before)
    assert frame.step == 3


def test_capture_into_preallocated_arrays():
    _, camera = small_scene()
    rgb = np.zeros((48, 64, 3), np.uint8)
    depth = np.zeros((48, 64), np.float32)
    frame = camera.capture(out={"rgb": rgb, "depth": depth})
    assert data_pointer(frame.rgb) == data_pointer(rgb)
    assert data_pointer(frame.depth) == data_pointer(depth)
    reference = camera.capture()
    assert np.array_equal(rgb, reference.rgb)
    assert np.array_equal(depth, reference.depth)
    # Slices of a bigger, contiguous buffer work too (a ring of frames, say).
    ring = np.zeros((4, 48, 64), np.float32)
    camera.capture(out={"depth": ring[2]})
    assert np.array_equal(ring[2], reference.depth) and not ring[1].any()


def test_depth_only_capture_leaves_rgb_out():
    _, camera = small_scene()
    depth = np.zeros((48, 64), np.float32)
    frame = camera.capture(out={"depth": depth})
    assert frame.rgb is None
    assert depth.max() > 0


def test_preallocated_views_keep_the_callers_array_alive():
    _, camera = small_scene()
    frame = camera.capture(out={"depth": np.zeros((48, 64), np.float32)})
    view = frame.depth
    del frame
    gc.collect()
    junk = [np.full(48 * 64 * 4, 0xAB, np.uint8) for _ in range(8)]
    assert view.max() > 0 and view.max() < 1.0
    del junk


@pytest.mark.parametrize(
    ("out", "error"),
    [
        ({"rgb": np.zeros((48, 64, 3), np.float32)}, ValueError),
        ({"rgb": np.zeros((48, 64, 4), np.uint8)}, ValueError),
        ({"depth": np.zeros((64, 48), np.float32)}, ValueError),
        ({"depth": np.zeros((48, 128), np.float32)[:, ::2]}, ValueError),
        ({"depth": np.zeros((48, 64), np.float64)}, ValueError),
        ({"normals": np.zeros((48, 64, 3), np.float32)}, ValueError),
        ({"depth": [0.0] * 10}, TypeError),
        (np.zeros((48, 64), np.float32), TypeError),
    ],
)
def test_bad_outputs_are_refused_with_a_reason(out, error):
    _, camera = small_scene()
    with pytest.raises(error, match="out"):
        camera.capture(out=out)


def test_read_only_output_is_refused():
    _, camera = small_scene()
    depth = np.zeros((48, 64), np.float32)
    depth.flags.writeable = False
    with pytest.raises(ValueError, match="read-only"):
        camera.capture(out={"depth": depth})


def test_frame_of_another_size_is_refused():
    world, camera = small_scene()
    other = world.add_camera("other", 32, 24)
    frame = other.capture()
    with pytest.raises(ValueError, match="32"):
        camera.capture(out=frame)


def resident_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096


def test_a_thousand_captures_do_not_grow_memory():
    # A leaked 160x120 frame (77 kB) would add 75 MiB over 1000 captures.
    _, camera = small_scene(160, 120)
    for _ in range(50):
        camera.capture()
    gc.collect()
    before = resident_bytes()
    for _ in range(1000):
        frame = camera.capture()
        frame.rgb, frame.depth  # noqa: B018 (make the views too)
    del frame
    gc.collect()
    growth = resident_bytes() - before
    assert growth < 8 * 2**20, f"resident memory grew by {growth / 2**20:.1f} MiB"
