"""The command line's one error path: an exception a command raised, as the one line ``main``
prints on stderr (exit status 2).

- An error of the package's own types (``ambfplus.Error`` and every exception class defined in
  ``ambfplus``) is its message: it names the file and what was expected.
- An ``OSError`` is its file and what to do (``_OS_ADVICE``: a missing file, a folder where a
  file was expected, a full or read-only disk, ...); an ``ImportError``, its message (an extra
  to install).
- Anything else is bad input that no check caught yet, or a bug: its type and message, and how
  to see the traceback (``ambfplus --debug``).

A message that names none of the command's arguments is prefixed with its first argument (its
input), so that the line always says which file it is about.
"""

from __future__ import annotations

import argparse
import errno
import os
import sys
from pathlib import Path

# The longest line printed; a message can quote a whole value.
MAX_LINE = 1000

# errno -> what happened and what to do, for the OS errors a command meets on bad arguments.
_OS_ADVICE = {
    errno.ENOENT: "no such file or folder: check the path",
    errno.EACCES: "permission denied: check its permissions, or use another path",
    errno.EPERM: "operation not permitted: use another path",
    errno.EISDIR: "a folder, where a file is expected: name a file",
    errno.ENOTDIR: "a part of the path is not a folder: check the path",
    errno.EEXIST: "already exists: remove it or choose another path",
    errno.ENOTEMPTY: "the folder is not empty: remove what it holds or choose another path",
    errno.ENOSPC: "no space left on the device: free some space or write elsewhere",
    errno.EDQUOT: "disk quota exceeded: free some space or write elsewhere",
    errno.EFBIG: "file too large for this file system: write elsewhere",
    errno.EROFS: "a read-only file system: write elsewhere",
    errno.ENAMETOOLONG: "file name too long: use a shorter path",
    errno.ELOOP: "too many levels of symbolic links: check the links",
    errno.ENXIO: "no such device or address (a FIFO with no reader?): name a regular file",
    errno.EIO: "input/output error: the disk or file system failed; check it",
    errno.EMFILE: "too many open files: raise the limit (ulimit -n)",
    errno.ENFILE: "too many open files in the system: close some",
    errno.EPIPE: "broken pipe: the output was closed",
    errno.EXDEV: "across file systems: use a path on the same file system",
}
# Errors of writing: a message without a file name names the command's output.
_WRITING = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS)
# Options that name an output.
_OUTPUTS = ("out", "output", "json", "report")


def command_name(args: argparse.Namespace) -> str:
    """``ambfplus <command>`` (with its own subcommand, as ``dataset info``)."""
    words = ["ambfplus", getattr(args, "command", None) or ""]
    sub = getattr(args, f"{words[1].replace('-', '_')}_command", None)
    return " ".join(w for w in [*words, sub] if w)


def report(args: argparse.Namespace, error: BaseException | str) -> int:
    """Prints the one line for `error` (or a command's own message) on stderr; returns 2."""
    print(line(args, error), file=sys.stderr, flush=True)
    return 2


def line(args: argparse.Namespace, error: BaseException | str) -> str:
    """The one line (see the module) that names the file or argument and what to do."""
    prefix = f"{command_name(args)}: "
    named = False
    if isinstance(error, str):
        message = error.removeprefix(prefix)
    elif isinstance(error, OSError) and error.errno is not None:
        message, named = _os_message(args, error)
    elif _ours(error) or isinstance(error, (OSError, ImportError)):
        message = _text(error)
    else:
        message = _untyped(error)
    given = _given(args)
    if not named and given and not any(value in message for value in _arguments(args)):
        message = f"{given}: {message}"
    return _one_line(prefix + message)


def _ours(error: BaseException) -> bool:
    """An exception of a type the package defines (and so raises on purpose, with a message)."""
    return any(cls.__module__.split(".")[0] == "ambfplus" for cls in type(error).__mro__)


def _text(error: BaseException) -> str:
    """An exception's message (a KeyError's without the quotes repr adds), or its type's name."""
    if isinstance(error, KeyError) and len(error.args) == 1 and isinstance(error.args[0], str):
        return error.args[0]
    return str(error) or type(error).__name__


def _os_message(args: argparse.Namespace, error: OSError) -> tuple[str, bool]:
    """``file: what happened: what to do`` for an OS error, and whether it names a file."""
    code = error.errno
    assert code is not None
    standard = error.strerror in (None, os.strerror(code))
    reason = _OS_ADVICE.get(code, os.strerror(code).lower()) if standard else str(error.strerror)
    names = [os.fsdecode(n) for n in (error.filename, error.filename2) if n is not None]
    if not names and code in _WRITING:
        names = [str(v) for v in (getattr(args, k, None) for k in _OUTPUTS) if v is not None][:1]
    if not names or names[0] in reason:
        return reason, bool(names)
    return f"{' -> '.join(names)}: {reason}", True


def _untyped(error: BaseException) -> str:
    """An error no check turned into a message: what it says, and where to see more."""
    if isinstance(error, UnicodeDecodeError):
        byte = error.object[error.start : error.start + 1].hex()
        what = f"byte 0x{byte} at offset {error.start} is not {error.encoding} text"
    elif isinstance(error, RecursionError):
        what = "nested too deeply to read"
    elif isinstance(error, MemoryError):
        what = "out of memory"
    elif isinstance(error, KeyError) and len(error.args) == 1:
        what = f"no {error.args[0]!r}"
    else:
        what = _text(error)
    return (
        f"{what} ({type(error).__name__}: a damaged input or a bug; "
        "rerun with ambfplus --debug for the traceback)"
    )


def _arguments(args: argparse.Namespace) -> list[str]:
    """The paths and words the command was given (options left at their defaults are not), as
    a message would quote them."""
    defaults = getattr(args, "_defaults", {})
    out: list[str] = []
    for name, value in vars(args).items():
        if (
            name in ("func", "command", "debug")
            or name.startswith("_")
            or name.endswith("_command")
        ):
            continue
        if name in defaults and value == defaults[name]:
            continue
        for item in value if isinstance(value, list) else [value]:
            if isinstance(item, (str, Path)) and len(str(item)) > 2:
                out.append(str(item))
    return out


def _given(args: argparse.Namespace) -> str | None:
    """The command's first argument that the user must give (a positional one or a required
    option: its input, for every command that has one), as ``main`` lists them in
    ``args._inputs``."""
    for name in getattr(args, "_inputs", ()):
        value = getattr(args, name, None)
        for item in value if isinstance(value, list) else [value]:
            if isinstance(item, (str, Path)):
                return str(item)
    return None


def _one_line(text: str) -> str:
    """Whitespace runs with a line break in them as one space, and at most MAX_LINE
    characters."""
    flat = " ".join(part.strip() for part in text.splitlines() if part.strip())
    return flat if len(flat) <= MAX_LINE else flat[: MAX_LINE - 3] + "..."
