"""Instance masks of a recording as COCO annotations (run-length encoded with pycocotools),
one annotation file per camera stream.

``OUT/<stream>.json`` holds ``info`` (the export's conventions), ``images`` (one per recorded
frame: ``file_name`` relative to OUT, size, and ambfplus's ``time``, ``step``, ``intrinsics``
and ``pose``), ``categories`` and ``annotations``; ``OUT/<stream>/NNNNNN.png`` are the frames'
RGB images. Categories, the same in every file, are the legend's objects that can be seen
(bodies, soft bodies, ...; ``supercategory`` is their kind) and, for each volume, one per
anatomy label its pixels show in any frame, named after the label in the volume's label table
(``supercategory`` "anatomy", ``volume`` its volume, ``label_id``): a volume's pixels are split
by the label image into one annotation per label. A volume takes a category of its own
(``supercategory`` "volume", with a warning) only for pixels with no label to split by: a
stream without the label pass, or label 0 in a recording that has some. Each annotation has
``segmentation`` (compressed RLE, column-major as pycocotools writes it), ``area`` (pixels),
``bbox`` ([x, y, w, h]), ``iscrowd`` 0 and ambfplus's ``instance_id`` and ``label_id`` (0
outside volumes), so decoded masks rebuild the instance image exactly.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..recording.values import FrameGate
from ._common import ExportError, export_conventions, require

SKIPPED_KINDS = {"camera", "light", "input device", "drill", "volume", "sensor", "actuator"}


class CocoExport:
    """Categories from a recording's legend and the anatomy its frames show, and the
    annotations of its frames."""

    def __init__(self, recording) -> None:
        self.rec = recording
        self.mask = require("export", "pycocotools.mask")
        self.warnings: list[str] = []
        self.streams = [s for s in recording.cameras.values() if "instance" in s.passes]
        if not self.streams:
            raise ExportError(
                f"{recording.path}: no camera stream has the 'instance' pass; COCO masks are "
                "made from instance images"
            )
        for stream in recording.cameras.values():
            if stream not in self.streams:
                self.warnings.append(f"stream {stream.name} has no instance images: left out")
        self.legend = {int(k): v for k, v in recording.legend.items()}
        self._volumes = {k for k, v in self.legend.items() if v.get("kind") == "volume"}
        # What the frames show: (object id, label id), the label None outside volumes and for a
        # volume seen without a label pass. Categories are made from it once every frame is in.
        self._seen: set[tuple[int, int | None]] = set()
        self._category: dict[tuple[int, int | None], int] = {}
        self.categories: list[dict] = []

    def annotations(self, frame, image_id: int, first_id: int) -> list[dict]:
        """The annotations of one frame: a mask per object, volumes split per anatomy label.
        Their ``category_id`` is set by ``categorise`` once every frame is in."""
        instance = np.asarray(frame.instance)
        labels = np.asarray(frame.label) if frame.label is not None else None
        out = []
        for object_id in np.unique(instance):
            object_id = int(object_id)
            if object_id == 0:
                continue
            inside = instance == object_id
            if object_id in self._volumes and labels is not None:
                for label_id in np.unique(labels[inside]):
                    mask = inside & (labels == label_id)
                    out.append(self._annotation(mask, image_id, object_id, int(label_id)))
            else:
                if object_id in self._volumes:
                    self._warn(f"stream {frame.stream} has no label pass: each volume has one "
                               "mask")  # fmt: skip
                out.append(self._annotation(inside, image_id, object_id, None))
        for offset, annotation in enumerate(out):
            annotation["id"] = first_id + offset
        return out

    def categorise(self, annotations: list[dict]) -> None:
        """Sets each annotation's ``category_id`` (after ``make_categories``)."""
        for annotation in annotations:
            annotation["category_id"] = self._category[annotation.pop("_key")]

    def make_categories(self) -> None:
        """The categories, once every frame's annotations are made: the legend's objects that
        can be seen (bodies, soft bodies, ...) and, for each volume, one category per anatomy
        label its pixels show, named after the label."""
        for object_id, entry in sorted(self.legend.items()):
            if object_id in self._volumes:
                table = {int(k): v for k, v in entry.get("labels", {}).items()}
                shown = sorted(label for o, label in self._seen if o == object_id and label)
                for label_id in shown:
                    self._category[(object_id, label_id)] = self._label_category(
                        entry, label_id, table.get(label_id)
                    )
                for whole in ((object_id, None), (object_id, 0)):
                    if whole in self._seen:
                        self._category[whole] = self._volume_category(object_id, entry, whole[1])
            elif entry.get("kind") not in SKIPPED_KINDS:
                self._category[(object_id, None)] = self._add_category(
                    entry.get("key") or entry["name"], entry.get("kind", "object"),
                    object_id=object_id,
                    color=list(entry.get("color", ())),
                )  # fmt: skip
        for key in sorted(self._seen - self._category.keys(), key=lambda k: k[0]):
            # An id seen in an image but missing from the legend gets a category of its own.
            self.warnings.append(f"object id {key[0]} is not in the legend")
            self._category[key] = self._add_category(
                f"object {key[0]}", "unknown", object_id=key[0]
            )

    def _label_category(self, entry: dict, label_id: int, label: dict | None) -> int:
        if label is None:
            self.warnings.append(
                f"label {label_id} of volume {entry['name']} is not in its label table"
            )
            label = {"name": f"label {label_id}"}
        return self._add_category(
            label["name"], "anatomy", volume=entry["name"], label_id=label_id,
            color=list(label.get("color", ())),
        )  # fmt: skip

    def _volume_category(self, object_id: int, entry: dict, label_id: int | None) -> int:
        """A whole volume's category: for a stream without a label pass, or for volume pixels
        whose label is 0 (a recording whose renderer left some unlabelled)."""
        if label_id == 0:
            self.warnings.append(
                f"volume {entry['name']} has pixels without a label: they take the category "
                f"{entry['name']!r}"
            )
        if (object_id, None) in self._category:
            return self._category[(object_id, None)]
        return self._add_category(entry["name"], "volume", object_id=object_id)

    def _add_category(self, name: str, supercategory: str, **extra) -> int:
        category_id = len(self.categories) + 1
        self.categories.append({"id": category_id, "name": name,
                                "supercategory": supercategory, **extra})  # fmt: skip
        return category_id

    def _warn(self, text: str) -> None:
        if text not in self.warnings:
            self.warnings.append(text)

    def _annotation(self, mask, image_id, object_id, label_id) -> dict:
        self._seen.add((object_id, label_id))
        rle = self.mask.encode(np.asfortranarray(mask.astype(np.uint8)))
        bbox = self.mask.toBbox(rle)
        return {
            "image_id": image_id,
            "_key": (object_id, label_id),
            "segmentation": {"size": list(rle["size"]), "counts": rle["counts"].decode("ascii")},
            "area": float(mask.sum()),
            "bbox": [float(v) for v in bbox],
            "iscrowd": 0,
            "instance_id": object_id,
            "label_id": label_id or 0,
        }


