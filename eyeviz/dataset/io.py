"""CSV and NPZ files of data sets (DESIGN.md §3), streamed and written atomically.

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
so an interruption or a full disk leaves no partial output.
"""

from __future__ import annotations

import contextlib
import functools
import itertools
import json
import os
import zipfile
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path
from typing import NamedTuple

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.geometry import EyePair
from eyeviz.files import limits
from eyeviz.files.atomic import atomic_output

FORMATS = ("csv", "npz")
NPZ_VERSION = 1
_ZERO, _ONE, _COMMA, _NEWLINE = 48, 49, 44, 10
_TABLE_MAX_W = 4096  # packed lookup tables up to 2 x 2 MB


def format_of(path) -> str:
    suffix = Path(path).suffix.lower().lstrip(".")
    if suffix not in FORMATS:
        raise EyevizError(f"output must end in .csv or .npz, got {str(path)!r}")
    return suffix


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
        self.buf[:, 0::2] = _ZERO
        self.buf[:, 1::2] = _COMMA
        self.flat = self.buf.reshape(-1)
        mv = memoryview(self.flat)
        self.row_views = [mv[i * self.rb : (i + 1) * self.rb] for i in range(rows)]
        self._lit: np.ndarray | None = None

    def _tails(self, r, phi, g) -> list[bytes]:
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
            tail[rows, at] = _NEWLINE if j == len(cols) - 1 else _COMMA
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

    def encode_intervals(self, r, phi, g, la, ra, lb, rb) -> list:
        """Rows whose eye E lights bits L_E..R_E (0 <= L <= R < m/2)."""
        if self._lit is not None:
            self.flat[self._lit] = _ZERO
        pos = np.concatenate([self._lit_positions(la, ra, 0), self._lit_positions(lb, rb, self.w)])
        self.flat[pos] = _ONE
        self._lit = pos
        return self._parts(r.shape[0], self._tails(r, phi, g))

    def encode_bitmaps(self, omega_a, omega_b, r, phi, g) -> list:
        if self._lit is not None:  # invariant: the buffer is "0," except at self._lit
            self.flat[self._lit] = _ZERO
        n = r.shape[0]
        view = self.buf[:n]
        w = self.w
        view[:, 0 : 2 * w : 2] = _ZERO + omega_a.view(np.uint8)
        view[:, 2 * w :: 2] = _ZERO + omega_b.view(np.uint8)
        self._lit = np.flatnonzero(self.buf[:n].reshape(-1) == _ONE)
        return self._parts(n, self._tails(r, phi, g))


_IOV = 1024  # buffers per writev call (IOV_MAX on Linux)


def write_parts(f, parts: list) -> None:
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


