"""Reading data set files (docs/contract.md) row by row validated, whole or in blocks.

Every reader validates per row and field and names the first bad line (CSV) or row
(NPZ); an NPZ's declared shape is checked against its member's size before anything is
allocated, compressed members and short packed rows are refused, and ``np.load``-style
pickles are never read (the members are parsed with ``np.lib.format`` headers only).
:func:`iter_blocks` streams a file of any size in bounded memory; :func:`load` reads it
whole. Both are re-exported by :mod:`eyeviz.dataset.io` (the stable path); what readers and
writers share is :mod:`eyeviz.dataset.formats`.

The CSV and NPZ readers share the block reader and the per-line diagnosis that names the
first bad line and column.
"""

from __future__ import annotations

import itertools
import json
import zipfile
from collections.abc import Iterator
from pathlib import Path
from typing import NamedTuple

import numpy as np

from eyeviz import EyevizError
from eyeviz.core import paper
from eyeviz.core.bounds import MAX_M, check_m
from eyeviz.core.geometry import EyePair
from eyeviz.core.validation import check_int, num
from eyeviz.dataset.formats import (
    COMMA,
    ONE,
    ZERO,
    check_floats,
    check_rows,
    format_of,
    npz_dtype,
)
from eyeviz.dataset.records import Dataset
from eyeviz.files import limits

__all__ = ["BLOCK_ROWS", "Block", "BlockReader", "check_rows", "iter_blocks", "load"]

BLOCK_ROWS = 65536
_META_MAX_BYTES = 1 << 20


class Block(NamedTuple):
    """Rows ``start .. start + len(r) - 1`` of a data set (bits as bool (k, m/2))."""

    omega_a: np.ndarray
    omega_b: np.ndarray
    r: np.ndarray
    phi: np.ndarray
    g: np.ndarray
    start: int


def _read_header(f) -> tuple[tuple[int, ...], bool, np.dtype]:
    """(shape, fortran order, dtype) of the .npy stream ``f``, nothing allocated."""
    version = np.lib.format.read_magic(f)
    read = (
        np.lib.format.read_array_header_1_0
        if version == (1, 0)
        else np.lib.format.read_array_header_2_0
    )
    return read(f, max_header_size=10000)


