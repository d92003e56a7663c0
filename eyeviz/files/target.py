"""What an output path names, and writing through one that is not a regular file.

An output is written as a temporary file renamed over the target
(:func:`eyeviz.files.atomic.atomic_output`). A rename over a character device or a FIFO
would replace it with a regular file (``-o /dev/null`` run as root would replace the
system's /dev/null; issue 35): such a target is instead opened as it is before any work
and, once the output is complete, the temporary file's bytes are written into it. Every
other kind of file that is not a regular file (a folder, a block device, a socket, a link
loop) is refused in one line. A link is followed: its target is what is written.
"""

from __future__ import annotations

import errno
import os
import stat
import tempfile
from dataclasses import dataclass
from pathlib import Path

from eyeviz import EyevizError

__all__ = ["Target", "open_through", "resolve_output", "write_through"]

_COPY = 1 << 20  # bytes per write into a device or FIFO


@dataclass(frozen=True)
class Target:
    """An output path after its links are followed.

    ``kind`` is ``"new"`` (nothing there yet), ``"file"`` (a regular file), ``"char"``
    (a character device) or ``"fifo"``; ``folder`` is where the temporary file goes (the
    target's own folder for a file, the temporary directory for a device or FIFO, whose
    folder may be /dev).
    """

    path: Path
    kind: str
    folder: Path

    @property
    def through(self) -> bool:
        """True when the output is written into the target, not renamed over it."""
        return self.kind in ("char", "fifo")


def _follow(path: Path) -> Path:
    if not path.is_symlink():
        return path
    try:
        return Path(os.path.realpath(path, strict=True))
    except FileNotFoundError:
        return Path(os.path.realpath(path))  # a dangling link: its target is created
    except OSError as exc:
        raise EyevizError(f"output {str(path)!r}: {exc.strerror or 'a link loop'}") from None


def _what(mode: int) -> str:
    for test, name in (
        (stat.S_ISDIR, "a directory"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return name
    return "not a regular file"


def resolve_output(path: str | os.PathLike) -> Target:
    """The :class:`Target` ``path`` names; one-line EyevizError for an output that can be
    neither replaced nor written through, or whose folder does not exist. A command may
    call it before any work; :func:`eyeviz.files.atomic.atomic_output` calls it again."""
    path = _follow(Path(path))
    try:
        st = os.stat(path)
    except FileNotFoundError:
        st = None
    except OSError as exc:
        raise EyevizError(f"output {str(path)!r}: {exc.strerror}") from None
    if st is None or stat.S_ISREG(st.st_mode):
        folder = path.parent if str(path.parent) else Path(".")
        if not folder.is_dir():
            raise EyevizError(f"output directory does not exist: {str(folder)!r}")
        return Target(path, "new" if st is None else "file", folder)
    if stat.S_ISCHR(st.st_mode) or stat.S_ISFIFO(st.st_mode):
        kind = "char" if stat.S_ISCHR(st.st_mode) else "fifo"
        return Target(path, kind, Path(tempfile.gettempdir()))
    raise EyevizError(
        f"output {str(path)!r} is {_what(st.st_mode)}; eyeviz writes a regular file, "
        "or writes through a character device or a FIFO"
    )


def open_through(t: Target) -> int:
    """A write descriptor on a device or FIFO target, opened before any work.

    A FIFO with no reader is refused (opening it would block until one came)."""
    flags = os.O_WRONLY | getattr(os, "O_CLOEXEC", 0)
    try:
        if t.kind == "fifo":
            fd = os.open(t.path, flags | os.O_NONBLOCK)
            os.set_blocking(fd, True)
            return fd
        return os.open(t.path, flags)
    except OSError as exc:
        if exc.errno == errno.ENXIO:
            msg = f"output {str(t.path)!r} is a FIFO with no reader; start its reader first"
            raise EyevizError(msg) from None
        raise EyevizError(f"cannot write {str(t.path)!r}: {exc.strerror}") from None


def write_through(src: Path, fd: int, t: Target) -> None:
    """Write the bytes of the finished temporary file ``src`` into ``fd``."""
    try:
        with open(src, "rb") as f:
            while chunk := f.read(_COPY):
                view = memoryview(chunk)
                while view:
                    view = view[os.write(fd, view) :]
    except BrokenPipeError:
        raise EyevizError(f"output {str(t.path)!r}: the FIFO's reader went away") from None
