"""CSV and NPZ files of data sets (docs/contract.md), streamed and written atomically.

CSV: no header, comma separated, ``Omega_A[0..m/2-1], Omega_B[0..m/2-1], r, phi, g``;
bits as ``0``/``1``, floats as ``'%.17g'`` (17 significant digits: every float64 reads
back bit-exactly), lines ending in ``\\n``. The paper's Appendix A/B loader
(``row[:720]``, ``row[720]``, ``row[721]``) reads it unchanged. A CSV without the g
column (m + 2 columns) is read too.

NPZ: an uncompressed zip of two ``.npy`` members: ``meta`` (a JSON string: format
version, m, n and the generation parameters) and ``rows``, a structured array with
fields ``omega_a``, ``omega_b`` (uint8 (m/8 rounded up,), ``np.packbits`` of the bitmap,
big bit order), ``r``, ``phi``, ``g`` (float64). One member holds whole rows, so a file of
any size is streamed chunk by chunk.

Both are written to a temporary file in the target directory and renamed at the end,
so an interruption or a full disk leaves no partial output. Reading (validated, whole or
in blocks) is :mod:`eyeviz.dataset.reader`, re-exported here; what both share (format
names, byte codes, the NPZ row dtype, the row checks) is :mod:`eyeviz.dataset.formats`.
This module is over 400 lines because the vectorised ``%.17g`` formatting and the CSV
encoder belong with the writers they serve.
"""

from __future__ import annotations

import contextlib
import functools
import json
import os
import zipfile
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path
from types import TracebackType
from typing import BinaryIO, Generic, TypeVar

import numpy as np

from eyeviz.dataset.formats import (
    COMMA,
    FORMATS,
    NEWLINE,
    NPZ_VERSION,
    ONE,
    ZERO,
    check_rows,
    format_of,
    npz_dtype,
)
from eyeviz.dataset.reader import BLOCK_ROWS, Block, BlockReader, iter_blocks, load
from eyeviz.dataset.records import CHUNK, Chunk, Dataset
from eyeviz.files.atomic import atomic_output

_TABLE_MAX_W = 4096  # packed lookup tables up to 2 x 2 MB


# --- float formatting ----------------------------------------------------------------

_FW = 24  # widest '%.17g' text in fixed notation: "-0.000" + 17 digits
_P10 = 10.0 ** np.arange(23)  # exact doubles 1 .. 1e22
_P10_INT = 10 ** np.arange(16, -1, -1, dtype=np.int64)  # 1e16 .. 1


