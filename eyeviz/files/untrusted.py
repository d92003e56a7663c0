"""Opening untrusted files: only regular files, bounded, and never outside a folder.

:func:`open_regular` opens without blocking (a FIFO would block ``open()`` for good) and
checks the *opened* file with ``fstat``, so a path swapped for a FIFO, a device such as
``/dev/zero`` or a folder between a check and the open is still refused.
:func:`resolve_inside` turns a reference found in a file (a glTF buffer's ``uri``) into a
path that stays inside the referring file's folder after every symlink is followed.
"""

from __future__ import annotations

import contextlib
import os
import stat
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO
from urllib.parse import unquote

from eyeviz import EyevizError

__all__ = ["open_regular", "read_regular", "resolve_inside"]


@contextlib.contextmanager
def open_regular(path, max_bytes: int, what: str = "file") -> Iterator[tuple[BinaryIO, int]]:
    """(binary file, size) of a regular file of at most ``max_bytes`` bytes."""
    p = str(path)
    try:
        fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0))
    except OSError as exc:
        raise EyevizError(f"cannot read {what} {p!r}: {exc.strerror}") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise EyevizError(f"{what} {p!r} is not a regular file")
        if st.st_size > max_bytes:
            raise EyevizError(f"{what} {p!r} is {st.st_size} bytes, more than {max_bytes}")
        f = os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise
    with f:
        yield f, st.st_size


def read_regular(path, max_bytes: int, what: str = "file") -> bytes:
    """The bytes of a regular file, reading at most ``max_bytes + 1`` whatever it claims."""
    with open_regular(path, max_bytes, what) as (f, _):
        data = f.read(max_bytes + 1)
    if len(data) > max_bytes:
        raise EyevizError(f"{what} {str(path)!r} is larger than {max_bytes} bytes")
    return data


def resolve_inside(folder, ref: str, what: str) -> Path:
    """The file a relative URI reference ``ref`` names inside ``folder``.

    Refused: a scheme (``http:``, ``file:``), an absolute path, a ``..`` segment, a
    backslash or NUL, and any path whose real location (symlinks followed) is not inside
    the real ``folder``."""
    if not isinstance(ref, str) or not ref:
        raise EyevizError(f"{what}: the uri must be a non-empty string")
    head = ref.split("/", 1)[0]
    if ":" in head or ref.startswith(("/", "\\")) or "\\" in ref:
        raise EyevizError(f"{what}: uri {ref[:80]!r} is not a relative path in the file's folder")
    rel = unquote(ref)
    parts = rel.split("/")
    if "\0" in rel or ".." in parts or rel.startswith("/") or not rel.strip("/"):
        raise EyevizError(f"{what}: uri {ref[:80]!r} leaves the file's folder")
    base = Path(os.path.realpath(folder))
    target = Path(os.path.realpath(base / rel))
    if not target.is_relative_to(base) or target == base:
        raise EyevizError(f"{what}: uri {ref[:80]!r} leads outside the file's folder")
    return target