def npz_dtype(m: int) -> np.dtype:
    nb = (m // 2 + 7) // 8
    return np.dtype(
        [
            ("omega_a", np.uint8, (nb,)),
            ("omega_b", np.uint8, (nb,)),
            ("r", "<f8"),
            ("phi", "<f8"),
            ("g", "<f8"),
        ]
    )


@functools.lru_cache(maxsize=8)
def _pack_tables(w: int) -> tuple[np.ndarray, np.ndarray]:
    """np.packbits of the bitmaps {k >= lo} (row lo) and {k <= hi} (row hi), k < w."""
    k = np.arange(w)
    return (
        np.packbits(k[None, :] >= k[:, None], axis=1),
        np.packbits(k[None, :] <= k[:, None], axis=1),
    )


def _packed_from_intervals(lo, hi, w: int) -> np.ndarray:
    """np.packbits of the bitmap lit on lo..hi (0 <= lo <= hi < w), without building it."""
    if w > _TABLE_MAX_W:
        return _packed_clip(lo, hi, w)
    ge, le = _pack_tables(w)
    out = ge.take(lo, axis=0)
    out &= le.take(hi, axis=0)
    return out


def _packed_clip(lo, hi, w: int) -> np.ndarray:
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

    def rows_from_intervals(self, r, phi, g, la, ra, lb, rb) -> np.ndarray:
        rows = _npz_rows(self.m, r.shape[0])
        w = self.m // 2
        rows["omega_a"] = _packed_from_intervals(la, ra, w)
        rows["omega_b"] = _packed_from_intervals(lb, rb, w)
        rows["r"], rows["phi"], rows["g"] = r, phi, g
        return rows

    def rows_from_bitmaps(self, omega_a, omega_b, r, phi, g) -> np.ndarray:
        rows = _npz_rows(self.m, r.shape[0])
        rows["omega_a"] = np.packbits(omega_a, axis=1)
        rows["omega_b"] = np.packbits(omega_b, axis=1)
        rows["r"], rows["phi"], rows["g"] = r, phi, g
        return rows

    def __enter__(self) -> _NpzWriter:
        return self

    def __exit__(self, *exc) -> None:
        try:
            self.f.close()
        finally:
            self.zf.close()


# --- writing -------------------------------------------------------------------------


class _Overlapped:
    """Runs ``write`` calls on one worker thread, one at a time, so the file write of a
    chunk overlaps the generation and encoding of the next (I/O releases the GIL).

    Every call gets a fresh buffer; errors surface at the next call or at ``wait``.
    """

    def __init__(self, write: Callable[[object], object]):
        self._write = write
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="eyeviz-write")
        self._pending: Future | None = None

    def __call__(self, buf) -> None:
        self.wait()
        self._pending = self._pool.submit(self._write, buf)

    def wait(self) -> None:
        if self._pending is not None:
            pending, self._pending = self._pending, None
            pending.result()

    def __enter__(self) -> _Overlapped:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        try:
            if exc_type is None:
                self.wait()
            elif self._pending is not None:
                with contextlib.suppress(BaseException):
                    self._pending.result()
        finally:
            self._pool.shutdown(wait=True)


def _encode_csv_chunk(enc: CsvEncoder, c) -> list:
    return enc.encode_intervals(c.r, c.phi, c.g, c.la, c.ra, c.lb, c.rb)


def write_chunks(
    path,
    fmt: str,
    n: int,
    m: int,
    params: dict,
    chunks: Iterable,
    progress: Callable[[int], None] | None = None,
) -> None:
    """Stream generated :class:`eyeviz.dataset.Chunk` objects into ``path``."""
    from eyeviz.dataset import CHUNK

    with atomic_output(path) as tmp:
        if fmt == "csv":
            # two buffers: chunk k+1 is encoded while chunk k is written; encoding k+2
            # into k's buffer starts only after out() has waited for k's write
            encs = (CsvEncoder(m, CHUNK), CsvEncoder(m, CHUNK))
            with (
                open(tmp, "wb", buffering=0) as f,
                _Overlapped(functools.partial(write_parts, f)) as out,
            ):
                for i, c in enumerate(chunks):
                    out(_encode_csv_chunk(encs[i % 2], c))
                    if progress:
                        progress(len(c))
        else:
            meta = {"version": NPZ_VERSION, "m": m, "n": n, "params": params}
            with _NpzWriter(tmp, m, n, meta) as wr, _Overlapped(wr.f.write) as out:
                for c in chunks:
                    out(wr.rows_from_intervals(c.r, c.phi, c.g, c.la, c.ra, c.lb, c.rb))
                    if progress:
                        progress(len(c))


def save(ds, path) -> None:
    """Write a data set; refuses rows :func:`load` would refuse (NaN r, bits 3 or 255)."""
    fmt = format_of(path)
    n, m = len(ds), ds.eyes.m
    check_rows(ds.omega_a, ds.omega_b, ds.r, ds.phi, ds.g, m)
    step = 1 << 14
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
                    wr.f.write(
                        wr.rows_from_bitmaps(
                            ds.omega_a[sl], ds.omega_b[sl], ds.r[sl], ds.phi[sl], ds.g[sl]
                        )
                    )


