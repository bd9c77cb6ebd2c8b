"""Slice stacks in every PNG layout (RGBA, RGB, palette with and without transparency, grey and
alpha, 16-bit grey, interlaced) and in JPEG load to the labels their pixels say; malformed slices
(truncated, wrong checksum, absurd size, not an image) give a ConfigError naming the slice. The
images are written by Pillow, independently of the engine."""

from __future__ import annotations

import struct
import zlib

import numpy as np
import pytest
from PIL import Image

import ambfplus

PALETTE = np.array([[0, 0, 0], [230, 220, 190], [255, 200, 0], [200, 40, 40]], np.uint8)


def index_slices(shape=(12, 9, 4), seed=2) -> list[np.ndarray]:
    """Palette indices per slice, (rows, columns), every index present in every slice."""
    rng = np.random.default_rng(seed)
    slices = []
    for _ in range(shape[2]):
        index = rng.integers(0, len(PALETTE), (shape[1], shape[0]))
        index.flat[: len(PALETTE)] = np.arange(len(PALETTE))
        slices.append(index)
    return slices


def save_stack(folder, images, extension="png", **options):
    folder.mkdir()
    for k, image in enumerate(images):
        image.save(folder / f"plane00{k}.{extension}", **options)
    return folder


def load(folder, extension="png"):
    data = ambfplus.load_slice_stack(folder, dimensions=(1, 1, 1), format=extension)
    return np.asarray(data.labels).copy(), [(x.id, tuple(x.color)) for x in data.label_table]


def palette_image(index: np.ndarray) -> Image.Image:
    image = Image.fromarray(index.astype(np.uint8), "P")
    image.putpalette(PALETTE.flatten().tolist())
    return image


def test_every_png_colour_layout_gives_the_same_labels(tmp_path):
    slices = index_slices()
    opaque = [np.where(i > 0, 255, 0).astype(np.uint8) for i in slices]
    rgba = [Image.fromarray(np.dstack([PALETTE[i], a]), "RGBA") for i, a in zip(slices, opaque)]
    reference = load(save_stack(tmp_path / "rgba", rgba))
    labels, table = reference
    # Pixel (row r, column c) of slice k is voxel (c, ny - 1 - r, k); colours by frequency.
    assert labels.shape == (12, 9, 4)
    by_colour = {colour: i for i, colour in table}
    expected_ids = {0: 0} | {j: by_colour[tuple(int(v) for v in PALETTE[j])] for j in (1, 2, 3)}
    for k, index in enumerate(slices):
        want = np.vectorize(expected_ids.get)(index)
        assert np.array_equal(labels[:, ::-1, k].T, want)

    # The same colours as RGB (black is empty), interlaced RGBA, a palette, a palette whose
    # first entry is transparent, and an RGB image with black as its transparent colour.
    variants = {
        "rgb": save_stack(tmp_path / "rgb", [Image.fromarray(PALETTE[i], "RGB") for i in slices]),
        "interlaced": save_stack(tmp_path / "interlaced", rgba, interlace=1),
        "palette": save_stack(tmp_path / "palette", [palette_image(i) for i in slices]),
        "palette_trns": save_stack(
            tmp_path / "palette_trns",
            [palette_image(i) for i in slices],
            transparency=bytes([0, 255, 255, 255]),
        ),
        "rgb_trns": save_stack(
            tmp_path / "rgb_trns",
            [Image.fromarray(PALETTE[i], "RGB") for i in slices],
            transparency=(0, 0, 0),
        ),
    }
    for name, folder in variants.items():
        got_labels, got_table = load(folder)
        assert np.array_equal(got_labels, labels), name
        assert got_table == table, name


def test_sixteen_bit_grey_slices_round_to_eight_bits(tmp_path):
    # Every 16-bit value once: 65535 -> 255 and v * 257 -> v, rounding to the nearest.
    values = np.arange(65536, dtype=np.uint16).reshape(256, 256)
    folder = save_stack(tmp_path / "grey16", [Image.fromarray(values)] * 2)
    labels, table = load(folder)
    expected = ((values.astype(np.int64) + 128) // 257).astype(np.uint8)
    assert np.array_equal(labels[:, ::-1, 0].T, expected)
    assert np.array_equal(labels[:, :, 1], labels[:, :, 0])
    assert [i for i, _ in table] == list(range(1, 256))


def test_grey_and_alpha_slices_read_as_grey_colours(tmp_path):
    grey = np.array([[0, 90, 90, 200], [200, 200, 90, 0]], np.uint8)
    alpha = np.array([[255, 255, 0, 255], [255, 255, 255, 255]], np.uint8)
    folder = save_stack(tmp_path / "la", [Image.fromarray(np.dstack([grey, alpha]), "LA")])
    labels, table = load(folder)
    colours = {colour: i for i, colour in table}
    assert set(colours) == {(0, 0, 0), (90, 90, 90), (200, 200, 200)}
    want = np.where(alpha >= 128, np.vectorize(lambda g: colours[(g, g, g)])(grey), 0)
    assert np.array_equal(labels[:, ::-1, 0].T, want)


def test_jpeg_slices_load(tmp_path):
    # Flat 8x8 blocks at quality 100 decode exactly (one DC coefficient, quantiser 1).
    blocks = np.array([[10, 20, 30], [40, 50, 60]], np.uint8)
    grey = np.kron(blocks, np.ones((8, 8), np.uint8))
    folder = save_stack(
        tmp_path / "jpg", [Image.fromarray(grey, "L")] * 3, extension="jpg", quality=100
    )
    labels, table = load(folder, "jpg")
    assert labels.shape == (24, 16, 3)
    assert np.array_equal(labels[:, ::-1, 2].T, grey)
    assert [i for i, _ in table] == [10, 20, 30, 40, 50, 60]


def png_chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def png_with_header(width: int, height: int) -> bytes:
    """An RGB PNG whose header says width x height but holds one black row of 4 pixels."""
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    pixels = zlib.compress(b"\0" + bytes(12))
    return (
        b"\x89PNG\r\n\x1a\n"
        + png_chunk(b"IHDR", header)
        + png_chunk(b"IDAT", pixels)
        + png_chunk(b"IEND", b"")
    )


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        (lambda good: good[: len(good) // 2], "the file ends early"),
        (lambda good: good[:-1], "the file ends early"),
        (lambda good: good[:29] + bytes([good[29] ^ 0xFF]) + good[30:], "IHDR: CRC error"),
        (lambda good: png_with_header(100000, 2), "100000x2 pixels: more than the 65535"),
        (lambda good: png_with_header(40000, 40000), "more than 1024 MiB"),
        (lambda good: png_with_header(4, 3), "Not enough image data"),
        (lambda good: png_with_header(0, 1), "cannot decode the PNG image"),
        (lambda good: b"GIF89a" + good, "not a PNG or JPEG file"),
        (lambda good: b"", "the file is empty"),
    ],
)
def test_malformed_slices_name_the_slice_and_the_problem(tmp_path, damage, message):
    rgba = [Image.fromarray(np.full((6, 5, 4), 200, np.uint8), "RGBA")] * 3
    folder = save_stack(tmp_path / "s", rgba)
    good = (folder / "plane001.png").read_bytes()
    (folder / "plane001.png").write_bytes(damage(good))
    with pytest.raises(ambfplus.ConfigError, match=message) as info:
        load(folder)
    assert str(folder / "plane001.png") in str(info.value)
