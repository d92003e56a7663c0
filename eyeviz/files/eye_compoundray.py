"""CompoundRay ``.eye`` files: one ommatidium a line (docs/eye_files.md).

A line holds 8 numbers: lens position x y z, axis x y z, full acceptance angle (rad) and
focal offset (the distance back into the eye where the sampling cone's tip sits);
millimetres by CompoundRay's ``data/eyes/eye-specification.txt``. CompoundRay's own
reader splits a line on spaces (runs of spaces count as one) and reads the first 8
numbers; its specification calls the files CSVs. eyeviz reads numbers separated by
spaces, tabs or commas, skips blank lines, accepts ``\\r\\n`` line ends, and accepts 7
numbers a line (the older files without a focal offset) when every line has 7. Anything
else (a 9th number, a word, ``nan``, ``1e999``) is refused, naming the line.

Both eyes are in one file: eye A is the lenses at x < 0 of eyeviz's frame, eye B the
others, each in file order. Writing puts eye A's lines first, every number as Python's
shortest round-trip ``repr``, so a pair written and read back (same frame, mm) is equal
to the last bit.
"""

from __future__ import annotations

import math
import os

import numpy as np

from eyeviz import EyevizError
from eyeviz.files import limits
from eyeviz.files.eye_frames import Frame
from eyeviz.files.untrusted import read_regular

__all__ = ["read_eye_rows", "format_eye_rows"]

_ALLOWED = b"0123456789.eE+-, \t\r\n"
_SEP = np.zeros(256, dtype=bool)
_SEP[[ord(c) for c in " \t\r\n,"]] = True
_CHUNK = 1 << 23


def _line_of(data: bytes, pos: int) -> int:
    return data.count(b"\n", 0, pos) + 1


def _bad_token(data: bytes, line: int, name: str) -> EyevizError:
    text = data.split(b"\n", line)[line - 1] if line > 0 else b""
    for tok in text.replace(b",", b" ").split():
        try:
            # 'nan', 'inf' and '1_0' are Python floats, not the format's numbers
            if tok.strip(_ALLOWED):
                raise ValueError
            float(tok)
        except ValueError:
            shown = tok[:40].decode("ascii", "replace")
            return EyevizError(f"{name}: line {line}: {shown!r} is not a number")
    shown = text[:60].decode("ascii", "replace")
    return EyevizError(f"{name}: line {line}: not 8 numbers: {shown!r}")


def _token_counts(data: bytes) -> tuple[np.ndarray, np.ndarray]:
    """Tokens on each line and each line's 1-based number (lines with tokens only)."""
    arr = np.frombuffer(data, dtype=np.uint8)
    sep = _SEP[arr]
    start = ~sep
    start[1:] &= sep[:-1]
    nl = np.flatnonzero(arr == 10)
    starts = np.flatnonzero(start)
    line = np.searchsorted(nl, starts)  # 0-based line of each token
    counts = np.bincount(line, minlength=nl.size + 1)
    lines = np.flatnonzero(counts)
    return counts[lines], lines + 1


def _chunks(data: bytes):
    """(start, end, lines before start) of pieces of about _CHUNK bytes cut after a line
    end: the file is tokenised piece by piece, to bound the memory a big file takes."""
    pos, line0 = 0, 0
    while pos < len(data):
        end = data.find(b"\n", min(pos + _CHUNK, len(data)))
        end = len(data) if end < 0 else end + 1
        yield pos, end, line0
        line0 += data.count(b"\n", pos, end)
        pos = end


def _numbers(chunk: bytes, data: bytes, line0: int, name: str) -> np.ndarray:
    """The numbers of one piece, in order; a bad token names its line."""
    toks = chunk.replace(b",", b" ").split()
    try:
        return np.array(toks, dtype=np.float64) if toks else np.zeros(0)
    except ValueError:
        for i, text in enumerate(chunk.split(b"\n")):
            for tok in text.replace(b",", b" ").split():
                try:
                    float(tok)
                except ValueError:
                    raise _bad_token(data, line0 + i + 1, name) from None
        raise