class BlockReader:
    """A data set file read block by block in bounded memory (:func:`iter_blocks`).

    The file's header is validated when the reader is made: ``eyes`` (the design, from
    the NPZ's h, l, m or the CSV's column count with the paper's h = 40, l = 20),
    ``params`` (generation parameters, empty for CSV), ``n`` (rows; None for a CSV until
    read) and ``with_g``. Iterating yields :class:`Block` objects, each validated before
    it is yielded; a bad row raises :class:`EyevizError` naming its line (CSV) or row
    (NPZ). Memory is about ``block_rows * (2 m + 1.5 m)`` bytes for a CSV (text + bits),
    whatever the file size.
    """

    def __init__(self, path, block_rows: int = BLOCK_ROWS, eyes: EyePair | None = None):
        self.path = Path(path)
        self.fmt = format_of(self.path)
        self.block_rows = check_int("block_rows", block_rows, ge=1)
        if not self.path.exists():
            raise EyevizError(f"no such data set file: {str(self.path)!r}")
        if not self.path.is_file():  # a folder, a FIFO, /dev/zero (or a link to one)
            raise EyevizError(f"data set {str(self.path)!r} is not a regular file")
        self.params: dict = {}
        self.n: int | None = None
        self.with_g = True
        if self.fmt == "npz":
            self._open_npz(eyes)
        else:
            self._open_csv(eyes)

    # -- NPZ --

    def _npz_fail(self, msg: str) -> EyevizError:
        return EyevizError(f"{self.path}: not an eyeviz NPZ data set ({msg})")

    def _open_npz(self, eyes: EyePair | None) -> None:
        try:
            other = _other_kind(self.path)
            if other is not None:
                raise EyevizError(
                    f"{self.path}: {other.what} ({other.kind} eyes), not a planar one: read "
                    "it with eyeviz.dataset.kinds.open_reader (or kinds.load)"
                )
            with zipfile.ZipFile(self.path) as zf:
                infos = {i.filename: i for i in zf.infolist()}
                for name in ("meta.npy", "rows.npy"):
                    if name not in infos:
                        raise self._npz_fail(f"no member {name!r}")
                    if infos[name].compress_type != zipfile.ZIP_STORED:
                        raise self._npz_fail(f"member {name!r} is compressed; only stored")
                mi = infos["meta.npy"]
                if mi.file_size > _META_MAX_BYTES:
                    raise self._npz_fail(f"meta member of {mi.file_size} bytes")
                with zf.open(mi) as f:  # the header first: a 400-byte member may declare GBs
                    shape, _fortran, dtype = _read_header(f)
                if shape != () or dtype.kind != "U" or dtype.itemsize > _META_MAX_BYTES:
                    raise self._npz_fail(f"meta member is {dtype} of shape {shape}, not a string")
                with zf.open(mi) as f:
                    meta_arr = np.lib.format.read_array(f, allow_pickle=False)
                with zf.open(infos["rows.npy"]) as f:
                    shape, fortran, dtype = _read_header(f)
                    self._data_offset = f.tell()
        except EyevizError:
            raise
        except (OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile) as exc:
            raise self._npz_fail(_one_line(exc)) from None
        self._rows_info = ri = infos["rows.npy"]
        if ri.compress_size != ri.file_size or ri.file_size > self.path.stat().st_size:
            raise self._npz_fail(f"rows member declares {ri.file_size} bytes the file lacks")
        try:
            meta = json.loads(str(meta_arr[()]))
            if not isinstance(meta, dict):
                raise TypeError("meta is not an object")
            m = check_m(meta["m"])
            n = check_int("n", meta["n"], ge=0, le=limits.MAX_ROWS)
            params = meta.get("params", {})
            if not isinstance(params, dict):
                raise TypeError("params is not an object")
            h = float(params.get("h", paper.H))
            l_ = float(params.get("l", paper.L))
            file_eyes = EyePair(h, l_, m)
        except EyevizError as exc:
            raise self._npz_fail(str(exc)) from None
        except (ValueError, KeyError, TypeError, OverflowError, IndexError) as exc:
            raise self._npz_fail(f"bad meta: {_one_line(exc)}") from None
        want = npz_dtype(m)
        if dtype != want or fortran or len(shape) != 1:
            raise self._npz_fail(
                f"rows have dtype {dtype} shape {shape}, expected {want} shape (n,) for m={m}"
            )
        if shape[0] != n:
            raise self._npz_fail(f"meta says n={n} but rows declare {shape[0]}")
        body = self._rows_info.file_size - self._data_offset
        if body != n * want.itemsize:
            raise self._npz_fail(
                f"rows declare {n} x {want.itemsize} bytes but the member holds {body}"
            )
        self.n, self.params, self._dtype = n, params, want
        self.eyes = self._check_eyes(eyes, file_eyes, has_design="h" in params)

    def _check_eyes(self, eyes: EyePair | None, file_eyes: EyePair, has_design: bool) -> EyePair:
        if eyes is None:
            return file_eyes
        if eyes.m != file_eyes.m:
            raise EyevizError(
                f"{self.path}: data set has m={file_eyes.m}, but eyes have m={eyes.m}"
            )
        if has_design and (eyes.h != file_eyes.h or eyes.l != file_eyes.l):
            raise EyevizError(
                f"{self.path}: data set was made with h={num(file_eyes.h)}, l={num(file_eyes.l)}, "
                f"but eyes have h={num(eyes.h)}, l={num(eyes.l)}"
            )
        return eyes

    def _npz_rows(self) -> int:
        """The NPZ's row count (known once its header is read); EyevizError for a CSV."""
        if self.fmt != "npz" or self.n is None:
            raise EyevizError(f"{self.path}: reading every row at once needs an NPZ data set")
        return self.n

    def _iter_npz(self) -> Iterator[Block]:
        m, dt = self.eyes.m, self._dtype
        w = m // 2
        n = self._npz_rows()
        try:
            with zipfile.ZipFile(self.path) as zf, zf.open(self._rows_info) as f:
                f.read(self._data_offset)
                start = 0
                while start < n:
                    k = min(self.block_rows, n - start)
                    buf = f.read(k * dt.itemsize)
                    if len(buf) != k * dt.itemsize:
                        raise self._npz_fail(f"rows end early at row {start + 1}")
                    rows = np.frombuffer(buf, dt)
                    oa = np.unpackbits(rows["omega_a"], axis=1, count=w).view(bool)
                    ob = np.unpackbits(rows["omega_b"], axis=1, count=w).view(bool)
                    r, phi, g = rows["r"].copy(), rows["phi"].copy(), rows["g"].copy()
                    check_floats(self.path, start, r, phi, g, "row")
                    yield Block(oa, ob, r, phi, g, start)
                    start += k
        except EyevizError:
            raise
        except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
            raise self._npz_fail(_one_line(exc)) from None

    def read_all(self) -> np.ndarray:
        """Every row of an NPZ in one structured array (its size checked against the file
        when the reader was made), floats validated."""
        n = self._npz_rows()
        dt = self._dtype
        rows = np.empty(n, dt)
        try:
            with zipfile.ZipFile(self.path) as zf, zf.open(self._rows_info) as f:
                f.read(self._data_offset)
                buf = rows.view(np.uint8).reshape(-1).data
                got = 0
                while got < len(buf):
                    k = f.readinto(buf[got:]) if hasattr(f, "readinto") else 0
                    if not k:
                        raise self._npz_fail(f"rows end early at byte {got}")
                    got += k
        except EyevizError:
            raise
        except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
            raise self._npz_fail(_one_line(exc)) from None
        check_floats(self.path, 0, rows["r"], rows["phi"], rows["g"], "row")
        return rows

    # -- CSV --

    def _open_csv(self, eyes: EyePair | None) -> None:
        with open(self.path, "rb") as f:
            first = f.readline(MAX_M * 4 + 1000)
        if not first.strip():
            raise EyevizError(f"{self.path}: the CSV file is empty")
        if not first.endswith(b"\n") and len(first) >= MAX_M * 4 + 1000:
            raise _csv_error(self.path, 1, 1, "line too long for a data set row")
        ncols = first.count(b",") + 1
        self.with_g = ncols % 2 == 1
        m = ncols - (3 if self.with_g else 2)
        if m < 4:
            raise _csv_error(self.path, 1, ncols, f"too few columns ({ncols}) for a data set row")
        file_eyes = EyePair(paper.H, paper.L, m)
        if eyes is not None and eyes.m != m:
            raise _csv_error(
                self.path, 1, ncols, f"{ncols} columns mean m={m}, but eyes have m={eyes.m}"
            )
        self.ncols = ncols
        self.eyes = eyes if eyes is not None else file_eyes

    def _iter_csv(self) -> Iterator[Block]:
        m, nf = self.eyes.m, 3 if self.with_g else 2
        w = m // 2
        start = 0
        with open(self.path, "rb") as f:
            while True:
                block = list(itertools.islice(f, self.block_rows))
                if not block:
                    break
                block = [ln[:-1] if ln.endswith(b"\n") else ln for ln in block]
                block = [ln[:-1] if ln.endswith(b"\r") else ln for ln in block]
                k = len(block)
                oa = np.empty((k, w), np.uint8)
                ob = np.empty((k, w), np.uint8)
                floats = np.empty((nf, k))
                try:
                    _parse_block(block, m, nf, oa, ob, floats)
                except ValueError:
                    _diagnose(self.path, block, start, m, self.ncols)
                    raise EyevizError(f"{self.path}: line {start + 1}: bad row") from None
                g = floats[2] if self.with_g else np.full(k, np.nan)
                check_floats(self.path, start, floats[0], floats[1], g, "line")
                yield Block(oa.view(bool), ob.view(bool), floats[0], floats[1], g, start)
                start += k
        if start == 0:
            raise EyevizError(f"{self.path}: the CSV file is empty")
        self.n = start

    def __iter__(self) -> Iterator[Block]:
        return self._iter_npz() if self.fmt == "npz" else self._iter_csv()


