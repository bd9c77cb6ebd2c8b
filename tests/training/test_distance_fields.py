"""Distance fields of a volume's structures (ambfplus.DistanceField): exact against brute force,
up to date after drilling, named by label name or id, and sampled with a gradient."""

from __future__ import annotations

import numpy as np
import pytest

import ambfplus


def small_volume(seed: int = 0) -> ambfplus.VolumeData:
    rng = np.random.default_rng(seed)
    labels = np.ones((14, 11, 9), dtype=np.uint8)
    for _ in range(3):
        lo = rng.integers(0, (11, 8, 6))
        labels[lo[0] : lo[0] + 3, lo[1] : lo[1] + 2, lo[2] : lo[2] + 3] = 2
    table = [
        ambfplus.Label(1, "Bone", (230, 230, 200)),
        ambfplus.Label(2, "Facial_Nerve", (250, 210, 40)),
    ]
    return ambfplus.VolumeData(labels, dimensions=(0.0028, 0.0033, 0.0018), label_table=table)


def brute_force(data: ambfplus.VolumeData, band: float) -> np.ndarray:
    labels = np.array(data.labels)
    n = np.array(labels.shape)
    size = np.asarray(data.dimensions) / n
    centres = (np.stack(np.meshgrid(*[np.arange(k) for k in n], indexing="ij"), -1) + 0.5) * size
    inside = labels == 2
    pts, member = centres.reshape(-1, 3), inside.reshape(-1)
    d = np.linalg.norm(pts[:, None, :] - pts[None, :, :], axis=-1)
    out = np.where(
        member,
        -np.where(member[None, :], np.inf, d).min(1),
        np.where(member[None, :], d, np.inf).min(1),
    )
    return np.clip(out, -band, band).reshape(labels.shape)


def test_the_field_equals_brute_force_and_is_an_owned_float32_grid():
    data = small_volume()
    field = ambfplus.DistanceField(data, "Facial_Nerve", band=0.001)
    values = field.values()
    assert values.dtype == np.float32 and values.shape == tuple(data.shape)
    assert values.strides == (4, 4 * 14, 4 * 14 * 11)  # i fastest, like the label grid
    np.testing.assert_allclose(values, brute_force(data, 0.001), atol=1e-9)
    assert (values < 0).any() and (values >= 0.001 - 1e-9).any()
    assert field.structure_voxels == int((np.array(data.labels) == 2).sum())


def test_names_and_ids_name_the_same_structure_and_unknown_names_are_listed():
    data = small_volume()
    a = ambfplus.DistanceField(data, ["Facial_Nerve"]).values()
    b = ambfplus.DistanceField(data, 2).values()
    np.testing.assert_array_equal(a, b)
    with pytest.raises(ambfplus.NotFound, match="'Sigmoid'.*1 'Bone', 2 'Facial_Nerve'"):
        ambfplus.DistanceField(data, "Sigmoid")
    with pytest.raises(ambfplus.ArgumentError, match="band"):
        ambfplus.DistanceField(data, 2, band=-1.0)


def test_drilling_into_the_structure_updates_the_field_as_a_fresh_build():
    data = small_volume(3)
    field = ambfplus.DistanceField(data, 2, band=0.0012)
    labels = np.array(data.labels)
    target = np.argwhere(labels == 2)[0]
    centre = (target + 0.5) * np.asarray(data.dimensions) / labels.shape - np.asarray(
        data.dimensions
    ) / 2
    data.remove_sphere(centre, 0.0005, only_removable=False)
    assert field.update() > 0
    np.testing.assert_allclose(
        field.values(), ambfplus.DistanceField(data, 2, band=0.0012).values(), atol=1e-9
    )
    assert field.revision == data.revision


def test_samples_match_one_by_one_and_in_bulk_and_point_away_from_the_nerve():
    data = ambfplus.phantom(64)
    field = ambfplus.DistanceField(data, "Facial_Nerve", band=0.004)
    rng = np.random.default_rng(1)
    points = rng.uniform(-0.01, 0.01, size=(50, 3))
    d, g = field.sample(points)
    assert d.shape == (50,) and g.shape == (50, 3)
    for p, dp, gp in zip(points, d, g):
        one, grad = field.sample(p)
        assert one == dp and np.array_equal(grad, gp)
    # Stepping along the gradient from a point near the nerve increases the distance by the step.
    near = np.argmin(np.abs(d - 0.002))
    step = 2e-4 * g[near] / np.linalg.norm(g[near])
    further, _ = field.sample(points[near] + step)
    assert further - d[near] == pytest.approx(2e-4, rel=0.3)
