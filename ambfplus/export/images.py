"""Camera images as ``sensor_msgs/CompressedImage`` payloads, encoded with Pillow, and back.

The ``format`` field follows the convention sensor_msgs documents for image_transport's
``compressed`` plugin, ``ORIG_PIXFMT; CODEC compressed [COMPRESSED_PIXFMT]``, so ROS 2 tools,
OpenCV and Foxglove (PNG and JPEG) decode them:

=============  ==========  ===========================  ======================================
pass           raw         format                       payload
=============  ==========  ===========================  ======================================
rgb            rgb8        ``rgb8; png compressed       PNG (lossless) or, as an option, JPEG
                           bgr8`` (or ``jpeg``)         (lossy, ``jpeg_quality``)
segmentation   rgb8        ``rgb8; png compressed       PNG, lossless
                           bgr8``
label          16UC1       ``16UC1; png compressed``    16-bit greyscale PNG, lossless
depth          32FC1       ``32FC1; tiff compressed``   32-bit float TIFF (deflate), lossless
instance,      32SC1       ``32SC1; tiff compressed``   32-bit integer TIFF (deflate), lossless
voxel
=============  ==========  ===========================  ======================================

PNG holds at most 16 bits per channel, so the 32-bit passes use TIFF, the third codec of that
convention: bit for bit what was recorded (Foxglove's image panel shows PNG and JPEG only;
depth stays viewable on the raw topic). ``bgr8`` names the channel order image_transport
hands its encoder; the files themselves are ordinary RGB PNG and JPEG.
"""

from __future__ import annotations

import io

import numpy as np

from ._common import ExportError, require

COMPRESSED_IMAGE = "sensor_msgs/msg/CompressedImage"
IMAGE_TOPICS = ("raw", "compressed", "both")
RGB_CODECS = ("png", "jpeg")
# raw encoding -> (codec, format) for the lossless codecs
LOSSLESS = {
    "rgb8": ("png", "rgb8; png compressed bgr8"),
    "16UC1": ("png", "16UC1; png compressed"),
    "32FC1": ("tiff", "32FC1; tiff compressed"),
    "32SC1": ("tiff", "32SC1; tiff compressed"),
}
JPEG_FORMAT = "rgb8; jpeg compressed bgr8"
_DTYPES = {"rgb8": np.uint8, "16UC1": np.uint16, "32FC1": np.float32, "32SC1": np.int32}


def check_image_options(image_topics: str, rgb_codec: str, jpeg_quality: int) -> None:
    """Raises ExportError for unknown image topics or codec, or a JPEG quality off 1..100."""
    if image_topics not in IMAGE_TOPICS:
        raise ExportError(f"image_topics is one of {', '.join(IMAGE_TOPICS)}, not "
                          f"{image_topics!r}")  # fmt: skip
    if rgb_codec not in RGB_CODECS:
        raise ExportError(f"the rgb codec is one of {', '.join(RGB_CODECS)}, not {rgb_codec!r}")
    if isinstance(jpeg_quality, bool) or not isinstance(jpeg_quality, int):
        raise ExportError(f"jpeg_quality is an integer 1..100, not {jpeg_quality!r}")
    if not 1 <= jpeg_quality <= 100:
        raise ExportError(f"jpeg_quality is 1..100, not {jpeg_quality}")
    if image_topics != "raw":
        require("export", "PIL.Image")


def encode_image(array: np.ndarray, encoding: str, codec: str = "png",
                 jpeg_quality: int = 90) -> tuple[str, bytes]:  # fmt: skip
    """(format, bytes) of an image of a raw ROS encoding: `codec` "jpeg" applies to rgb8
    only; everything else takes its lossless codec (see the module)."""
    image_module = require("export", "PIL.Image")
    array = np.ascontiguousarray(array)
    if encoding not in LOSSLESS:
        raise ExportError(f"no compressed form of {encoding} images")
    if array.dtype != _DTYPES[encoding]:
        raise ExportError(f"a {encoding} image must be {np.dtype(_DTYPES[encoding])}, "
                          f"not {array.dtype}")  # fmt: skip
    # Pillow takes the mode from the dtype: RGB, I;16, F (float32), I (int32).
    image = image_module.fromarray(array.astype(array.dtype.newbyteorder("="), copy=False))
    buffer = io.BytesIO()
    if codec == "jpeg" and encoding == "rgb8":
        image.save(buffer, "JPEG", quality=jpeg_quality)
        return JPEG_FORMAT, buffer.getvalue()
    codec, format_ = LOSSLESS[encoding]
    if codec == "png":
        image.save(buffer, "PNG")
    else:
        image.save(buffer, "TIFF", compression="tiff_adobe_deflate")
    return format_, buffer.getvalue()


def compressed_image_message(header: dict, array: np.ndarray, encoding: str,
                             codec: str = "png", jpeg_quality: int = 90) -> dict:  # fmt: skip
    """A sensor_msgs/CompressedImage of an image (see encode_image)."""
    format_, data = encode_image(array, encoding, codec, jpeg_quality)
    return {"header": header, "format": format_, "data": np.frombuffer(data, np.uint8)}


def decode_image(format_: str, data) -> np.ndarray:
    """The image of a CompressedImage written by ``encode_image`` (or by image_transport's
    compressed plugin for these encodings), as the raw encoding's array."""
    image_module = require("export", "PIL.Image")
    original = format_.split(";", 1)[0].strip()
    if original not in _DTYPES:
        raise ExportError(f"cannot decode a compressed {original or format_!r} image")
    with image_module.open(io.BytesIO(bytes(data))) as image:
        if original == "rgb8":
            return np.asarray(image.convert("RGB"))
        return np.asarray(image).astype(_DTYPES[original], copy=False)
