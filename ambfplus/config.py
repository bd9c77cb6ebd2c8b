"""Checked YAML configuration: the rules every YAML file the package reads (dataset specs,
training tasks) is checked by, so that an error always names the file, the key path and what
was expected, the same way everywhere.

``Where`` is a position (file and key path) that makes errors of the caller's type; the checks
take a value and a ``Where`` and return the value normalised, or raise.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from pathlib import Path

from ._core import ConfigError
from .fileio import require_regular_file

ANATOMY_SOURCES = ("phantom", "file")
ANATOMY_FILE_KEYS = ("file", "name", "prefix", "labels", "dimensions", "voxel_size", "threshold")


class Where:
    """A position in a YAML file (its name and a key path) for error messages; `error` is the
    exception type raised (a ``ConfigError``)."""

    def __init__(self, source: str, path: str = "", error: type = ConfigError) -> None:
        self.source, self.path, self.error_type = source, path, error

    def at(self, key) -> Where:
        if isinstance(key, int):
            return Where(self.source, f"{self.path}[{key}]", self.error_type)
        return Where(self.source, f"{self.path}.{key}" if self.path else str(key), self.error_type)

    def error(self, key, message: str) -> ConfigError:
        path = self.at(key).path if key is not None else self.path
        return self.error_type(f"{self.source}: {path or 'the file'}: {message}")


# The phantoms a spec or task may ask for, and what the largest costs: its label grid and the
# drill's distance fields grow with the cube of the resolution.
MIN_PHANTOM_RESOLUTION = 16
MAX_PHANTOM_RESOLUTION = 512
PHANTOM_LIMIT = "a 512^3 phantom takes about 1 GB with its drill's distance fields"
# A phantom's seed is 32 bits; other seeds (a dataset's) 63.
MAX_PHANTOM_SEED = 2**32 - 1
MAX_SEED = 2**63 - 1


# What a YAML file the package reads (a spec, a task) may hold: a page or two of text, a few
# levels deep. Larger or deeper files are refused before they are parsed.
MAX_YAML_BYTES = 1 << 20
MAX_YAML_DEPTH = 32


def load_yaml(path: Path, error: type = ConfigError, what: str = "YAML"):
    """A YAML file's content; a missing file, one that is not a regular file, one over
    MAX_YAML_BYTES, text that is not UTF-8, bad YAML, nesting deeper than MAX_YAML_DEPTH, a key
    given twice in a mapping or an alias (``*name``: a few lines of aliases can expand to
    billions of nodes) raises `error` naming the file (and the line and column). An OS error
    reading it (permission denied, ...) is raised as it is (an ``OSError`` naming the file)."""
    import yaml

    require_regular_file(path, f"{what} file", error)
    size = path.stat().st_size
    if size > MAX_YAML_BYTES:
        raise error(
            f"{path}: {size} bytes; a {what} file holds at most {MAX_YAML_BYTES} bytes: "
            "is it the right file?"
        )
    data = path.read_bytes()
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        column = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise error(
            f"{path}: line {line}, column {column}: byte 0x{data[exc.start]:02x} is not UTF-8 "
            "text (save the file as UTF-8)"
        ) from None
    try:
        _check_events(yaml.parse(text, Loader=yaml.SafeLoader), path, error, what)
        return yaml.safe_load(text), text
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" (line {mark.line + 1}, column {mark.column + 1})" if mark else ""
        parts = [getattr(exc, "context", None), getattr(exc, "problem", None)]
        problem = ", ".join(p for p in parts if p) or " ".join(str(exc).split())
        raise error(f"{path}: not valid YAML{where}: {problem}") from None


def _check_events(events, path: Path, error: type, what: str) -> None:
    """Reads a YAML file's parse events, refusing an alias, nesting deeper than MAX_YAML_DEPTH
    and a key given twice in one mapping (which YAML would let the later win silently)."""
    import yaml

    # One entry per open collection: (keys seen, or None for a sequence; next node is a key).
    stack: list[list] = []

    def at(event) -> str:
        mark = event.start_mark
        return f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""

    for event in events:
        if isinstance(event, yaml.AliasEvent):
            raise error(
                f"{path}: {at(event)}YAML aliases (*{event.anchor}) are not allowed in a {what} "
                "file: write the value out"
            )
        if isinstance(event, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
            stack.pop()
            if stack and stack[-1][0] is not None:
                stack[-1][1] = not stack[-1][1]
            continue
        if not isinstance(event, yaml.NodeEvent):
            continue
        parent = stack[-1] if stack else None
        if parent is not None and parent[0] is not None and parent[1]:
            if isinstance(event, yaml.ScalarEvent):
                if event.value in parent[0]:
                    raise error(
                        f"{path}: {at(event)}the key {event.value!r} is given twice in one "
                        "mapping: keep one"
                    )
                parent[0].add(event.value)
        if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
            if len(stack) >= MAX_YAML_DEPTH:
                raise error(
                    f"{path}: {at(event)}nested more than {MAX_YAML_DEPTH} levels deep; a "
                    f"{what} file is a few levels deep"
                )
            mapping = isinstance(event, yaml.MappingStartEvent)
            stack.append([set() if mapping else None, True])
        elif parent is not None and parent[0] is not None:
            parent[1] = not parent[1]


def describe(value) -> str:
    """A value as an error message shows it."""
    return "nothing" if value is None else f"{type(value).__name__} {value!r}"


def mapping(value, where: Where, what: str) -> dict:
    if not isinstance(value, dict):
        raise where.error(None, f"expected a mapping ({what}), got {describe(value)}")
    return value


def keys(value: dict, where: Where, required=(), optional=()) -> None:
    """Refuses unknown keys (naming the first and the keys allowed) and missing required ones."""
    allowed = set(required) | set(optional)
    unknown = sorted(str(k) for k in value if k not in allowed)
    if unknown:
        raise where.error(unknown[0], f"unknown key; expected one of {', '.join(sorted(allowed))}")
    missing = [k for k in required if k not in value]
    if missing:
        raise where.error(missing[0], "missing (required)")


def number(value, where: Where, minimum=None, maximum=None, integer=False, strict=False,
           limit: str = ""):  # fmt: skip
    """A number (bool refused) within bounds; `strict`: strictly above `minimum`; `limit`: why
    the maximum is what it is (what a larger value would cost), for the error."""
    ok = isinstance(value, int) if integer else isinstance(value, (int, float))
    if ok and not integer and isinstance(value, int) and abs(value) > sys.float_info.max:
        ok = False  # no float holds it
    if isinstance(value, bool) or not ok or (not integer and not math.isfinite(value)):
        raise where.error(
            None, f"expected {'an integer' if integer else 'a number'}, got {describe(value)}"
        )
    if minimum is not None and (value <= minimum if strict else value < minimum):
        raise where.error(
            None, f"expected a value {'>' if strict else '>='} {minimum}, got {value}"
        )
    if maximum is not None and value > maximum:
        why = f" ({limit})" if limit else ""
        raise where.error(None, f"expected a value <= {maximum}, got {value}{why}")
    return value if integer else float(value)


def boolean(value, where: Where) -> bool:
    if not isinstance(value, bool):
        raise where.error(None, f"expected true or false, got {describe(value)}")
    return value


def integer(value, where: Where, minimum=None, maximum=None, limit: str = "") -> int:
    return number(value, where, minimum, maximum, integer=True, limit=limit)


def positive(value, where: Where) -> float:
    return number(value, where, minimum=0, strict=True)


def non_negative(value, where: Where) -> float:
    return number(value, where, minimum=0)


def unit(value, where: Where) -> float:
    return number(value, where, minimum=0, maximum=1)


def fixed(value, where: Where, check: Callable, size: int | None):
    """One value through check(value, where), or a list of exactly `size` of them."""
    if size is None:
        return check(value, where)
    if not isinstance(value, list) or len(value) != size:
        raise where.error(None, f"expected a list of {size} numbers, got {describe(value)}")
    return [check(v, where.at(i)) for i, v in enumerate(value)]


def existing(value, base: Path, where: Where) -> Path:
    """A path to something that exists, relative to `base` unless absolute."""
    if not isinstance(value, str) or not value:
        raise where.error(None, f"expected a path, got {describe(value)}")
    if "\0" in value:
        raise where.error(None, f"a path cannot hold a NUL character, got {value!r}")
    try:
        path = Path(value).expanduser()
        path = path if path.is_absolute() else base / path
        found = path.exists()
    except (OSError, RuntimeError) as error:  # a name too long, ~user unknown, ...
        raise where.error(None, f"not a usable path: {value!r} ({error})") from None
    if not found:
        raise where.error(None, f"no such file or folder: {path}")
    return path.resolve()


def _fixed_parameter(value, where: Where, check: Callable, integer: bool = False):
    return check(value, where)


def anatomy(entry, where: Where, base: Path, parameter: Callable = _fixed_parameter) -> dict:
    """An anatomy: ``{phantom: {resolution, seed}}`` or ``{file: ..., prefix, labels,
    dimensions, voxel_size, threshold}`` (as ``ambfplus.load_volume`` takes them), with an
    optional ``name``. `parameter(value, where, check, integer=...)` reads the phantom's values
    (a dataset spec lets them vary; by default they are fixed)."""
    mapping(entry, where, "an anatomy")
    sources = [k for k in ANATOMY_SOURCES if k in entry]
    if len(sources) != 1:
        raise where.error(
            None,
            f"expected exactly one of {', '.join(ANATOMY_SOURCES)}, got {sorted(entry) or 'none'}",
        )
    if sources[0] == "phantom":
        keys(entry, where, optional=("phantom", "name"))
        params = entry["phantom"] if entry["phantom"] is not None else {}
        mapping(params, where.at("phantom"), "phantom options")
        keys(params, where.at("phantom"), optional=("resolution", "seed"))
        return {
            "name": str(entry.get("name", "phantom")),
            "phantom": {
                "resolution": parameter(
                    params.get("resolution", 128),
                    where.at("phantom").at("resolution"),
                    lambda v, w: integer(
                        v,
                        w,
                        minimum=MIN_PHANTOM_RESOLUTION,
                        maximum=MAX_PHANTOM_RESOLUTION,
                        limit=PHANTOM_LIMIT,
                    ),
                    integer=True,
                ),
                "seed": parameter(
                    params.get("seed", 0),
                    where.at("phantom").at("seed"),
                    lambda v, w: integer(v, w, minimum=0, maximum=MAX_PHANTOM_SEED),
                    integer=True,
                ),
            },
        }
    keys(entry, where, optional=ANATOMY_FILE_KEYS)
    path = existing(entry["file"], base, where.at("file"))
    out = {"name": str(entry.get("name", path.name.split(".")[0])), "file": str(path)}
    if "labels" in entry:
        out["labels"] = str(existing(entry["labels"], base, where.at("labels")))
    if "prefix" in entry:
        out["prefix"] = str(entry["prefix"])
    for key in ("dimensions", "voxel_size"):
        if key in entry:
            out[key] = fixed(entry[key], where.at(key), positive, 3)
    if "threshold" in entry:
        out["threshold"] = number(entry["threshold"], where.at("threshold"))
    if path.is_dir() and "dimensions" not in out and "voxel_size" not in out:
        raise where.error(None, f"the slice folder {path} needs dimensions or voxel_size")
    return out