def _other_kind(path: Path):
    """The data set format of ``path`` when its meta declares eyes of another kind than
    this reader's (:func:`eyeviz.dataset.kinds.kind_of`), else None."""
    from eyeviz.dataset.kinds import FORMATS, data_format, kind_of

    fmt = data_format(kind_of(path))
    return None if fmt.reader == FORMATS["planar"].reader else fmt


def iter_blocks(path, block_rows: int = BLOCK_ROWS, eyes: EyePair | None = None) -> BlockReader:
    """Read a CSV or NPZ data set block by block, validating as it goes.

    >>> import pathlib, tempfile
    >>> from eyeviz import dataset
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "data.npz"
    >>> dataset.save(dataset.generate(100, seed=3), path)
    >>> reader = iter_blocks(path, block_rows=40)        # the header is checked here
    >>> reader.eyes.m, reader.n                          # the design metadata
    (720, 100)
    >>> [b.omega_a.shape for b in reader]                # Block(omega_a, omega_b, ..., start)
    [(40, 360), (40, 360), (20, 360)]

    ``eyes``: the consumer's design; refused when its m (or, for an NPZ that carries them,
    h and l) differs from the file's.
    """
    return BlockReader(path, block_rows, eyes)


def load(path, eyes: EyePair | None = None):
    """The whole data set in memory (validated row by row, first bad line named)."""
    reader = iter_blocks(path, BLOCK_ROWS, eyes)
    if reader.fmt == "npz":
        rows = reader.read_all()
        w = reader.eyes.m // 2
        oa = np.unpackbits(rows["omega_a"], axis=1, count=w).view(bool)
        ob = np.unpackbits(rows["omega_b"], axis=1, count=w).view(bool)
        r, phi, g = rows["r"].copy(), rows["phi"].copy(), rows["g"].copy()
        del rows
        return Dataset(oa, ob, r, phi, g, reader.eyes, reader.params)
    blocks = list(reader)
    if len(blocks) == 1:
        b = blocks[0]
        return Dataset(b.omega_a, b.omega_b, b.r, b.phi, b.g, reader.eyes, {})
    oa, ob, r, phi, g = (np.concatenate([getattr(b, f) for b in blocks]) for f in Block._fields[:5])
    return Dataset(oa, ob, r, phi, g, reader.eyes, {})


