"""Writing files whole: a reader sees the old file (or folder) or the new one, never a partial
one. Every writer in the package that replaces an output in place goes through here: the
recording's parts and head, a dataset's manifest and environment, exports, the launcher's status
file.

A file is written to its temporary name beside it (``<name>.tmp``, on the same file system) and
renamed into place, which POSIX makes atomic. Readers and validators ignore ``.tmp`` files."""

from __future__ import annotations

import contextlib
import os
import shutil
from collections.abc import Iterable, Iterator
from pathlib import Path


def temporary_name(path: Path) -> Path:
    """Where ``path`` is written before it is renamed into place."""
    path = Path(path)
    return path.with_name(path.name + ".tmp")


def remove(path: Path) -> None:
    """Removes a file, a link or a folder tree; nothing if there is none."""
    path = Path(path)
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    elif path.exists() or path.is_symlink():
        path.unlink()


@contextlib.contextmanager
def written_whole(path: Path) -> Iterator[Path]:
    """Yields the temporary path to write ``path``'s new content to (a file or a folder); once
    the body ends it replaces ``path``, and if the body fails it is removed, leaving ``path``
    as it was."""
    path = Path(path)
    temporary = temporary_name(path)
    remove(temporary)
    try:
        yield temporary
        if not temporary.exists():
            raise FileNotFoundError(f"{path}: nothing was written to {temporary}")
        if temporary.is_dir() or (path.is_dir() and not path.is_symlink()):
            remove(path)  # a rename replaces a file by a file only
        os.replace(temporary, path)
    except BaseException:
        remove(temporary)
        raise


def write_text(path: Path, text: str) -> None:
    """Writes text to ``path`` whole (see the module)."""
    with written_whole(path) as temporary:
        temporary.write_text(text)


def write_bytes(path: Path, data: bytes) -> None:
    """Writes bytes to ``path`` whole (see the module)."""
    with written_whole(path) as temporary:
        temporary.write_bytes(data)


class OwnInputError(ValueError):
    """An output that would write over the command's own input."""


def refuse_writing_over(out, inputs: Iterable, command: str, error: type = OwnInputError) -> None:
    """Raises `error` if the output `out` is one of `inputs`, lies inside one (an input folder)
    or holds one (an output folder that would be replaced or filled): a command never writes
    over its own input, with --force or without. Paths are compared resolved (links followed),
    and by identity where both exist (hard links); checked before anything is written."""
    out = Path(out)
    target = out.resolve()
    for source in inputs:
        source = Path(source)
        found = source.resolve()
        same = target == found or (
            out.exists() and source.exists() and os.path.samefile(out, source)
        )
        if same or found in target.parents or target in found.parents:
            relation = "is" if same else "lies inside" if found in target.parents else "holds"
            raise error(
                f"{out}: the output {relation} the input {source}; {command} never writes over "
                "its own input (with --force or without): choose another output"
            )


def require_regular_file(path: Path, what: str, error: type = FileNotFoundError) -> None:
    """Raises `error` naming `path` unless it is a regular file (after links): what it is
    instead (missing, a folder, a FIFO, a socket, a device), so that nothing blocks opening a
    FIFO and no folder is called missing (the engine's readers say the same: util/files.h)."""
    import stat

    try:
        mode = Path(path).stat().st_mode
    except FileNotFoundError:
        raise error(f"{path}: no such {what}") from None
    except OSError as failure:
        raise error(f"{path}: cannot read this {what} ({failure.strerror})") from None
    if stat.S_ISREG(mode):
        return
    kind = (
        "a folder" if stat.S_ISDIR(mode)
        else "a FIFO" if stat.S_ISFIFO(mode)
        else "a socket" if stat.S_ISSOCK(mode)
        else "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode)
        else "something else"
    )  # fmt: skip
    raise error(f"{path}: not a regular file but {kind} (a {what} is read from a file)")