def _check_rows(rows: np.ndarray, lines: np.ndarray, name: str) -> None:
    """Non-finite numbers, zero axes and acceptance outside (0, pi), naming the line."""
    bad = ~np.isfinite(rows).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise EyevizError(f"{name}: line {lines[i]}: a number is not finite ({rows[i].tolist()})")
    zero = ~(rows[:, 3:6] != 0).any(axis=1)
    if zero.any():
        i = int(np.flatnonzero(zero)[0])
        raise EyevizError(f"{name}: line {lines[i]}: the axis is zero")
    acc = rows[:, 6]
    out = ~((acc > 0) & (acc < math.pi))
    if out.any():
        i = int(np.flatnonzero(out)[0])
        raise EyevizError(
            f"{name}: line {lines[i]}: acceptance angle {float(acc[i])!r} rad is not in (0, pi)"
        )


def read_eye_rows(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray]:
    """(rows (n, 7 or 8) float64 in the file's frame and units, their 1-based line numbers).

    Bounded: a file over :data:`limits.MAX_EYE_FILE_BYTES` is refused before a byte is
    read, one of over :data:`limits.MAX_EYE_ROWS` lines before a number is parsed."""
    name = os.path.basename(str(path))
    data = read_regular(path, limits.MAX_EYE_FILE_BYTES, "eye file")
    nlines = data.count(b"\n") + 1
    if nlines > limits.MAX_EYE_ROWS:
        raise EyevizError(
            f"{name}: {nlines} lines, more than the bound of {limits.MAX_EYE_ROWS} ommatidia"
        )
    rest = data.translate(None, _ALLOWED)
    if rest:
        pos = data.find(rest[:1])
        raise _bad_token(data, _line_of(data, pos), name)
    k, first, rows_, lines_ = 0, 0, [], []
    for start, end, line0 in _chunks(data):
        counts, lines = _token_counts(data[start:end])
        if counts.size == 0:
            continue
        lines += line0
        if not k:
            k, first = int(counts[0]), int(lines[0])
            if k not in (7, 8):
                raise EyevizError(f"{name}: line {first}: {k} numbers, expected 8 (or 7)")
        off = np.flatnonzero(counts != k)
        if off.size:
            i = int(off[0])
            raise EyevizError(
                f"{name}: line {lines[i]}: {counts[i]} numbers, expected {k} as on line {first}"
            )
        rows_.append(_numbers(data[start:end], data, line0, name).reshape(-1, k))
        lines_.append(lines)
    if not k:
        raise EyevizError(f"{name}: no ommatidia (the file has no numbers)")
    rows, lines = np.concatenate(rows_), np.concatenate(lines_)
    _check_rows(rows, lines, name)
    return rows, lines


def split_rows(rows: np.ndarray, frame: Frame, scale: float, name: str):
    """Map rows to eyeviz's frame and mm; split them into eye A (x < 0) and eye B.

    Returns ((pos, axes, acc, fo) of A, the same of B); fo is None for 7-number rows."""
    pos = frame.to_eyeviz(rows[:, 0:3]) * scale
    ax = frame.to_eyeviz(rows[:, 3:6])
    acc = rows[:, 6].copy()
    fo = rows[:, 7] * scale if rows.shape[1] > 7 else None
    a = pos[:, 0] < 0
    if a.all() or not a.any():
        side = "x < 0" if a.all() else "x >= 0"
        raise EyevizError(
            f"{name}: every lens is at {side} in eyeviz's frame (frame {frame.text!r}): "
            "one eye, not a pair; check the frame (the eyes must lie on either side of x = 0)"
        )
    return tuple((pos[s], ax[s], acc[s], None if fo is None else fo[s]) for s in (a, ~a))


def format_eye_rows(eyes, frame: Frame, scale: float) -> str:
    """The text of a ``.eye`` file: each eye's (pos, axes, acc, fo) in eyeviz's frame and
    mm, written in ``frame`` and units of ``scale`` mm, every number as ``repr``."""
    lines: list[str] = []
    for pos, ax, acc, fo in eyes:
        p = frame.from_eyeviz(np.asarray(pos, np.float64))
        if scale != 1.0:
            p = p / scale
        a = frame.from_eyeviz(np.asarray(ax, np.float64))
        f = np.zeros(len(acc)) if fo is None else np.asarray(fo, np.float64) / scale
        block = np.column_stack([p, a, np.asarray(acc, np.float64), f])
        lines.extend(" ".join(map(repr, r)) for r in block.tolist())
    return "\n".join(lines) + "\n"
