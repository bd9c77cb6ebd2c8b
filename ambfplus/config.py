"""Checked YAML configuration: the rules every YAML file the package reads (dataset specs,
training tasks) is checked by, so that an error always names the file, the key path and what
was expected, the same way everywhere.

``Where`` is a position (file and key path) that makes errors of the caller's type; the checks
take a value and a ``Where`` and return the value normalised, or raise.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

from ._core import ConfigError

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


# The largest phantom a spec or task may ask for, and what it costs: its label grid and the
# drill's distance fields grow with the cube of the resolution.
MAX_PHANTOM_RESOLUTION = 512
PHANTOM_LIMIT = "a 512^3 phantom takes about 1 GB with its drill's distance fields"


def load_yaml(path: Path, error: type = ConfigError, what: str = "YAML"):
    """A YAML file's content; a missing file, one that is not a regular file, bad YAML or an
    alias (``*name``: a few lines of aliases can expand to billions of nodes) raises `error`
    naming the file (and the line and column)."""
    import yaml

    if not path.is_file():
        if path.exists():
            raise error(f"{path}: not a regular file (a {what} file is read whole)")
        raise error(f"{path}: no such {what} file")
    text = path.read_text()
    try:
        for event in yaml.parse(text, Loader=yaml.SafeLoader):
            if isinstance(event, yaml.AliasEvent):
                mark = event.start_mark
                at = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
                raise error(
                    f"{path}: {at}YAML aliases (*{event.anchor}) are not allowed in a {what} "
                    "file: write the value out"
                )
        return yaml.safe_load(text), text
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" (line {mark.line + 1}, column {mark.column + 1})" if mark else ""
        raise error(f"{path}: not valid YAML{where}: {exc}") from None


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
    path = Path(value).expanduser()
    path = path if path.is_absolute() else base / path
    if not path.exists():
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
                        v, w, minimum=8, maximum=MAX_PHANTOM_RESOLUTION, limit=PHANTOM_LIMIT
                    ),
                    integer=True,
                ),
                "seed": parameter(
                    params.get("seed", 0),
                    where.at("phantom").at("seed"),
                    lambda v, w: integer(v, w, minimum=0),
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
