"""Window state and recent files in a plain JSON file that cannot carry code (issue 13).

Qt's ``QSettings`` INI reader unpickles every ``@Variant(... PyQt_PyObject ...)`` value it
meets, whatever its key, so a planted settings file could run code when the app starts.
eyeviz never lets QSettings read a file: settings are a JSON object of strings, numbers and
lists of strings; byte values (the window geometry) are stored as base64 text. A file that
is not such an object, contains ``@Variant(`` or a pickle, is larger than MAX_BYTES or is
not a regular file (a FIFO blocked the app forever, /dev/zero read until MemoryError:
issue 35) is refused with a one-line message and ignored: the app starts with defaults
and never writes over the refused file.

Path: ``--settings`` > ``$EYEVIZ_SETTINGS`` > ``$XDG_CONFIG_HOME/eyeviz/settings.json``
(default ``~/.config/eyeviz/settings.json``).
"""

from __future__ import annotations

import base64
import json
import os
import stat
import sys
from pathlib import Path
from typing import Any

from eyeviz import EyevizError
from eyeviz.files.atomic import atomic_output

__all__ = ["MAX_BYTES", "Settings", "default_path", "make_settings"]

MAX_BYTES = 1 << 20
_ALLOWED = (str, int, float, bool, type(None))
_HOSTILE = (b"@Variant(", b"@ByteArray(", b"PyQt_PyObject", b"\x80\x02", b"\x80\x03", b"\x80\x04")


def default_path() -> Path:
    base = os.environ.get("XDG_CONFIG_HOME") or str(Path.home() / ".config")
    return Path(base) / "eyeviz" / "settings.json"


def _plain(v) -> bool:
    if isinstance(v, _ALLOWED):
        return True
    return isinstance(v, list) and all(isinstance(x, _ALLOWED) for x in v)


class Settings:
    """A QSettings-like store (``value``, ``setValue``, ``sync``) backed by JSON."""

    def __init__(self, path: str | os.PathLike | None = None) -> None:
        self.path = Path(path) if path else default_path()
        self.data: dict = {}
        self.refused: str = ""  # why the file was ignored, one line
        self.read_only = False  # read, never written (``eyeviz app --screenshot``)
        self._read()

    def _refuse(self, why: str) -> None:
        self.refused = f"eyeviz: ignoring settings file {self.path}: {why}"
        print(self.refused, file=sys.stderr)

    def _read(self) -> None:
        if not self.path.exists() and not self.path.is_symlink():
            return  # no file yet: defaults
        try:
            raw = _read_regular(self.path, MAX_BYTES)
        except _NotRegular:
            return self._refuse("not a regular file")
        except OSError as exc:
            return self._refuse(f"cannot read it ({exc.strerror})")
        if raw is None:
            return self._refuse(f"larger than {MAX_BYTES} bytes")
        if any(tok in raw for tok in _HOSTILE):
            return self._refuse("it holds a Qt @Variant / pickled value, which could run code")
        try:
            doc = json.loads(raw.decode("utf-8"))
        except (UnicodeDecodeError, ValueError, RecursionError):
            return self._refuse("not a JSON settings file (old INI settings are not read)")
        if not isinstance(doc, dict) or not all(
            isinstance(k, str) and _plain(v) for k, v in doc.items()
        ):
            return self._refuse("not an object of strings, numbers and lists of strings")
        self.data = doc

    def value(self, key: str, default: Any = None) -> Any:
        """The stored value; keys ending in ``@bytes`` are decoded from base64."""
        if key in self.data:
            return self.data[key]
        b = self.data.get(key + "@bytes")
        if isinstance(b, str):
            try:
                return base64.b64decode(b, validate=True)
            except ValueError:
                return default
        return default

    def setValue(self, key: str, value: Any) -> None:  # noqa: N802 (QSettings' name)
        if isinstance(value, (bytes, bytearray, memoryview)) or type(value).__name__ == (
            "QByteArray"
        ):
            self.data.pop(key, None)
            self.data[key + "@bytes"] = base64.b64encode(bytes(value)).decode("ascii")
            return
        if not _plain(value):
            raise TypeError(f"settings hold only plain values, not {type(value).__name__}")
        self.data.pop(key + "@bytes", None)
        self.data[key] = value

    def sync(self) -> None:
        """Write the file (atomically); a refused file is never overwritten, a read-only
        one never written."""
        if self.refused or self.read_only:
            return
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            with atomic_output(self.path) as tmp:
                Path(tmp).write_text(json.dumps(self.data, indent=1), encoding="utf-8")
        except (OSError, EyevizError) as exc:
            print(f"eyeviz: cannot write settings {self.path}: {exc}", file=sys.stderr)


class _NotRegular(Exception):
    pass


def _read_regular(path: Path, max_bytes: int) -> bytes | None:
    """The bytes of the regular file at ``path`` (None when larger than ``max_bytes``).

    Opened without blocking (a FIFO with no writer would block ``open`` forever) and
    checked on the open descriptor, so nothing can be swapped in between; at most
    ``max_bytes + 1`` bytes are read whatever the file claims."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise _NotRegular
        if st.st_size > max_bytes:
            return None
        os.set_blocking(fd, True)
        chunks, got = [], 0
        while got <= max_bytes and (chunk := os.read(fd, max_bytes + 1 - got)):
            chunks.append(chunk)
            got += len(chunk)
    finally:
        os.close(fd)
    return None if got > max_bytes else b"".join(chunks)


def make_settings(path: str | os.PathLike | None = None) -> Settings:
    """Settings from ``path``, else $EYEVIZ_SETTINGS, else the user's config directory."""
    return Settings(path or os.environ.get("EYEVIZ_SETTINGS") or None)
