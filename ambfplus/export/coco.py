"""Instance masks of a recording as COCO annotations (run-length encoded with pycocotools),
one annotation file per camera stream.

``OUT/<stream>.json`` holds ``info`` (the export's conventions), ``images`` (one per recorded
frame: ``file_name`` relative to OUT, size, and ambfplus's ``time``, ``step``, ``intrinsics``
and ``pose``), ``categories`` and ``annotations``; ``OUT/<stream>/NNNNNN.png`` are the frames'
RGB images. Categories are the legend's objects that can be seen (bodies, soft bodies, ...;
``supercategory`` is their kind) and every anatomy label of every volume (``supercategory``
"anatomy", ``volume`` its volume): a volume's pixels are split by the label image into one
annotation per label (pixels of label 0 take the volume's own category, supercategory
"volume"). Each annotation has ``segmentation`` (compressed RLE, column-major as
pycocotools writes it), ``area`` (pixels), ``bbox`` ([x, y, w, h]), ``iscrowd`` 0 and ambfplus's
``instance_id`` and ``label_id`` (0 outside volumes), so decoded masks rebuild the instance
image exactly.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ._common import ExportError, export_conventions, require

SKIPPED_KINDS = {"camera", "light", "input device", "drill", "volume", "sensor", "actuator"}


class CocoExport:
    """Categories from a recording's legend and the annotations of its frames."""

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
        self.categories: list[dict] = []
        self._object_category: dict[int, int] = {}
        self._label_category: dict[tuple[int, int], int] = {}
        self._volumes: set[int] = set()
        for object_id, entry in sorted(recording.legend.items(), key=lambda kv: int(kv[0])):
            object_id = int(object_id)
            if entry.get("kind") == "volume":
                self._volumes.add(object_id)
                # Pixels of the volume whose label is 0 (none) take the volume's own category.
                self._object_category[object_id] = self._add_category(
                    entry["name"], "volume", object_id=object_id
                )
                self._label_category[(object_id, 0)] = self._object_category[object_id]
                for label_id, label in sorted(entry.get("labels", {}).items()):
                    self._label_category[(object_id, int(label_id))] = self._add_category(
                        label["name"], "anatomy", volume=entry["name"], label_id=int(label_id),
                        color=list(label.get("color", ())),
                    )  # fmt: skip
            elif entry.get("kind") not in SKIPPED_KINDS:
                self._object_category[object_id] = self._add_category(
                    entry["name"], entry.get("kind", "object"), object_id=object_id,
                    color=list(entry.get("color", ())),
                )  # fmt: skip

    def _add_category(self, name: str, supercategory: str, **extra) -> int:
        category_id = len(self.categories) + 1
        self.categories.append({"id": category_id, "name": name,
                                "supercategory": supercategory, **extra})  # fmt: skip
        return category_id

    def _fallback(self, object_id: int) -> int:
        """An id seen in an image but missing from the legend gets a category of its own."""
        if object_id not in self._object_category:
            self.warnings.append(f"object id {object_id} is not in the legend")
            self._object_category[object_id] = self._add_category(
                f"object {object_id}", "unknown", object_id=object_id
            )
        return self._object_category[object_id]

    def annotations(self, frame, image_id: int, first_id: int) -> list[dict]:
        """The annotations of one frame: a mask per object, volumes split per anatomy label."""
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
                    key = (object_id, int(label_id))
                    category = self._label_category.get(key)
                    if category is None:
                        category = self._add_unknown_label(*key)
                    out.append(self._annotation(inside & (labels == label_id), image_id,
                                                category, object_id, int(label_id)))  # fmt: skip
            else:
                if object_id in self._volumes:
                    self._warn(f"stream {frame.stream} has no label pass: each volume has one "
                               "mask")  # fmt: skip
                category = self._object_category.get(object_id) or self._fallback(object_id)
                out.append(self._annotation(inside, image_id, category, object_id, 0))
        for offset, annotation in enumerate(out):
            annotation["id"] = first_id + offset
        return out

    def _warn(self, text: str) -> None:
        if text not in self.warnings:
            self.warnings.append(text)

    def _add_unknown_label(self, object_id: int, label_id: int) -> int:
        self.warnings.append(f"label {label_id} of volume {object_id} is not in its label table")
        category = self._add_category(f"label {label_id}", "anatomy", label_id=label_id)
        self._label_category[(object_id, label_id)] = category
        return category

    def _annotation(self, mask, image_id, category, object_id, label_id) -> dict:
        rle = self.mask.encode(np.asfortranarray(mask.astype(np.uint8)))
        bbox = self.mask.toBbox(rle)
        return {
            "image_id": image_id,
            "category_id": category,
            "segmentation": {"size": list(rle["size"]), "counts": rle["counts"].decode("ascii")},
            "area": float(mask.sum()),
            "bbox": [float(v) for v in bbox],
            "iscrowd": 0,
            "instance_id": object_id,
            "label_id": label_id,
        }


def write_coco(recording, out: Path, bar, *, images: bool = True) -> dict:
    """Writes COCO annotations (and, with images, the RGB frames as PNG) into the folder
    ``out`` (which must not exist yet)."""
    from .. import write_image

    export = CocoExport(recording)
    out.mkdir()
    files, counts = [], {}
    info = {
        "description": f"instance masks of {recording.path.name}",
        "version": "1.0",
        **export_conventions(recording),
        "masks": "compressed RLE (pycocotools), column-major; categories are the legend's "
        "objects and each volume's anatomy labels",
        "image_convention": "row 0 is the top; intrinsics centre pixel (r, c) at "
        "(c + 0.5, r + 0.5); pose is world-from-camera, OpenCV camera axes",
    }
    for stream in export.streams:
        image_entries: list[dict] = []
        annotations: list[dict] = []
        if images and stream.rgb is not None:
            (out / stream.name).mkdir()
        for index in range(len(stream)):
            frame = stream[index]
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
            "frames": sum(len(s) for s in export.streams)}  # fmt: skip
