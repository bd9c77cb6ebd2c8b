"""What the ids in a capture mean: the legend of object ids (names, kinds, flat colours, and
each volume's label table) and the segmentation colours drawn from it. A recording stores the
legend beside its frames (``ambfplus.recording.Recorder.set_legend``)."""

from __future__ import annotations

from collections import Counter

import numpy as np

from ._core import Frame, World


def legend(world: World) -> dict[int, dict]:
    """Every object id a capture's instance image can hold: name (as declared), kind, model and
    flat colour (RGB 0..255; bodies their material colour), and, for an object under a namespace
    other than AMBF's root, its key (``psm1/baselink``: unique where names are not, and what
    COCO categories and TF frames are named by); volumes also list their labels (id -> name,
    colour)."""
    out = {}
    for o in world.objects:
        entry = {"name": o.name, "kind": o.kind, "model": o.model.name}
        if o.key != o.name:
            entry["key"] = o.key
        color = getattr(o, "color", None)
        if color is not None:
            entry["color"] = tuple(int(round(255 * c)) for c in list(color)[:3])
        if o.kind == "drill":
            # The structures of the step log's `critical_distance` column, in its order.
            entry["critical"] = list(o.critical_distances)
        if o.kind == "volume":
            entry["labels"] = {
                label.id: {"name": label.name, "color": tuple(label.color)}
                for label in o.data.label_table
            }
        out[o.id] = entry
    return out


def segmentation(frame: Frame, world: World, background=(0, 0, 0)) -> np.ndarray:
    """Each object in its legend colour (its material colour, at full strength), volumes in their
    labels' colours, from the frame's instance image (and label for volumes). For the colours
    AMBF's preprocessing shaders draw, capture the "segmentation" pass instead."""
    if frame.instance is None:
        raise ValueError("segmentation needs a frame captured with the 'instance' pass")
    ids = frame.instance
    lut = np.zeros((int(ids.max()) + 1, 3), dtype=np.uint8)
    lut[0] = background
    entries = legend(world)
    for i, entry in entries.items():
        if i < len(lut) and "color" in entry:
            lut[i] = entry["color"]
    image = lut[ids]
    if frame.label is not None:
        labels = frame.label
        on_volume = labels > 0
        if on_volume.any():
            table = np.zeros((int(labels.max()) + 1, 3), dtype=np.uint8)
            for entry in entries.values():
                for label_id, label in entry.get("labels", {}).items():
                    if label_id < len(table):
                        table[label_id] = label["color"]
            image[on_volume] = table[labels[on_volume]]
    return image


def legend_index(legend) -> dict[str, dict]:
    """A recording legend's entries by the names its step-log columns and streams use: every
    object's key (the legend's ``key``, under a namespace: ``psm1/link``; else its name), and
    each declared name that one object alone has (streams name cameras by their names; two
    namespaces' ``link`` are told apart by their keys only)."""
    entries = list(legend.values())
    declared = Counter(entry.get("name") for entry in entries)
    out = {entry.get("name"): entry for entry in entries if declared[entry.get("name")] == 1}
    for entry in entries:
        out[entry.get("key") or entry.get("name")] = entry
    return out


def object_key(index: dict[str, dict], name: str) -> str:
    """The key of the object a step-log column or stream names (``legend_index``)."""
    entry = index.get(name) or {}
    return entry.get("key") or name