# --- reading -------------------------------------------------------------------------

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
        if not isinstance(block_rows, int) or block_rows < 1:
            raise EyevizError(f"block_rows must be an integer >= 1, got {block_rows!r}")
        self.block_rows = block_rows
        if not self.path.is_file():
            raise EyevizError(f"no such data set file: {str(self.path)!r}")
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
                with zf.open(mi) as f:
                    meta_arr = np.lib.format.read_array(f, allow_pickle=False)
                with zf.open(infos["rows.npy"]) as f:
                    version = np.lib.format.read_magic(f)
                    read_header = (
                        np.lib.format.read_array_header_1_0
                        if version == (1, 0)
                        else np.lib.format.read_array_header_2_0
                    )
                    shape, fortran, dtype = read_header(f, max_header_size=10000)
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
            m = limits.check_m(meta["m"])
            n = limits.check_int("n", meta["n"], 0, limits.MAX_ROWS)
            params = meta.get("params", {})
            if not isinstance(params, dict):
                raise TypeError("params is not an object")
            h = float(params.get("h", 40.0))
            l_ = float(params.get("l", 20.0))
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
                f"{self.path}: data set was made with h={file_eyes.h:g}, l={file_eyes.l:g}, "
                f"but eyes have h={eyes.h:g}, l={eyes.l:g}"
            )
        return eyes

    def _iter_npz(self) -> Iterator[Block]:
        m, dt = self.eyes.m, self._dtype
        w = m // 2
        try:
            with zipfile.ZipFile(self.path) as zf, zf.open(self._rows_info) as f:
                f.read(self._data_offset)
                start = 0
                while start < self.n:
                    k = min(self.block_rows, self.n - start)
                    buf = f.read(k * dt.itemsize)
                    if len(buf) != k * dt.itemsize:
                        raise self._npz_fail(f"rows end early at row {start + 1}")
                    rows = np.frombuffer(buf, dt)
                    oa = np.unpackbits(rows["omega_a"], axis=1, count=w).view(bool)
                    ob = np.unpackbits(rows["omega_b"], axis=1, count=w).view(bool)
                    r, phi, g = rows["r"].copy(), rows["phi"].copy(), rows["g"].copy()
                    _check_floats(self.path, start, r, phi, g, "row")
                    yield Block(oa, ob, r, phi, g, start)
                    start += k
        except EyevizError:
            raise
        except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
            raise self._npz_fail(_one_line(exc)) from None

    def read_all(self) -> np.ndarray:
        """Every row of an NPZ in one structured array (its size checked against the file
        when the reader was made), floats validated."""
        dt = self._dtype
        rows = np.empty(self.n, dt)
        try:
            with zipfile.ZipFile(self.path) as zf, zf.open(self._rows_info) as f:
                f.read(self._data_offset)
                buf = memoryview(rows.view(np.uint8).reshape(-1))
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
        _check_floats(self.path, 0, rows["r"], rows["phi"], rows["g"], "row")
        return rows

    # -- CSV --

    def _open_csv(self, eyes: EyePair | None) -> None:
        with open(self.path, "rb") as f:
            first = f.readline(limits.MAX_M * 4 + 1000)
        if not first.strip():
            raise EyevizError(f"{self.path}: the CSV file is empty")
        if not first.endswith(b"\n") and len(first) >= limits.MAX_M * 4 + 1000:
            raise _csv_error(self.path, 1, 1, "line too long for a data set row")
        ncols = first.count(b",") + 1
        self.with_g = ncols % 2 == 1
        m = ncols - (3 if self.with_g else 2)
        if m < 4:
            raise _csv_error(self.path, 1, ncols, f"too few columns ({ncols}) for a data set row")
        file_eyes = EyePair(40.0, 20.0, m)
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
                _check_floats(self.path, start, floats[0], floats[1], g, "line")
                yield Block(oa.view(bool), ob.view(bool), floats[0], floats[1], g, start)
                start += k
        if start == 0:
            raise EyevizError(f"{self.path}: the CSV file is empty")
        self.n = start

    def __iter__(self) -> Iterator[Block]:
        return self._iter_npz() if self.fmt == "npz" else self._iter_csv()