def _show(field: bytes) -> str:
    t = repr(field[:40].decode(errors="replace"))
    return t + ("..." if len(field) > 40 else "")


def _one_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0][:200] if text else type(exc).__name__


def _csv_error(path: Path, line: int, col: int, msg: str) -> EyevizError:
    return EyevizError(f"{path}: line {line}, column {col}: {msg}")


def _parse_block(
    block: list[bytes], m: int, nf: int, oa: np.ndarray, ob: np.ndarray, floats: np.ndarray
) -> None:
    """Fast path: every line is exactly ``b,`` * m followed by nf floats (checked per line:
    a line with an extra field next to one with a missing field is refused)."""
    rb = 2 * m
    head = np.frombuffer(b"".join([ln[:rb] for ln in block]), np.uint8)
    if head.size != len(block) * rb:
        raise ValueError("short line")
    head = head.reshape(len(block), m, 2)
    if not (np.all(head[:, :, 1] == COMMA) and np.all((head[:, :, 0] | 1) == ONE)):
        raise ValueError("bad bits")
    w = m // 2
    np.subtract(head[:, :w, 0], ZERO, out=oa)
    np.subtract(head[:, w:, 0], ZERO, out=ob)
    tails = [ln[rb:] for ln in block]
    if any(t.count(b",") != nf - 1 for t in tails):
        raise ValueError("bad field count")
    if any(b"_" in t for t in tails):  # Python's float() reads "1_000"; a CSV number does not
        raise ValueError("underscore in a number")
    floats[:] = np.array(list(map(float, b",".join(tails).split(b",")))).reshape(len(block), nf).T
    if not np.all(np.isfinite(floats)):
        raise ValueError("non-finite")


def _diagnose(path: Path, block: list[bytes], offset: int, m: int, ncols: int) -> None:
    """Slow path: find the first bad field and raise an error naming line and column."""
    for i, ln in enumerate(block):
        lineno = offset + i + 1
        fields = ln.split(b",")
        if len(fields) != ncols:
            raise _csv_error(
                path,
                lineno,
                min(len(fields), ncols) + 1,
                f"expected {ncols} columns, found {len(fields)}",
            )
        for j, fv in enumerate(fields):
            if j < m:
                if fv not in (b"0", b"1"):
                    raise _csv_error(
                        path,
                        lineno,
                        j + 1,
                        f"bit must be 0 or 1, got {_show(fv)}",
                    )
            else:
                try:
                    if b"_" in fv:
                        raise ValueError(fv)
                    v = float(fv)
                except ValueError:
                    raise _csv_error(path, lineno, j + 1, f"not a number: {_show(fv)}") from None
                if not np.isfinite(v):
                    raise _csv_error(path, lineno, j + 1, f"not a finite number: {v!r}")
