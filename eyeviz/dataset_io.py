"""CSV and NPZ files of data sets (DESIGN.md §3), streamed and written atomically.

CSV: no header, comma separated, ``Omega_A[0..m/2-1], Omega_B[0..m/2-1], r, phi, g``;
bits as ``0``/``1``, floats in Python's shortest round-trip form (``repr``), lines ending
in ``\\n``. The paper's Appendix A/B loader (``row[:720]``, ``row[720]``, ``row[721]``)
reads it unchanged. A CSV without the g column (m + 2 columns) is read too.

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
import json
import os
import tempfile
import zipfile
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

import numpy as np

from eyeviz import EyevizError
from eyeviz.geometry import EyePair

FORMATS = ("csv", "npz")
NPZ_VERSION = 1
_ZERO, _ONE, _COMMA = 48, 49, 44


def format_of(path) -> str:
    suffix = Path(path).suffix.lower().lstrip(".")
    if suffix not in FORMATS:
        raise EyevizError(f"output must end in .csv or .npz, got {str(path)!r}")
    return suffix


@contextlib.contextmanager
def atomic_output(path) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; rename it over ``path`` only on success."""
    path = Path(path)
    d = path.parent if str(path.parent) else Path(".")
    if not d.is_dir():
        raise EyevizError(f"output directory does not exist: {str(d)!r}")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=d)
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; give the file the usual mode
    tmp = Path(tmp)
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise


# --- CSV encoding --------------------------------------------------------------------

class CsvEncoder:
    """Encodes chunks of rows as CSV bytes, reusing one preformatted bit buffer.

    The buffer holds ``0,`` for every bit of ``rows`` rows; a chunk sets its lit bits to
    ``1`` by one scatter, encodes, and sets them back, so no page is touched twice.
    """

    def __init__(self, m: int, rows: int, with_g: bool = True):
        self.w = m // 2
        self.rb = 2 * m  # bytes of the bit columns of one row (m bits, each "b,")
        self.with_g = with_g
        self.buf = np.empty((rows, self.rb), np.uint8)
        self.buf[:, 0::2] = _ZERO
        self.buf[:, 1::2] = _COMMA
        self.flat = self.buf.reshape(-1)

    def _tails(self, r, phi, g) -> list[bytes]:
        if self.with_g:
            s = "{!r},{!r},{!r}\n".format
            lines = map(s, r.tolist(), phi.tolist(), g.tolist())
        else:
            s = "{!r},{!r}\n".format
            lines = map(s, r.tolist(), phi.tolist())
        return [t.encode() for t in lines]

    def _join(self, n: int, tails: list[bytes]) -> bytes:
        rb = self.rb
        mv = memoryview(self.flat)
        parts: list = [None] * (2 * n)
        parts[0::2] = [mv[i * rb:(i + 1) * rb] for i in range(n)]
        parts[1::2] = tails
        return b"".join(parts)

    def _lit_positions(self, lo: np.ndarray, hi: np.ndarray, col0: int) -> np.ndarray:
        """Flat buffer positions of the '0' bytes of bits lo..hi of each row (lo <= hi)."""
        cnt = hi - lo + 1
        tot = int(cnt.sum())
        base = np.arange(lo.shape[0], dtype=np.int64) * self.rb + 2 * (col0 + lo)
        excl = np.cumsum(cnt) - cnt
        return np.repeat(base - 2 * excl, cnt) + 2 * np.arange(tot, dtype=np.int64)

    def encode_intervals(self, r, phi, g, la, ra, lb, rb) -> bytes:
        """Rows whose eye E lights bits L_E..R_E (0 <= L <= R < m/2)."""
        n = r.shape[0]
        pos = np.concatenate([self._lit_positions(la, ra, 0),
                              self._lit_positions(lb, rb, self.w)])
        self.flat[pos] = _ONE
        try:
            return self._join(n, self._tails(r, phi, g))
        finally:
            self.flat[pos] = _ZERO

    def encode_bitmaps(self, omega_a, omega_b, r, phi, g) -> bytes:
        n = r.shape[0]
        view = self.buf[:n]
        w = self.w
        view[:, 0:2 * w:2] = _ZERO + omega_a.view(np.uint8)
        view[:, 2 * w::2] = _ZERO + omega_b.view(np.uint8)
        try:
            return self._join(n, self._tails(r, phi, g))
        finally:
            view[:, 0::2] = _ZERO


# --- NPZ -----------------------------------------------------------------------------

