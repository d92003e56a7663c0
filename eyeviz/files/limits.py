"""Bounds on the files a user hands in or a run writes (issue 13), as named constants.

Only limits about *files* live here: bytes, rows, declared array shapes and counts a file
controls. The bounds of the model (m, nside, r, phi) and of a run's options are
:mod:`eyeviz.core.bounds`; the integer rule is :func:`eyeviz.core.validation.check_int`.

Each ``check_*`` raises :class:`eyeviz.EyevizError` with a one-line message naming the
value and the bound; a value beyond a bound is refused, never clamped. Readers call
these *before* allocating anything the file declares.
"""

from __future__ import annotations

import errno
import os
import shutil
import stat
from pathlib import Path

from eyeviz import EyevizError
from eyeviz.core import bounds
from eyeviz.core.validation import check_int

#: Rows of a generated data set (``eyeviz generate -n``).
MAX_ROWS = 10**9
#: Scene TOML files: room for MAX_FEATURES features with full-precision coordinates and
#: names of MAX_NAME_CHARS (about 4 MB; a file Save writes must load back).
MAX_SCENE_BYTES = 8 << 20
#: A study table (``eyeviz study -o STUDY.csv``; one row per design point and distance bin).
MAX_STUDY_BYTES = 1 << 28
#: Features drawn in one scene / snapshot.
MAX_FEATURES = 10**4
#: Width of a hidden layer read from a model directory, and total parameters of a model.
MAX_HIDDEN = 4096
MAX_MODEL_PARAMS = 50_000_000
#: Size of one model file (weights, a posterior table) and of its JSON metadata.
MAX_MODEL_FILE_BYTES = 1 << 30
MAX_MODEL_META_BYTES = 1 << 20
#: Keys of a posterior table (bayes.npz; the shipped one has 371,494).
MAX_TABLE_KEYS = 50_000_000
#: Length of a feature name in a scene.
MAX_NAME_CHARS = 200
#: Measured eye files (``.eye``, ``.gltf``, ``.glb`` and a glTF's external buffers): bytes
#: of one file, and ommatidia (rows) in all; two eyes of the model's MAX_FACETS each
#: (:mod:`eyeviz.core.measured`). A ``.eye`` row with full-precision numbers is about 160
#: bytes.
MAX_EYE_FILE_BYTES = 1 << 29
MAX_EYE_ROWS = 2_000_000
#: The JSON part of a glTF (nodes, accessors, a base64 buffer inside a ``data:`` URI).
MAX_GLTF_JSON_BYTES = 1 << 29
#: glTF objects of one kind (nodes, accessors, buffer views, buffers, OCES eyes).
MAX_GLTF_OBJECTS = 10_000


def check_rows(n, name: str = "n") -> int:
    """Rows of a data set: an integer in [1, MAX_ROWS]."""
    return check_int(name, n, ge=1, le=MAX_ROWS)


def check_model_shape(name: str, shape, max_dim: int = bounds.MAX_M) -> tuple[int, ...]:
    """A tensor shape read from a model file, checked before anything is allocated:
    every dimension in [1, max_dim] and at most MAX_MODEL_PARAMS elements in all.

    For the hidden width of a network use :func:`check_hidden` (at most MAX_HIDDEN);
    e.g. ``check_model_shape("compact_dd.pt: net.0.weight", (hidden, m))``."""
    try:
        dims = tuple(int(d) for d in shape)
    except (TypeError, ValueError, OverflowError):
        msg = f"model {name}: shape must be a list of integers, got {shape!r}"
        raise EyevizError(msg) from None
    total = 1
    for d in dims:
        if not 1 <= d <= max_dim:
            raise EyevizError(f"model {name}: dimension {d} outside [1, {max_dim}]")
        total *= d
    if total > MAX_MODEL_PARAMS:
        raise EyevizError(f"model {name}: {total} parameters exceed {MAX_MODEL_PARAMS}")
    return dims


def check_hidden(name: str, hidden) -> int:
    """A hidden width declared by a model directory (e.g. ``compact_dd.pt`` hidden=30000)."""
    return check_int(f"model {name}: hidden width", hidden, ge=1, le=MAX_HIDDEN)


#: What a path that is not a regular file is, by its stat mode (for one-line refusals).
_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def check_regular_file(path, what: str = "file") -> os.stat_result:
    """The stat of ``path`` when it is a regular file (or a link to one); else one line
    saying what it is instead (issue 36: ``predict`` said "not found" for a directory, a
    FIFO, /dev/zero and a symlink loop alike)."""
    p = Path(path)
    try:
        st = p.stat()
    except OSError as exc:
        if exc.errno == errno.ENOENT:
            why = "not found" if not p.is_symlink() else "a symbolic link to nothing"
            raise EyevizError(f"{what} {str(p)!r}: {why}") from None
        if exc.errno == errno.ELOOP:
            raise EyevizError(f"{what} {str(p)!r}: a loop of symbolic links") from None
        raise EyevizError(f"cannot read {what} {str(p)!r}: {exc.strerror}") from None
    if not stat.S_ISREG(st.st_mode):
        kind = next((k for test, k in _KINDS if test(st.st_mode)), "of another kind")
        raise EyevizError(f"{what} {str(p)!r} is not a regular file: it is {kind}")
    return st


def check_file_size(path, max_bytes: int, what: str = "file") -> int:
    """A regular file no larger than ``max_bytes`` (refuses /dev/zero, FIFOs, folders)."""
    p = Path(path)
    st = check_regular_file(p, what)
    if st.st_size > max_bytes:
        raise EyevizError(f"{what} {str(p)!r} is {st.st_size} bytes, more than {max_bytes}")
    return st.st_size


def read_bounded(path, max_bytes: int, what: str = "file") -> bytes:
    """The bytes of a regular file, reading at most ``max_bytes + 1`` whatever it claims."""
    check_file_size(path, max_bytes, what)
    with open(path, "rb") as f:
        data = f.read(max_bytes + 1)
    if len(data) > max_bytes:
        raise EyevizError(f"{what} {str(path)!r} is larger than {max_bytes} bytes")
    return data


def check_free_space(path, needed_bytes: int) -> None:
    """Refuse an output whose estimated size exceeds the free space of its folder."""
    d = Path(path).parent if str(Path(path).parent) else Path(".")
    try:
        free = shutil.disk_usage(d).free
    except OSError:
        return
    if needed_bytes > free:
        raise EyevizError(
            f"output {str(path)!r} would need about {needed_bytes / 1e9:.3g} GB, "
            f"only {free / 1e9:.3g} GB free in {str(d)!r}"
        )


def estimated_output_bytes(n: int, m: int, fmt: str) -> int:
    """Upper-ish estimate of a data set file: CSV 2 bytes per bit + ~60 per row of floats;
    NPZ m/8 + 24 bytes per row."""
    if fmt == "csv":
        return n * (2 * m + 60)
    return n * (2 * ((m // 2 + 7) // 8) + 24)