def write_coco(recording, out: Path, bar, *, images: bool = True,
               bad_frames: str = "refuse") -> dict:  # fmt: skip
    """Writes COCO annotations (and, with images, the RGB frames as PNG) into the folder
    ``out`` (which must not exist yet). ``bad_frames``: "refuse" or "skip" frames whose values
    break ``ambfplus.recording.values``' rules."""
    from .. import write_image

    export = CocoExport(recording)
    gate = FrameGate(recording, bad_frames, ExportError)
    out.mkdir()
    files, counts = [], {}
    info = {
        "description": f"instance masks of {recording.path.name}",
        "version": "1.0",
        **export_conventions(recording),
        "masks": "compressed RLE (pycocotools), column-major; categories are the legend's "
        "objects and, per volume, the anatomy labels its pixels show",
        "image_convention": "row 0 is the top; intrinsics centre pixel (r, c) at "
        "(c + 0.5, r + 0.5); pose is world-from-camera, OpenCV camera axes",
    }
    documents = []
    for stream in export.streams:
        image_entries: list[dict] = []
        annotations: list[dict] = []
        if images and stream.rgb is not None:
            (out / stream.name).mkdir()
        for index in range(len(stream)):
            frame = stream[index]
            if not gate.frame_ok(stream.name, index, frame):
                bar.update(1)
                continue
            image_id = index + 1
            file_name = f"{stream.name}/{index:06d}.png"
            if images and frame.rgb is not None:
                write_image(str(out / file_name), np.ascontiguousarray(frame.rgb))
            image_entries.append({
                "id": image_id, "file_name": file_name, "width": frame.width,
                "height": frame.height, "camera": frame.camera, "time": frame.time,
                "step": frame.step, "intrinsics": np.asarray(frame.intrinsics).tolist(),
                "pose": np.asarray(frame.pose).tolist(),
            })  # fmt: skip
            annotations += export.annotations(frame, image_id, len(annotations) + 1)
            bar.update(1)
        documents.append((stream, image_entries, annotations))
    # Every stream's file lists the same categories: those of everything any frame shows.
    export.make_categories()
    for stream, image_entries, annotations in documents:
        export.categorise(annotations)
        document = {
            "info": {
                **info,
                "camera": stream.camera,
                "stream": stream.name,
                "warnings": export.warnings,
            },  # fmt: skip
            "licenses": [],
            "images": image_entries,
            "annotations": annotations,
            "categories": export.categories,
        }
        (out / f"{stream.name}.json").write_text(json.dumps(document))
        files.append(f"{stream.name}.json")
        counts[stream.name] = len(annotations)
    return {"files": files, "annotations": counts, "warnings": export.warnings,
            "frames": sum(len(s) for s in export.streams) - gate.skipped_frames,
            **gate.counts()}  # fmt: skip