def npz_dtype(m: int) -> np.dtype:
    nb = (m // 2 + 7) // 8
    return np.dtype([("omega_a", np.uint8, (nb,)), ("omega_b", np.uint8, (nb,)),
                     ("r", "<f8"), ("phi", "<f8"), ("g", "<f8")])


def _packed_from_intervals(lo, hi, w: int) -> np.ndarray:
    """np.packbits of the bitmap lit on lo..hi (0 <= lo <= hi < w), without building it."""
    nb = (w + 7) // 8
    start = np.arange(nb, dtype=np.int16) * 8
    a = np.clip(lo.astype(np.int16)[:, None] - start, 0, 8)
    b = np.clip(hi.astype(np.int16)[:, None] + 1 - start, 0, 8)
    # bits a..b-1 of a byte, most significant first: (0xFF >> a) & ~(0xFF >> b)
    full = np.int16(0xFF)
    return ((full >> a) & ~(full >> b)).astype(np.uint8)


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
        header = {"descr": np.lib.format.dtype_to_descr(dt), "fortran_order": False,
                  "shape": (n,)}
        np.lib.format.write_array_header_1_0(self.f, header)

    def write_intervals(self, r, phi, g, la, ra, lb, rb) -> None:
        rows = _npz_rows(self.m, r.shape[0])
        w = self.m // 2
        rows["omega_a"] = _packed_from_intervals(la, ra, w)
        rows["omega_b"] = _packed_from_intervals(lb, rb, w)
        rows["r"], rows["phi"], rows["g"] = r, phi, g
        self.f.write(rows.data)

    def write_bitmaps(self, omega_a, omega_b, r, phi, g) -> None:
        rows = _npz_rows(self.m, r.shape[0])
        rows["omega_a"] = np.packbits(omega_a, axis=1)
        rows["omega_b"] = np.packbits(omega_b, axis=1)
        rows["r"], rows["phi"], rows["g"] = r, phi, g
        self.f.write(rows.data)

    def close(self) -> None:
        self.f.close()
        self.zf.close()


# --- writing -------------------------------------------------------------------------

def write_chunks(path, fmt: str, n: int, m: int, params: dict, chunks: Iterable,
                 progress: Callable[[int], None] | None = None) -> None:
    """Stream generated :class:`eyeviz.dataset.Chunk` objects into ``path``."""
    from eyeviz.dataset import CHUNK

    with atomic_output(path) as tmp:
        if fmt == "csv":
            enc = CsvEncoder(m, CHUNK)
            with open(tmp, "wb") as f:
                for c in chunks:
                    f.write(enc.encode_intervals(c.r, c.phi, c.g, c.la, c.ra, c.lb, c.rb))
                    if progress:
                        progress(len(c))
        else:
            meta = {"version": NPZ_VERSION, "m": m, "n": n, "params": params}
            wr = _NpzWriter(tmp, m, n, meta)
            try:
                for c in chunks:
                    wr.write_intervals(c.r, c.phi, c.g, c.la, c.ra, c.lb, c.rb)
                    if progress:
                        progress(len(c))
            finally:
                wr.close()


def save(ds, path) -> None:
    fmt = format_of(path)
    n, m = len(ds), ds.eyes.m
    step = 1 << 14
    with atomic_output(path) as tmp:
        if fmt == "csv":
            with_g = not bool(np.all(np.isnan(ds.g))) if n else True
            enc = CsvEncoder(m, min(step, max(n, 1)), with_g)
            with open(tmp, "wb") as f:
                for s in range(0, n, step):
                    sl = slice(s, s + step)
                    f.write(enc.encode_bitmaps(ds.omega_a[sl], ds.omega_b[sl], ds.r[sl],
                                               ds.phi[sl], ds.g[sl]))
        else:
            e = ds.eyes
            meta = {"version": NPZ_VERSION, "m": m, "n": n,
                    "params": {**ds.params, "h": e.h, "l": e.l, "m": m}}
            wr = _NpzWriter(tmp, m, n, meta)
            try:
                for s in range(0, n, step):
                    sl = slice(s, s + step)
                    wr.write_bitmaps(ds.omega_a[sl], ds.omega_b[sl], ds.r[sl], ds.phi[sl],
                                     ds.g[sl])
            finally:
                wr.close()


# --- reading -------------------------------------------------------------------------

def load(path, eyes: EyePair | None = None):
    path = Path(path)
    fmt = format_of(path)
    if not path.is_file():
        raise EyevizError(f"no such data set file: {str(path)!r}")
    return _load_npz(path, eyes) if fmt == "npz" else _load_csv(path, eyes)


def _load_npz(path: Path, eyes: EyePair | None):
    from eyeviz.dataset import Dataset

    try:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"][()]))
            rows = z["rows"]
    except (OSError, ValueError, KeyError, zipfile.BadZipFile, json.JSONDecodeError) as exc:
        raise EyevizError(f"{path}: not an eyeviz NPZ data set ({exc})") from None
    m = int(meta["m"])
    params = meta.get("params", {})
    if eyes is None:
        eyes = EyePair(params.get("h", 40.0), params.get("l", 20.0), m)
    elif eyes.m != m:
        raise EyevizError(f"{path}: data set has m={m}, but eyes have m={eyes.m}")
    w = m // 2
    oa = np.unpackbits(rows["omega_a"], axis=1, count=w).view(bool)
    ob = np.unpackbits(rows["omega_b"], axis=1, count=w).view(bool)
    return Dataset(oa, ob, rows["r"].copy(), rows["phi"].copy(), rows["g"].copy(), eyes,
                   params)


def _csv_error(path: Path, line: int, col: int, msg: str) -> EyevizError:
    return EyevizError(f"{path}: line {line}, column {col}: {msg}")


def _csv_lines(data: bytes) -> list[bytes]:
    lines = data.split(b"\n")
    if lines and lines[-1] == b"":
        lines.pop()
    if lines and lines[0].endswith(b"\r"):
        lines = [ln[:-1] if ln.endswith(b"\r") else ln for ln in lines]
    return lines


def _load_csv(path: Path, eyes: EyePair | None):
    from eyeviz.dataset import Dataset

    data = path.read_bytes()
    lines = _csv_lines(data)
    if not lines:
        raise EyevizError(f"{path}: the CSV file is empty")
    ncols = lines[0].count(b",") + 1
    with_g = ncols % 2 == 1
    m = ncols - (3 if with_g else 2)
    if m < 4:
        raise _csv_error(path, 1, ncols, f"too few columns ({ncols}) for a data set row")
    if eyes is None:
        eyes = EyePair(40.0, 20.0, m)
    elif eyes.m != m:
        raise _csv_error(path, 1, ncols, f"{ncols} columns mean m={m}, but eyes have "
                                         f"m={eyes.m}")
    n = len(lines)
    nf = 3 if with_g else 2
    bits = np.empty((n, m), np.uint8)
    floats = np.empty((n, nf))
    step = 1 << 14
    for s in range(0, n, step):
        block = lines[s:s + step]
        try:
            _parse_block(block, m, nf, bits[s:s + len(block)], floats[s:s + len(block)])
        except ValueError:
            _diagnose(path, block, s, m, ncols)
            raise
    w = m // 2
    g = floats[:, 2] if with_g else np.full(n, np.nan)
    bits_b = bits.view(bool)
    return Dataset(bits_b[:, :w].copy(), bits_b[:, w:].copy(), floats[:, 0].copy(),
                   floats[:, 1].copy(), g.copy(), eyes, {})


def _parse_block(block: list[bytes], m: int, nf: int, bits: np.ndarray, floats: np.ndarray):
    """Fast path: every line is exactly ``b,`` * m followed by nf floats."""
    rb = 2 * m
    head = np.frombuffer(b"".join([ln[:rb] for ln in block]), np.uint8)
    if head.size != len(block) * rb:
        raise ValueError("short line")
    head = head.reshape(len(block), m, 2)
    if not (np.all(head[:, :, 1] == _COMMA) and np.all((head[:, :, 0] | 1) == _ONE)):
        raise ValueError("bad bits")
    bits[:] = head[:, :, 0] - _ZERO
    tails = b",".join([ln[rb:] for ln in block]).split(b",")
    if len(tails) != len(block) * nf:
        raise ValueError("bad field count")
    floats[:] = np.array(list(map(float, tails))).reshape(len(block), nf)
    if not np.all(np.isfinite(floats)):
        raise ValueError("non-finite")


def _diagnose(path: Path, block: list[bytes], offset: int, m: int, ncols: int) -> None:
    """Slow path: find the first bad field and raise an error naming line and column."""
    for i, ln in enumerate(block):
        lineno = offset + i + 1
        fields = ln.split(b",")
        if len(fields) != ncols:
            raise _csv_error(path, lineno, min(len(fields), ncols) + (len(fields) < ncols),
                             f"expected {ncols} columns, found {len(fields)}")
        for j, fv in enumerate(fields):
            if j < m:
                if fv not in (b"0", b"1"):
                    raise _csv_error(path, lineno, j + 1,
                                     f"bit must be 0 or 1, got {fv.decode(errors='replace')!r}")
            else:
                try:
                    v = float(fv)
                except ValueError:
                    raise _csv_error(path, lineno, j + 1,
                                     f"not a number: {fv.decode(errors='replace')!r}") from None
                if not np.isfinite(v):
                    raise _csv_error(path, lineno, j + 1, f"not a finite number: {v!r}")