def iter_blocks(path, block_rows: int = BLOCK_ROWS, eyes: EyePair | None = None) -> BlockReader:
    """Read a CSV or NPZ data set block by block, validating as it goes.

    >>> reader = iter_blocks("data.npz", eyes=est.domain.eyes)   # header checked here
    >>> reader.eyes, reader.params, reader.n                     # the design metadata
    >>> for b in reader: predict(b.omega_a, b.omega_b) ...       # Block(omega_a, ..., start)

    ``eyes``: the consumer's design; refused when its m (or, for an NPZ that carries them,
    h and l) differs from the file's.
    """
    return BlockReader(path, block_rows, eyes)


def load(path, eyes: EyePair | None = None):
    """The whole data set in memory (validated row by row, first bad line named)."""
    from eyeviz.dataset import Dataset

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
    cat = [np.concatenate([getattr(b, f) for b in blocks]) for f in Block._fields[:5]]
    return Dataset(*cat, reader.eyes, {})


def _show(field: bytes) -> str:
    t = repr(field[:40].decode(errors="replace"))
    return t + ("..." if len(field) > 40 else "")


def _one_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0][:200] if text else type(exc).__name__


def _check_floats(path: Path, start: int, r, phi, g, unit: str) -> None:
    """r >= 0 and phi finite; g finite (or NaN in every row: a CSV without g)."""
    bad = ~(np.isfinite(r) & (r >= 0) & np.isfinite(phi) & (np.isfinite(g) | np.isnan(g)))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise EyevizError(
            f"{path}: {unit} {start + i + 1}: r, phi, g = {float(r[i])!r}, {float(phi[i])!r}, "
            f"{float(g[i])!r} "
            "(r must be finite and >= 0, phi and g finite)"
        )


def check_rows(omega_a, omega_b, r, phi, g, m: int) -> None:
    """What :func:`save` refuses to write: anything :func:`load` would refuse."""
    w = m // 2
    n = np.shape(r)[0] if np.ndim(r) else -1
    for name, a in (("omega_a", omega_a), ("omega_b", omega_b)):
        a = np.asarray(a)
        if a.ndim != 2 or a.shape != (n, w):
            raise EyevizError(f"{name} must have shape ({n}, {w}), got {a.shape}")
        if a.dtype != bool:
            bad = (a != 0) & (a != 1)
            if bad.any():
                i, j = (int(v[0]) for v in np.nonzero(bad))
                raise EyevizError(f"{name} row {i + 1}, bit {j}: {a[i, j].item()!r} is not 0 or 1")
    for name, a in (("phi", phi), ("g", g)):
        if np.shape(a) != (n,):
            raise EyevizError(f"{name} must have shape ({n},), got {np.shape(a)}")
    r, phi, g = (np.asarray(a, dtype=np.float64) for a in (r, phi, g))
    fin = np.isfinite(g)
    if n and not (fin.all() or np.isnan(g).all()):
        i = int(np.flatnonzero(~fin)[0])
        raise EyevizError(
            f"row {i + 1}: g = {float(g[i])!r} (g must be finite, or NaN in every row)"
        )
    _check_floats(Path("data set"), 0, r, phi, g, "row")


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
    if not (np.all(head[:, :, 1] == _COMMA) and np.all((head[:, :, 0] | 1) == _ONE)):
        raise ValueError("bad bits")
    w = m // 2
    np.subtract(head[:, :w, 0], _ZERO, out=oa)
    np.subtract(head[:, w:, 0], _ZERO, out=ob)
    tails = [ln[rb:] for ln in block]
    if any(t.count(b",") != nf - 1 for t in tails):
        raise ValueError("bad field count")
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
                    v = float(fv)
                except ValueError:
                    raise _csv_error(path, lineno, j + 1, f"not a number: {_show(fv)}") from None
                if not np.isfinite(v):
                    raise _csv_error(path, lineno, j + 1, f"not a finite number: {v!r}")
