"""The built-in phantom against the original system's 256^3 segmented ear: every structure's
volume and the distances between key structures within 0.5x-2x of the patient's, for ten seeds
and both sides (one seed per side in the fast suite), with the original's label table."""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pytest
from helpers.anatomy import comparison_table, measure

import ambfplus

EAR = "volumetric_drilling"


@functools.cache
def load_and_measure(root: Path):
    world = ambfplus.World()
    (volume,) = world.load_volumes(root / "ADF" / "volume_256.yaml", labels=root / "labels.csv")
    return volume.data, measure(volume.data)


@pytest.fixture
def fixture_ear(fixtures):
    """The fixture ear's volume and measures, loaded once per session."""
    return load_and_measure(fixtures / EAR)


def check_against_fixture(fixture_ear, seed, side):
    data = ambfplus.phantom(256, seed, side=side)
    rows = comparison_table(measure(data), fixture_ear[1])
    print(f"\nphantom(256, seed={seed}, side={side!r}) against the fixture ear")
    print(f"{'structure':46s} {'phantom':>10s} {'fixture':>10s} {'ratio':>6s}")
    for name, mine, theirs, ratio in rows:
        print(f"{name:46s} {mine:10.2f} {theirs:10.2f} {ratio:6.2f}")
    outside = [(name, round(ratio, 2)) for name, _, _, ratio in rows if not 0.5 <= ratio <= 2.0]
    assert not outside, f"seed {seed}, {side}: outside 0.5x-2x of the fixture: {outside}"


@pytest.mark.parametrize("side", ["right", "left"])
def test_phantom_matches_the_fixture_ear(fixture_ear, side):
    check_against_fixture(fixture_ear, 0, side)


@pytest.mark.slow
@pytest.mark.parametrize("side", ["right", "left"])
@pytest.mark.parametrize("seed", range(1, 10))
def test_phantom_matches_the_fixture_ear_for_every_seed(fixture_ear, seed, side):
    check_against_fixture(fixture_ear, seed, side)


def test_phantom_labels_are_the_fixture_ears(fixtures, fixture_ear):
    """Names, ids and colours as loading the fixture with its labels.csv gives them."""
    expected = [(label.id, label.name, label.color) for label in fixture_ear[0].label_table]
    table = ambfplus.phantom(32).label_table
    assert [(label.id, label.name, label.color) for label in table] == expected
    # And as the CSV itself lists them (ids in file order).
    rows = (fixtures / EAR / "labels.csv").read_text().split()[1:]
    listed = [(name, tuple(int(c) for c in rgb)) for name, *rgb in (r.split(",") for r in rows)]
    assert [(label.name, label.color) for label in table] == listed


def test_left_is_the_right_mirrored():
    right = np.asarray(ambfplus.phantom(64, 3, side="right").labels)
    left = np.asarray(ambfplus.phantom(64, 3, side="left").labels)
    assert np.array_equal(left, right[::-1, :, :])
    assert not np.array_equal(left, right)


def test_seeds_vary_the_anatomy_and_repeat_exactly():
    a = ambfplus.phantom(64, 1).label_counts()
    assert np.array_equal(a, ambfplus.phantom(64, 1).label_counts())
    b = ambfplus.phantom(64, 2).label_counts()
    assert not np.array_equal(a, b)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"side": "up"}, 'side must be "right" or "left", got "up"'),
        ({"side": "Right"}, 'got "Right"'),
        ({"resolution": 8}, "resolution must be 16..2048 voxels, got 8"),
    ],
)
def test_phantom_bad_arguments_are_clear_errors(kwargs, match):
    with pytest.raises(ValueError, match=match):
        ambfplus.phantom(**kwargs)