def _two_prod(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """a*b = hi + lo exactly (Dekker's product; no overflow for our magnitudes)."""
    hi = a * b
    c = 134217729.0 * a
    ah = c - (c - a)
    al = a - ah
    c = 134217729.0 * b
    bh = c - (c - b)
    bl = b - bh
    lo = ((ah * bh - hi) + ah * bl + al * bh) + al * bl
    return hi, lo


def _digits17(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(D, X): a = D * 10**(X - 16) rounded to 17 significant digits, 1e16 <= D < 1e17.

    For 1e-6 <= a < 1e17: the scaled value a * 10**k (k = 16 - X <= 22, 10**k exact) is
    computed exactly as hi + lo, and rounded half-even (hi is an even integer there).
    """
    x = np.floor(np.log10(a)).astype(np.int64)
    for _ in range(3):
        k = np.clip(16 - x, 0, 22)
        hi, lo = _two_prod(a, _P10[k])
        d = hi.astype(np.int64) + np.rint(lo).astype(np.int64)
        up = d >= 10**17
        down = d < 10**16
        if not (up.any() or down.any()):
            break
        x = x + up - down
    return d, x


def _ascii17(d: np.ndarray) -> np.ndarray:
    """ASCII digits (n, 17) of integers 1e16 <= d < 1e17, via a table of 4-digit groups."""
    out = np.empty((d.shape[0], 17), np.uint8)
    out[:, 0] = d // 10**16 + 48
    rest = d % 10**16
    hi8, lo8 = np.divmod(rest, 10**8)
    for j, grp in enumerate(np.divmod(hi8, 10**4) + np.divmod(lo8, 10**4)):
        out[:, 1 + 4 * j : 5 + 4 * j] = _GROUPS.take(grp, axis=0)
    return out


_GROUPS = np.array([list(f"{i:04d}".encode()) for i in range(10**4)], np.uint8)


def format_g17(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Texts of ``'%.17g' % v`` as (chars (n, 24) uint8, NUL-padded; lengths (n,)).

    17 significant digits always read back to the same float64. Fixed notation (the
    common case, 1e-4 <= |v| < 1e17) is vectorised; anything else goes through Python.
    """
    v = np.asarray(v, dtype=np.float64)
    n = v.shape[0]
    out = np.zeros((n, _FW), np.uint8)
    lens = np.zeros(n, np.int64)
    a = np.abs(v)
    fast = np.isfinite(a) & (a >= 1e-6) & (a < 1e17)
    all_fast = bool(fast.all())
    idx = np.arange(n) if all_fast else np.flatnonzero(fast)
    if idx.size:
        d, x = _digits17(a if all_fast else a[idx])
        ok = (x >= -4) & (x <= 16)
        if not ok.all():
            idx, d, x = idx[ok], d[ok], x[ok]
            all_fast = False
            fast[:] = False
            fast[idx] = True
        dig = _ascii17(d)
        sig = 17 - np.argmax(dig[:, ::-1] != 48, axis=1)  # without trailing zeros
        neg = v[idx] < 0
        body = out if all_fast else np.zeros((idx.size, _FW), np.uint8)
        blen = np.empty(idx.size, np.int64)
        for xv in np.unique(x).tolist():
            sel = slice(None) if x[0] == xv and (x == xv).all() else np.flatnonzero(x == xv)
            if xv >= 0:
                dec = np.maximum(sig[sel] - (xv + 1), 0)
                blk = np.empty((dig[sel].shape[0], 18), np.uint8)
                blk[:, : xv + 1] = dig[sel, : xv + 1]
                blk[:, xv + 1] = 46
                blk[:, xv + 2 :] = dig[sel, xv + 1 :]
                blen[sel] = xv + 1 + np.where(dec > 0, dec + 1, 0)
                body[sel, :18] = blk
            else:
                z = -xv - 1
                body[sel, 0] = 48
                body[sel, 1] = 46
                body[sel, 2 : 2 + z] = 48
                body[sel, 2 + z : 19 + z] = dig[sel]
                blen[sel] = 2 + z + sig[sel]
        body[np.arange(_FW)[None, :] >= blen[:, None]] = 0
        if neg.any():
            pos = np.flatnonzero(neg)
            body[pos, 1:] = body[pos, :-1]
            body[pos, 0] = 45
            blen = blen + neg
        if not all_fast:
            out[idx] = body
        lens[idx] = blen
    for i in np.flatnonzero(~fast).tolist():
        t = format(float(v[i]), ".17g").encode()
        out[i, : len(t)] = np.frombuffer(t, np.uint8)
        lens[i] = len(t)
    return out, lens


# --- CSV encoding --------------------------------------------------------------------


class CsvEncoder:
    """Encodes chunks of rows as CSV, reusing one preformatted bit buffer.

    The buffer holds ``0,`` for every bit of ``rows`` rows; a chunk sets its lit bits to
    ``1`` by one scatter (the previous chunk's are set back first). ``encode_*`` return
    the chunk as a list of buffers (row views into the bit buffer and the row tails) for
    :func:`write_parts`: valid until the next ``encode_*`` call on the same encoder.
    """

    def __init__(self, m: int, rows: int, with_g: bool = True):
        self.w = m // 2
        self.rb = 2 * m  # bytes of the bit columns of one row (m bits, each "b,")
        self.with_g = with_g
        self.buf = np.empty((rows, self.rb), np.uint8)
        self.buf[:, 0::2] = ZERO
        self.buf[:, 1::2] = COMMA
        self.flat = self.buf.reshape(-1)
        mv = self.flat.data  # memoryview(self.flat)
        self.row_views = [mv[i * self.rb : (i + 1) * self.rb] for i in range(rows)]
        self._lit: np.ndarray | None = None

    def _tails(self, r: np.ndarray, phi: np.ndarray, g: np.ndarray) -> list[bytes]:
        """Per row ``r,phi,g\n`` (``%.17g``), built as one NUL-padded matrix."""
        cols = [format_g17(r), format_g17(phi)]
        if self.with_g:
            cols.append(format_g17(g))
        n = r.shape[0]
        width = len(cols) * (_FW + 1)
        tail = np.zeros((n, width), np.uint8)
        rows = np.arange(n)
        at = np.zeros(n, np.int64)
        for j, (chars, lens) in enumerate(cols):
            for o in np.unique(at).tolist():
                sel = at == o
                tail[sel, o : o + _FW] = chars[sel]
            at = at + lens
            tail[rows, at] = NEWLINE if j == len(cols) - 1 else COMMA
            at += 1
        return tail.view(f"S{width}").ravel().tolist()

    def _parts(self, n: int, tails: list[bytes]) -> list:
        parts: list = [None] * (2 * n)
        parts[0::2] = self.row_views[:n]
        parts[1::2] = tails
        return parts

    def _lit_positions(self, lo: np.ndarray, hi: np.ndarray, col0: int) -> np.ndarray:
        """Flat buffer positions of the '0' bytes of bits lo..hi of each row (lo <= hi)."""
        cnt = hi - lo + 1
        tot = int(cnt.sum())
        base = np.arange(lo.shape[0], dtype=np.int64) * self.rb + 2 * (col0 + lo)
        excl = np.cumsum(cnt) - cnt
        return np.repeat(base - 2 * excl, cnt) + 2 * np.arange(tot, dtype=np.int64)

    def encode_intervals(
        self,
        r: np.ndarray,
        phi: np.ndarray,
        g: np.ndarray,
        la: np.ndarray,
        ra: np.ndarray,
        lb: np.ndarray,
        rb: np.ndarray,
    ) -> list:
        """Rows whose eye E lights bits L_E..R_E (0 <= L <= R < m/2)."""
        if self._lit is not None:
            self.flat[self._lit] = ZERO
        pos = np.concatenate([self._lit_positions(la, ra, 0), self._lit_positions(lb, rb, self.w)])
        self.flat[pos] = ONE
        self._lit = pos
        return self._parts(r.shape[0], self._tails(r, phi, g))

    def encode_bitmaps(
        self,
        omega_a: np.ndarray,
        omega_b: np.ndarray,
        r: np.ndarray,
        phi: np.ndarray,
        g: np.ndarray,
    ) -> list:
        if self._lit is not None:  # invariant: the buffer is "0," except at self._lit
            self.flat[self._lit] = ZERO
        n = r.shape[0]
        view = self.buf[:n]
        w = self.w
        view[:, 0 : 2 * w : 2] = ZERO + omega_a.view(np.uint8)
        view[:, 2 * w :: 2] = ZERO + omega_b.view(np.uint8)
        self._lit = np.flatnonzero(self.buf[:n].reshape(-1) == ONE)
        return self._parts(n, self._tails(r, phi, g))


_IOV = 1024  # buffers per writev call (IOV_MAX on Linux)


def write_parts(f: BinaryIO, parts: list) -> None:
    """Write a list of buffers to an unbuffered binary file, without joining them."""
    if not hasattr(os, "writev"):
        f.write(b"".join(parts))
        return
    fd = f.fileno()
    for s in range(0, len(parts), _IOV):
        group = parts[s : s + _IOV]
        done = os.writev(fd, group)
        total = sum(map(len, group))
        if done < total:
            rest = memoryview(b"".join(group))[done:]
            while rest:
                rest = rest[os.write(fd, rest) :]


# --- NPZ -----------------------------------------------------------------------------


@functools.lru_cache(maxsize=8)
def _pack_tables(w: int) -> tuple[np.ndarray, np.ndarray]:
    """np.packbits of the bitmaps {k >= lo} (row lo) and {k <= hi} (row hi), k < w."""
    k = np.arange(w)
    return (
        np.packbits(k[None, :] >= k[:, None], axis=1),
        np.packbits(k[None, :] <= k[:, None], axis=1),
    )


def _packed_from_intervals(lo: np.ndarray, hi: np.ndarray, w: int) -> np.ndarray:
    """np.packbits of the bitmap lit on lo..hi (0 <= lo <= hi < w), without building it."""
    if w > _TABLE_MAX_W:
        return _packed_clip(lo, hi, w)
    ge, le = _pack_tables(w)
    out = ge.take(lo, axis=0)
    out &= le.take(hi, axis=0)
    return out


def _packed_clip(lo: np.ndarray, hi: np.ndarray, w: int) -> np.ndarray:
    start = np.arange((w + 7) // 8, dtype=np.int64) * 8
    a = np.clip(lo[:, None] - start, 0, 8)
    b = np.clip(hi[:, None] + 1 - start, 0, 8)
    # bits a..b-1 of a byte, most significant first: (0xFF >> a) & ~(0xFF >> b)
    return ((0xFF >> a) & ~(0xFF >> b)).astype(np.uint8)


def _npz_rows(m: int, n: int) -> np.ndarray:
    return np.empty(n, dtype=npz_dtype(m))


class _NpzWriter:
    def __init__(self, tmp: Path, m: int, n: int, meta: dict):
        self.m = m
        self.zf = zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_STORED, allowZip64=True)
        with self.zf.open("meta.npy", "w") as f:
            np.lib.format.write_array(f, np.array(json.dumps(meta)), allow_pickle=False)
        self.f = self.zf.open("rows.npy", "w", force_zip64=True)
        dt = npz_dtype(m)
        header = {"descr": np.lib.format.dtype_to_descr(dt), "fortran_order": False, "shape": (n,)}
        np.lib.format.write_array_header_1_0(self.f, header)

    def rows_from_intervals(
        self,
        r: np.ndarray,
        phi: np.ndarray,
        g: np.ndarray,
        la: np.ndarray,
        ra: np.ndarray,
        lb: np.ndarray,
        rb: np.ndarray,
    ) -> np.ndarray:
        rows = _npz_rows(self.m, r.shape[0])
        w = self.m // 2
        rows["omega_a"] = _packed_from_intervals(la, ra, w)
        rows["omega_b"] = _packed_from_intervals(lb, rb, w)
        rows["r"], rows["phi"], rows["g"] = r, phi, g
        return rows

    def rows_from_bitmaps(
        self,
        omega_a: np.ndarray,
        omega_b: np.ndarray,
        r: np.ndarray,
        phi: np.ndarray,
        g: np.ndarray,
    ) -> np.ndarray:
        rows = _npz_rows(self.m, r.shape[0])
        rows["omega_a"] = np.packbits(omega_a, axis=1)
        rows["omega_b"] = np.packbits(omega_b, axis=1)
        rows["r"], rows["phi"], rows["g"] = r, phi, g
        return rows

    def write(self, rows: np.ndarray) -> None:
        """Append ``rows`` (from ``rows_from_*``) to ``rows.npy``, as its raw buffer."""
        self.f.write(rows.data)

    def __enter__(self) -> _NpzWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        try:
            self.f.close()
        finally:
            self.zf.close()


# --- writing -------------------------------------------------------------------------


_B = TypeVar("_B")  # what one write call takes


class _Overlapped(Generic[_B]):
    """Runs ``write`` calls on one worker thread, one at a time, so the file write of a
    chunk overlaps the generation and encoding of the next (I/O releases the GIL).

    Every call gets a fresh buffer; errors surface at the next call or at ``wait``.
    """

    def __init__(self, write: Callable[[_B], object]):
        self._write = write
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="eyeviz-write")
        self._pending: Future[object] | None = None

    def __call__(self, buf: _B) -> None:
        self.wait()
        self._pending = self._pool.submit(self._write, buf)

    def wait(self) -> None:
        if self._pending is not None:
            pending, self._pending = self._pending, None
            pending.result()

    def __enter__(self) -> _Overlapped[_B]:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        try:
            if exc_type is None:
                self.wait()
            elif self._pending is not None:
                with contextlib.suppress(BaseException):
                    self._pending.result()
        finally:
            self._pool.shutdown(wait=True)


#: Bytes of one encode buffer (CSV bits or NPZ rows). A chunk of wide rows (m up to
#: core.bounds.MAX_M) is written in blocks of at most this much, so memory does not grow with m
#: (a 16384-row CSV buffer at m = 2^20 would be 32 GiB); the bytes written are the same.
_BLOCK_BYTES = 64 << 20


def block_rows(row_bytes: int, cap: int) -> int:
    """Rows per encode block: ``cap``, fewer when rows of ``row_bytes`` would exceed
    :data:`_BLOCK_BYTES`; at least 1."""
    return max(1, min(cap, _BLOCK_BYTES // max(1, row_bytes)))


def _blocks(c: Chunk, rows: int) -> Iterator[tuple[np.ndarray, ...]]:
    """``(r, phi, g, la, ra, lb, rb)`` of ``c`` in consecutive blocks of ``rows``."""
    cols = (c.r, c.phi, c.g, c.la, c.ra, c.lb, c.rb)
    for s in range(0, len(c), rows):
        yield tuple(a[s : s + rows] for a in cols)


def write_chunks(
    path: str | os.PathLike,
    fmt: str,
    n: int,
    m: int,
    params: dict,
    chunks: Iterable[Chunk],
    progress: Callable[[int], None] | None = None,
) -> None:
    """Stream generated :class:`eyeviz.dataset.Chunk` objects into ``path``."""
    with atomic_output(path) as tmp:
        if fmt == "csv":
            # two buffers: chunk k+1 is encoded while chunk k is written; encoding k+2
            # into k's buffer starts only after out() has waited for k's write
            rows = block_rows(2 * m, CHUNK)
            encs = (CsvEncoder(m, rows), CsvEncoder(m, rows))
            k = 0
            with (
                open(tmp, "wb", buffering=0) as f,
                _Overlapped(functools.partial(write_parts, f)) as out,
            ):
                for c in chunks:
                    for cols in _blocks(c, rows):
                        out(encs[k % 2].encode_intervals(*cols))
                        k += 1
                    if progress:
                        progress(len(c))
        else:
            meta = {"version": NPZ_VERSION, "m": m, "n": n, "params": params}
            rows = block_rows(npz_dtype(m).itemsize, CHUNK)
            with _NpzWriter(tmp, m, n, meta) as wr, _Overlapped(wr.write) as out:
                for c in chunks:
                    for cols in _blocks(c, rows):
                        out(wr.rows_from_intervals(*cols))
                    if progress:
                        progress(len(c))


def save(ds: Dataset, path: str | os.PathLike) -> None:
    """Write a data set; refuses rows :func:`load` would refuse (NaN r, bits 3 or 255)."""
    fmt = format_of(path)
    n, m = len(ds), ds.eyes.m
    check_rows(ds.omega_a, ds.omega_b, ds.r, ds.phi, ds.g, m)
    step = block_rows(2 * m if fmt == "csv" else npz_dtype(m).itemsize, 1 << 14)
    with atomic_output(path) as tmp:
        if fmt == "csv":
            with_g = not bool(np.all(np.isnan(ds.g))) if n else True
            enc = CsvEncoder(m, min(step, max(n, 1)), with_g)
            with open(tmp, "wb", buffering=0) as f:
                for s in range(0, n, step):
                    sl = slice(s, s + step)
                    write_parts(
                        f,
                        enc.encode_bitmaps(
                            ds.omega_a[sl], ds.omega_b[sl], ds.r[sl], ds.phi[sl], ds.g[sl]
                        ),
                    )
        else:
            e = ds.eyes
            meta = {
                "version": NPZ_VERSION,
                "m": m,
                "n": n,
                "params": {**ds.params, "h": e.h, "l": e.l, "m": m},
            }
            with _NpzWriter(tmp, m, n, meta) as wr:
                for s in range(0, n, step):
                    sl = slice(s, s + step)
                    wr.write(
                        wr.rows_from_bitmaps(
                            ds.omega_a[sl], ds.omega_b[sl], ds.r[sl], ds.phi[sl], ds.g[sl]
                        )
                    )


__all__ = [
    "CsvEncoder",
    "FORMATS",
    "atomic_output",
    "format_of",
    "format_g17",
    "npz_dtype",
    "save",
    "write_chunks",
    "write_parts",
    "NPZ_VERSION",
    "BLOCK_ROWS",
    "Block",
    "BlockReader",
    "check_rows",
    "iter_blocks",
    "load",
]
