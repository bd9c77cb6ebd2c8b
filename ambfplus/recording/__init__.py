"""Lossless, self-describing HDF5 recordings of a session: camera streams, stereo rigs, physics
steps, removed voxels and events, written by a background thread and safe against a crash.

    from ambfplus.recording import Recorder, open_recording, validate

    with Recorder("session.h5", metadata={"scene": "ear.yaml", "seed": 0}) as rec:
        rec.set_legend(world)                       # or ambfplus.labels.legend(world)
        for _ in range(100):
            world.step(10)
            rec.add_stereo("rig", rig.capture(passes=["rgb", "depth", "label", "voxel"]))
            rec.add_steps({"step": [world.step_index], "time": [world.time]})
            rec.add_removed(drill.take_removed(), volume="ear")
            rec.add_events(drill.take_events())
    rec = open_recording("session.h5")
    rec.cameras["rig_left"][5].depth, rec.rigs["rig"][5].baseline, rec.steps["time"]

Files
-----
A recording named ``session.h5`` is a *head* file ``session.h5`` plus closed *parts*
``session.h5.part0001``, ``session.h5.part0002``, ... in the same folder. Each part is a complete
HDF5 file holding the rows written during one flush interval, in the layout below. The head holds
the description (attributes below) and, once the recorder has closed, one virtual dataset
(HDF5 VDS) per dataset that concatenates the parts, so that plain h5py reads the whole session
from the head alone::

    import h5py, json
    with h5py.File("session.h5") as f:          # keep the parts beside it
        depth = f["cameras/rig_left/depth"][5]  # float32 (H, W), metres
        legend = json.loads(f.attrs["legend"])  # text attributes come back as UTF-8 bytes
        kinds = f["events/kind"].asstr()[:]     # text columns as str

After a crash the head has no virtual datasets yet (``complete`` is False): read the parts in
order and concatenate along axis 0 (``open_recording`` does this), or call ``repair(path)``,
which writes them.

Layout of a part (and of a complete head)
-----------------------------------------
Every dataset is chunked and resizable along axis 0 (``maxshape`` None); images are stored one
frame per chunk, small columns in chunks of about 64 KiB. The default compression is Blosc with
LZ4 and byte shuffling for multi-byte types (HDF5 filter 32001, from the ``hdf5plugin`` package,
which the reader imports: ``import hdf5plugin`` before opening a file with plain h5py). It costs
about what writing uncompressed does (1 ms per 640x480 rgb + depth + label + instance view) and
compresses at least as well as lzf (4x for rgb and depth, 60-150x for ids), which costs 4 times
as much CPU; on a machine whose cores render, that CPU is taken from the capture rate.
``compression`` picks "lzf" or "gzip" (built into h5py, float datasets shuffled) or none.
All datasets of a group have the same length N (their rows belong together).

``cameras/<stream>/`` (attribute ``camera``: the camera's name), one row per frame:
    ``rgb`` uint8 (N, H, W, 3) RGB; ``depth`` float32 (N, H, W) metric z, 0 = no hit;
    ``instance`` int32 (N, H, W) object ids (0 = background); ``label`` uint16 (N, H, W) volume
    label ids (0 = none); ``voxel`` int32 (N, H, W) voxel index i + nx (j + ny k), -1 = none;
    ``points`` float32 (N, H, W, 3) camera frame, only when asked for (it follows from depth);
    ``time`` float64 (N,) s; ``step`` int64 (N,); ``intrinsics`` float64 (N, 3, 3);
    ``pose`` float64 (N, 4, 4) world-from-camera (OpenCV camera frame).
    A stream holds the same image passes in every frame.
``rigs/<rig>/`` (attributes ``left``, ``right``: the two streams), one row per stereo pair:
    ``time`` float64, ``step`` int64, ``baseline`` float64 (m), ``dcx`` float64 (px,
    cx_right - cx_left), ``left_index``, ``right_index`` int64 (the pair's rows in the streams).
``steps/``: columns at the physics rate, whatever the producer gives (leading dimension = number
    of steps), always with ``step`` int64 and ``time`` float64.
``removed/`` (attribute ``volume``: the volume's name): ``step`` int64 (M,), ``voxel`` int32
    (M, 3) global (i, j, k), never restarting; ``label`` uint16 (M,) the label it had.
``events/``: ``step`` int64, ``kind`` UTF-8 string, ``label`` uint16, ``voxel`` int32 (K, 3)
    (-1, -1, -1 when an event has no voxel).

Text, in attributes and in datasets (``events/kind``, text step columns), is stored as
fixed-length UTF-8 strings (NUL-padded; text may not contain NUL), never as variable-length
strings: libhdf5 keeps those in a global heap and loops forever when it reads a damaged one
(``ambfplus.recording.hdf5`` says how the reader guards against it). That is format 1.1;
format 1.0 (ambfplus before it) stored text as variable-length strings, and is still read.

Attributes of the head's root (parts carry the first five):
    ``format`` = "ambfplus.recording", ``ambfplus_recording_version`` = 1,
    ``ambfplus_recording_minor_version`` = 1 (absent in format 1.0), ``recording_id`` (a
    UUID every part repeats), ``part`` (in parts: its number), ``created`` (ISO 8601 UTC),
    ``software_version`` (ambfplus), ``h5py_version``, ``hdf5_version``, ``metadata`` (JSON: the
    user's dict), ``legend`` (JSON: object id -> {name, kind, model, color}; volumes add
    ``labels`` {id -> {name, color}}, ``shape`` (nx, ny, nz), ``dimensions`` and ``voxel_size``
    in metres), ``complete`` (True once closed), ``parts`` (JSON list of part file names).
    Group ``conventions`` has one string attribute per convention: units (SI), world frame (z
    up), camera frame (OpenCV), pixel centres at (c + 0.5, r + 0.5) in the intrinsics, depth,
    points, ids, voxel index order, stereo.

Reading
-------
``open_recording(path)`` checks the head and every part (format, version, numbering, equal
lengths) and raises ``RecordingError`` (a ``ConfigError``, so a ``ValueError``) naming the file
and dataset otherwise. ``rec.cameras[name]`` has ``len``, ``[i]`` (a ``RecordedFrame``: arrays,
time, step, intrinsics, pose) and lazy columns ``.rgb``, ``.depth``, ... that read only what is
indexed; ``rec.rigs[name][i]`` is an ``ambfplus.stereo.StereoFrame`` of two recorded frames;
``rec.steps`` (dict of arrays), ``rec.removed``, ``rec.events``, ``rec.metadata``,
``rec.legend`` (integer ids again), ``rec.version`` and ``rec.minor_version``. ``validate(path)``
(``ambfplus validate PATH``) checks the recording against itself and the conventions. Neither
hangs on a damaged file: a damaged global heap, a variable-length text in a format 1.1 file, an
attribute larger than its file are ``RecordingError``s naming the file (and the attribute).

Unlike the original system's recordings: depth stays float32 and poses float64, with no scale
factors; every frame carries its own intrinsics and pose; voxel indices are global; nothing is
dropped: a full queue blocks the producer instead.

Crash safety: why closed parts and not SWMR
-------------------------------------------
HDF5's single-writer/multiple-reader mode cannot create datasets once it is switched on, but
streams, step columns and event logs appear while a session runs; and a file whose writer died
stays marked as open for writing, so ordinary readers refuse it until ``h5clear`` is run. A file
that is open for writing is not consistent on disk between flushes in any other mode either.
So the writer never lets an open file matter: every ``flush_interval_s`` (and on ``flush()`` and
``close()``) it closes the current part, written as ``<part>.tmp``, and renames it into place,
which is atomic. A process killed at any moment (SIGKILL included) leaves the head (written at
start, replaced atomically), every renamed part, and at most one ``.tmp`` file that readers
ignore: every frame up to the last flush survives with its exact bytes. The price is one file per
flush interval; raise ``flush_interval_s`` for long sessions if that matters more than the
seconds at risk. Surviving power loss as well would need fsync, which this does not do.

Failed writes: HDF5 writes a part to its ``.tmp`` file through a guard (h5py's file-object
driver) that never passes a failed write on: at the first one (disk full, I/O error) the guard
keeps the rest of the part in memory and reports success, so that HDF5 never meets a failing
disk (after such errors its open objects crash the process when they are freed). The recorder
then removes that ``.tmp``, ends the recording at its last closed part and raises
``RecordingError`` from the next call (``add_*``, ``flush``, ``close``, every later ``close``
too); the process exits cleanly whichever way the recorder is then closed, or if it is not.
Until a write fails, a part costs no memory beyond HDF5's chunk cache; after one, the whole part
(what was written before is read back, since HDF5 reads its metadata while closing): at most
``flush_interval_s`` of the session, compressed.
"""

from .reader import CameraStream, Column, RecordedFrame, Recording, RigStream, open_recording
from .schema import RecordingError
from .validation import Check, ValidationReport, validate
from .writer import Recorder, RecorderStats, repair, world_legend

__all__ = [
    "CameraStream",
    "Check",
    "Column",
    "RecordedFrame",
    "Recorder",
    "RecorderStats",
    "Recording",
    "RecordingError",
    "RigStream",
    "ValidationReport",
    "open_recording",
    "repair",
    "validate",
    "world_legend",
]
