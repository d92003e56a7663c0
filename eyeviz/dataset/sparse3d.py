"""The sparse 3D data set file (NPZ): streamed, atomic writer and a reader that checks all.

A dense bitmap at nside 180 is 388,800 bits per eye and row; a ball lights a few thousand
facets, so each eye's lit facets are stored as CSR lists. The file is an uncompressed zip
of ``.npy`` members (numpy's NPZ, readable by ``numpy.load`` without pickles):

- ``meta``: a JSON string: ``format`` (:data:`FORMAT`), ``version``
  (:data:`VERSION`), ``n``, ``nnz_a``, ``nnz_b``, ``index_dtype``, ``domain`` (h, l,
  nside, r_min, r_max, g_max, el_max: :class:`eyeviz.core.domain.Domain3D`) and
  ``params`` (mode, seed, segments);
- ``indptr_a``, ``indptr_b``: int64 (n + 1,), 0 first, nnz last, non-decreasing;
- ``indices_a``, ``indices_b``: the RING indices (int32 while 12 nside^2 <= 2^31, int64
  beyond), strictly increasing within a row: row i of eye A is
  ``indices_a[indptr_a[i]:indptr_a[i + 1]]``;
- ``r``, ``azimuth``, ``elevation``, ``g`` (radians for the angles) and ``x``, ``y``,
  ``z`` (the centre the lit sets were computed at): float64 (n,).

A data set of measured eyes (``eyeviz generate --eye``) is the same format: its domain
names the pair by fingerprint (``eye``, ``n_a``, ``n_b`` in place of ``nside``), each
eye's indices are facet numbers in [0, n_A) and [0, n_B), r, azimuth and elevation are
about the midpoint of the two lens centroids (:attr:`Domain3D.origin`), and the pair
itself is embedded (:mod:`eyeviz.dataset.embedded_eyes`): the reader rebuilds it, checks
its fingerprint and re-computes a few rows' lit sets.

Writing streams chunk by chunk in bounded memory: each chunk's arrays are appended to
one spool file per member next to the output, and the zip is assembled at the end by
copying the spools into members whose headers now know their lengths. Spools and the
zip are temporary files of :mod:`eyeviz.files.atomic`'s naming (swept if a writer is
killed); the zip is renamed over the output only when complete, so an interruption
leaves nothing. Reading (:class:`Sparse3DReader`) never unpickles, checks every size the
file declares against the file before allocating, and checks every row.
"""

from __future__ import annotations

import json
import math
import os
import struct
import zipfile
import zlib
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.domain import FIELDS3D, Domain3D
from eyeviz.core.validation import check_int
from eyeviz.dataset import embedded_eyes, responses3d
from eyeviz.dataset.algorithm1_3d import check_n, iter_chunks3d, make_params3d
from eyeviz.dataset.records import Dataset3D, index_dtype
from eyeviz.dataset.spools import Spools
from eyeviz.files import limits
from eyeviz.files.atomic import atomic_output
from eyeviz.files.npz import NpzReader

__all__ = [
    "FORMAT",
    "VERSION",
    "Sparse3DReader",
    "check_output_path",
    "estimated_bytes3d",
    "load3d",
    "write3d",
    "write_chunks3d",
]

FORMAT = "eyeviz.sparse3d"
VERSION = 1
FLOATS = ("r", "azimuth", "elevation", "g", "x", "y", "z")
EYES = ("a", "b")
MEMBERS = ("indptr_a", "indices_a", "indptr_b", "indices_b", *FLOATS)
_COPY = 8 << 20  # bytes per copy from a spool into the zip
_META_MAX_BYTES = 1 << 16
_MAX_HEADER = 10_000
#: rows and lit indices (per eye) of one block read
BLOCK_ROWS = 1 << 14
BLOCK_LIT = 1 << 23


def check_output_path(path: str | os.PathLike) -> Path:
    """A 3D data set is an NPZ: refuse any other suffix (.csv holds planar bitmaps)."""
    p = Path(path)
    if p.suffix.lower() != ".npz":
        raise EyevizError(
            f"a 3D data set (--nside) is written as .npz (sparse lit lists), got {str(path)!r}"
        )
    return p


def estimated_bytes3d(n: int, domain: Domain3D) -> int:
    """Disk space a run needs at its peak (the spools and the zip side by side), roughly.

    A ball of angular radius a ~ g/r lights about npix a^2 / 4 facets; over g uniform in
    [0, g_max] and r uniform in [r_min, r_max] that averages npix g_max^2 / (12 r_min
    r_max), plus a rim of about 8 pi (g/r) / (cell width) facets.
    """
    d = domain
    # ratios, not g_max**2 (which raised OverflowError for g_max = 1e300): a ball wider
    # than its distance lights the whole eye at most
    mean_a = min(1.0, d.g_max / math.sqrt(d.r_min) / math.sqrt(d.r_max)) / 2
    if d.kind == "measured":
        # facets spread over about a hemisphere (solid angle 2 pi): a ball lights those
        # within its angular radius (rms g/r over the draws) plus the widest half
        # acceptance plus a facet spacing; twice that, as a real eye's facets crowd
        npix = max(d.facet_counts)
        rms_a = min(1.0, d.g_max / math.sqrt(3 * d.r_min) / math.sqrt(d.r_max))
        half = max(float(e.acceptance.max()) for e in (d.eyes.eye_a, d.eyes.eye_b)) / 2
        lit = min(npix, npix * (rms_a + half + d.gamma) ** 2 + 2)
        per_row = 2 * lit * index_dtype(npix).itemsize + 8 * (2 + len(FLOATS))
        return int(2 * n * per_row) + 2 * 56 * sum(d.facet_counts)
    npix = d.npix
    rim = 8 * math.pi * mean_a / math.sqrt(4 * math.pi / npix)
    share = min(1.0, d.g_max / d.r_min) * min(1.0, d.g_max / d.r_max) / 12
    lit = min(npix, npix * share + rim + 2)
    per_row = 2 * lit * index_dtype(npix).itemsize + 8 * (2 + len(FLOATS))
    return int(2 * n * per_row)


# --- writing -------------------------------------------------------------------------


def write_chunks3d(
    path: str | os.PathLike,
    n: int,
    domain: Domain3D,
    params: dict,
    chunks: Iterable[Dataset3D],
    progress: Callable[[int], None] | None = None,
    responses: str | None = None,
) -> None:
    """Stream generated chunks (:class:`Dataset3D`) into ``path``, atomically; with
    ``responses`` (a kind) each chunk's values too (:mod:`eyeviz.dataset.responses3d`)."""
    target = check_output_path(path)
    idt = index_dtype(max(domain.facet_counts))
    members = MEMBERS + (responses3d.VALUE_MEMBERS if responses else ())
    with atomic_output(target) as tmp:
        spools = Spools(tmp.parent / target.name, members)  # beside the temporary
        try:
            base = dict.fromkeys(EYES, 0)
            for e in EYES:
                spools.append(f"indptr_{e}", np.zeros(1, np.int64))
                spools.dtypes[f"indices_{e}"] = idt
            rows = 0
            for c in chunks:
                for e in EYES:
                    ptr = getattr(c, f"indptr_{e}")
                    spools.append(f"indptr_{e}", ptr[1:].astype(np.int64) + base[e])
                    spools.append(
                        f"indices_{e}", getattr(c, f"indices_{e}").astype(idt, copy=False)
                    )
                    base[e] += int(ptr[-1])
                    if responses:
                        spools.append(f"values_{e}", getattr(c, f"values_{e}").astype("<f8"))
                for name in FLOATS:
                    spools.append(name, getattr(c, name).astype(np.float64))
                rows += len(c)
                if progress:
                    progress(len(c))
            if rows != n:
                raise EyevizError(f"the generator gave {rows} rows, not n={n}")
            meta = {
                "format": FORMAT,
                "version": VERSION,
                "n": n,
                "nnz_a": base["a"],
                "nnz_b": base["b"],
                "index_dtype": idt.name,
                "domain": domain.to_dict(),
                "params": {k: v for k, v in params.items() if k not in domain.to_dict()},
            }
            if responses:
                meta["responses"] = responses
            with zipfile.ZipFile(tmp, "w", zipfile.ZIP_STORED, allowZip64=True) as zf:
                with zf.open("meta.npy", "w") as f:
                    np.lib.format.write_array(f, np.array(json.dumps(meta)), allow_pickle=False)
                for name in members:
                    spools.copy_into(zf, name)
                if domain.kind == "measured":  # the pair itself: the file is self-contained
                    for name, arr in embedded_eyes.eye_arrays(domain.eyes).items():
                        with zf.open(name + ".npy", "w", force_zip64=True) as f:
                            np.lib.format.write_array(f, arr, allow_pickle=False)
        finally:
            spools.close()


def write3d(
    path: str | os.PathLike,
    n: int,
    domain: Domain3D | None = None,
    mode: str = "single",
    seed: int = 0,
    segments: int | None = None,
    progress: Callable[[int], None] | None = None,
    field: str | None = None,
    responses: str | None = None,
) -> None:
    """Generate n elements of Algorithm 1 in 3D straight into ``path`` (.npz), streamed
    and atomic. Every parameter is checked before the file is touched; ``progress(k)`` is
    called after each chunk of k elements; ``field``: see :func:`make_params3d`;
    ``responses`` (a kind the eyes answer) adds each lit facet's graded response."""
    check_output_path(path)
    n = check_n(n)
    p = make_params3d(domain, mode, seed, segments, field)
    chunks: Iterable[Dataset3D] = iter_chunks3d(n, p)
    if responses is not None:
        responses = responses3d.check_kind(p.domain.kind, responses)
        chunks = responses3d.with_values(chunks, p.domain.eyes, responses)
    write_chunks3d(path, n, p.domain, p.as_dict(), chunks, progress, responses)


# --- reading -------------------------------------------------------------------------


class _Member:
    """A stored ``.npy`` member: its dtype, length and absolute data offset in the file,
    and the zip's CRC-32 of the member (its ``.npy`` header included: ``head``)."""

    def __init__(self, dtype: np.dtype, length: int, offset: int, head: bytes, crc: int):
        self.dtype, self.length, self.offset = dtype, length, offset
        self.end = offset + length * dtype.itemsize
        self.head_crc, self.crc = zlib.crc32(head), crc


class _Crc:
    """A member's running CRC-32 over the bytes read so far, in file order."""

    def __init__(self, m: _Member):
        self.pos, self.crc = m.offset, m.head_crc

    def feed(self, at: int, data: memoryview) -> None:
        """Bytes ``data`` read at file offset ``at`` (reads never go backwards by more
        than what was already counted)."""
        if at <= self.pos < at + len(data):
            self.crc = zlib.crc32(data[self.pos - at :], self.crc)
            self.pos = at + len(data)


class Sparse3DReader:
    """A sparse 3D data set opened for reading; everything it declares is checked here.

    ``.domain`` (:class:`Domain3D`), ``.params``, ``.n``, ``.nnz_a``, ``.nnz_b``; iterate
    for validated :class:`Dataset3D` blocks of at most ``block_rows`` rows and
    ``block_lit`` lit indices per eye (one row at least), or :meth:`read_all`.
    """

    def __init__(self, path, block_rows: int = BLOCK_ROWS, block_lit: int = BLOCK_LIT):
        self.path = Path(path)
        self.block_rows = check_int("block_rows", block_rows, ge=1, le=1 << 30)
        self.block_lit = check_int("block_lit", block_lit, ge=1, le=1 << 40)
        try:
            self.size = limits.check_file_size(self.path, 1 << 62, "data set")
            with zipfile.ZipFile(self.path) as zf:
                infos = {i.filename: i for i in zf.infolist()}
            if "meta.npy" not in infos:
                raise self.fail("member 'meta' is missing")
            with NpzReader(self.path) as npz:
                meta_arr = npz.read_member(
                    "meta", 1, dtypes=("U",), ndim=0, max_bytes=_META_MAX_BYTES
                )
            with open(self.path, "rb") as f:
                names = MEMBERS + tuple(v for v in responses3d.VALUE_MEMBERS if v + ".npy" in infos)
                self.members = {name: self._member(f, infos, name) for name in names}
                self._eye_members = {
                    name: self._member(f, infos, name)
                    for name in embedded_eyes.EYE_MEMBERS
                    if name + ".npy" in infos
                }
        except EyevizError:
            raise
        except Exception as exc:  # noqa: BLE001 - BadZipFile, numpy's header TokenError, ...
            raise self.fail(f"not a readable .npz ({_one_line(exc)})") from None
        self._check_meta(meta_arr)

    def fail(self, msg: str) -> EyevizError:
        return EyevizError(f"{self.path}: {msg}")

    def _member(self, f: BinaryIO, infos: dict, name: str) -> _Member:
        """The header of member ``name``, its bytes checked to lie inside the file."""
        info = infos.get(name + ".npy")
        if info is None:
            raise self.fail(f"member {name!r} is missing")
        if info.compress_type != zipfile.ZIP_STORED or info.flag_bits & 1:
            raise self.fail(f"member {name!r} is compressed or encrypted; only stored")
        if info.compress_size != info.file_size:
            raise self.fail(f"member {name!r} declares {info.file_size} bytes stored in "
                            f"{info.compress_size}")  # fmt: skip
        f.seek(info.header_offset)
        local = f.read(30)
        if len(local) != 30 or local[:4] != b"PK\x03\x04":
            raise self.fail(f"member {name!r}: bad local header")
        name_len, extra_len = struct.unpack("<HH", local[26:30])
        start = info.header_offset + 30 + name_len + extra_len
        if start + info.file_size > self.size:
            raise self.fail(f"member {name!r} declares {info.file_size} bytes the file lacks")
        f.seek(start)
        version = np.lib.format.read_magic(f)
        if version == (1, 0):
            hdr = np.lib.format.read_array_header_1_0(f, max_header_size=_MAX_HEADER)
        elif version in ((2, 0), (3, 0)):
            hdr = np.lib.format.read_array_header_2_0(f, max_header_size=_MAX_HEADER)
        else:
            raise self.fail(f"member {name!r} has .npy version {version}")
        shape, fortran, dtype = hdr
        if dtype.hasobject or dtype.fields is not None or dtype.subdtype is not None:
            raise self.fail(f"member {name!r} has dtype {dtype}, not a plain array")
        if len(shape) != 1 or fortran:
            raise self.fail(f"member {name!r} has shape {shape}, expected 1-D")
        body = info.file_size - (f.tell() - start)
        if shape[0] * dtype.itemsize != body:
            raise self.fail(
                f"member {name!r} declares shape {shape} ({shape[0] * dtype.itemsize} bytes) "
                f"but holds {body} bytes"
            )
        offset = f.tell()
        f.seek(start)
        head = f.read(offset - start)
        return _Member(dtype, int(shape[0]), offset, head, info.CRC)

    def _check_meta(self, meta_arr: np.ndarray) -> None:
        try:
            meta = json.loads(str(meta_arr[()]))
            if not isinstance(meta, dict):
                raise TypeError("meta is not an object")
            if meta.get("format") != FORMAT:
                raise ValueError(f"format is {meta.get('format')!r}, not {FORMAT!r}")
            if meta.get("version") != VERSION:
                raise ValueError(f"version {meta.get('version')!r}; this eyeviz reads {VERSION}")
            dom = meta["domain"]
            if not isinstance(dom, dict):
                raise TypeError("domain is not an object")
            keys = FIELDS3D if "eye" not in dom else _MEASURED_KEYS
            missing = [k for k in keys if k not in dom]
            if missing:
                raise KeyError(missing[0])
            self.pair = self._embedded_pair(dom) if "eye" in dom else None
            self.domain = Domain3D.from_dict(dom, eyes=self.pair)
            self.n = check_int("n", meta["n"], ge=0, le=limits.MAX_ROWS)
            self.nnz_a = check_int("nnz_a", meta["nnz_a"], ge=0, le=1 << 62)
            self.nnz_b = check_int("nnz_b", meta["nnz_b"], ge=0, le=1 << 62)
            params = meta.get("params", {})
            if not isinstance(params, dict):
                raise TypeError("params is not an object")
            self.params = params
            kind = meta.get("responses")
            self.responses = None if kind is None else responses3d.check_kind(d_kind(dom), kind)
            if self.responses:
                self.params = {**params, "responses": self.responses}
        except EyevizError as exc:
            raise self.fail(f"bad meta: {exc}") from None
        except (ValueError, KeyError, TypeError, OverflowError, IndexError) as exc:
            raise self.fail(f"bad meta: {_one_line(exc)}") from None
        self.counts = dict(zip(EYES, self.domain.facet_counts, strict=True))
        self.npix = max(self.domain.facet_counts)  # the index dtype's bound
        d = self.domain
        self._eyes = self.pair if self.pair is not None else d.eyes
        self._eyes_text = (
            "the embedded eyes"
            if self.pair is not None
            else f"the file's design h={d.h:g}, l={d.l:g}, nside={d.nside} (re-computed "
            "from the stored balls)"
        )
        want: dict[str, tuple[np.dtype, int]] = {
            f"indptr_{e}": (np.dtype("<i8"), self.n + 1) for e in EYES
        }
        for e in EYES:
            nnz = self.nnz_a if e == "a" else self.nnz_b
            want[f"indices_{e}"] = (index_dtype(self.npix).newbyteorder("<"), nnz)
        for name in FLOATS:
            want[name] = (np.dtype("<f8"), self.n)
        if self.responses:
            for e in EYES:
                want[f"values_{e}"] = (np.dtype("<f8"), self.nnz_a if e == "a" else self.nnz_b)
        for name, (dt, length) in want.items():
            if name not in self.members:
                raise self.fail(f"member {name!r} is missing (the meta names responses)")
            m = self.members[name]
            if m.dtype != dt or m.length != length:
                raise self.fail(
                    f"member {name!r} has dtype {m.dtype} length {m.length}, "
                    f"expected {dt} length {length}"
                )

    def _embedded_pair(self, dom: dict):
        """The measured pair embedded in the file, its sizes and fingerprint checked."""
        n_a, n_b = embedded_eyes.check_counts(dom["n_a"], dom["n_b"])
        arrays = {}
        with open(self.path, "rb") as f:
            self._crcs = {}
            for name, length in embedded_eyes.expected_lengths(n_a, n_b).items():
                m = self._eye_members.get(name)
                if m is None:
                    raise EyevizError(f"member {name!r} is missing (the embedded eyes)")
                if m.dtype != np.dtype("<f8") or m.length != length:
                    raise EyevizError(
                        f"member {name!r} has dtype {m.dtype} length {m.length}, "
                        f"expected float64 length {length}"
                    )
                self.members[name] = m  # read and CRC-checked as every member
                self._crcs[name] = _Crc(m)
                arrays[name] = self._read(f, name, 0, length)
        return embedded_eyes.pair_from_arrays(arrays, str(dom["eye"]))

    # -- rows --

    def _read(self, f: BinaryIO, name: str, start: int, count: int) -> np.ndarray:
        m = self.members[name]
        out = np.empty(count, m.dtype)
        at = m.offset + start * m.dtype.itemsize
        f.seek(at)
        buf = out.view(np.uint8).reshape(-1).data
        got = 0
        while got < len(buf):
            k = f.readinto(buf[got:])  # type: ignore[attr-defined]
            if not k:
                raise self.fail(f"member {name!r} ends early")
            got += k
        self._crcs[name].feed(at, buf)
        return out

    def _check_crcs(self, f: BinaryIO) -> None:
        """Every member read to its end matches the zip's CRC-32 (damage that keeps the
        rows valid, a flipped bit in a float or an index, is found here)."""
        for name, m in self.members.items():
            c = self._crcs[name]
            while c.pos < m.end:  # bytes no block needed (n = 0: the lone indptr 0)
                k = min(_COPY, m.end - c.pos)
                f.seek(c.pos)
                data = f.read(k)
                if len(data) != k:
                    raise self.fail(f"member {name!r} ends early")
                c.feed(c.pos, memoryview(data))
            if c.crc != m.crc:
                raise self.fail(f"member {name!r} is damaged (its CRC-32 does not match)")

    def _ptr_block(self, f: BinaryIO, e: str, start: int, k: int, prev: int) -> np.ndarray:
        """indptr_e[start .. start + k] checked: starts where the last block ended (0 at
        row 0), non-decreasing, at most nnz, and each row at most npix long."""
        nnz = self.nnz_a if e == "a" else self.nnz_b
        npix = self.counts[e]
        ptr = self._read(f, f"indptr_{e}", start, k + 1)
        if ptr[0] != prev:
            raise self.fail(f"indptr_{e}: row {start + 1} starts at {int(ptr[0])}, not {prev}")
        d = np.diff(ptr)
        bad = (d < 0) | (d > npix)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise self.fail(
                f"indptr_{e}: row {start + i + 1} has {int(d[i])} indices "
                f"(need 0..{npix}: indptr must not decrease)"
            )
        if ptr[-1] > nnz or (start + k == self.n and ptr[-1] != nnz):
            raise self.fail(f"indptr_{e} ends at {int(ptr[-1])}, but nnz_{e} is {nnz}")
        return ptr

    def _check_indices(self, e: str, start: int, ptr: np.ndarray, ind: np.ndarray) -> None:
        """Every index in [0, npix), strictly increasing within each row."""
        npix = self.counts[e]
        bad = (ind < 0) | (ind >= npix)
        if ind.size > 1:
            step_bad = np.diff(ind) <= 0
            first = ptr[1:-1] - ptr[0]  # where rows 2.. begin: no order across rows
            first = first[(first > 0) & (first < ind.size)]
            step_bad[first - 1] = False
            bad[1:] |= step_bad
        if bad.any():
            j = int(np.flatnonzero(bad)[0])
            row = int(np.searchsorted(ptr - ptr[0], j, side="right")) - 1
            v = int(ind[j])
            why = f"outside [0, {npix})" if not 0 <= v < npix else "not increasing"
            raise self.fail(f"indices_{e}: row {start + row + 1}: index {v} {why}")

    def _check_floats(self, start: int, cols: dict[str, np.ndarray]) -> None:
        d = self.domain
        r, az, el, g = cols["r"], cols["azimuth"], cols["elevation"], cols["g"]
        o = d.origin  # (0, 0, 0) for HEALPix eyes
        tol = 1e-9 * (r + max(abs(v) for v in o))
        with np.errstate(invalid="ignore", over="ignore"):
            ok = (r >= d.r_min) & (r <= d.r_max)
            ok &= (az >= 0) & (az <= math.pi)
            ok &= (np.abs(el) <= d.el_max) & (g > 0) & (g <= d.g_max)
            c = np.cos(el)
            for name, want, at in (
                ("x", r * c * np.cos(az), o[0]),
                ("y", r * c * np.sin(az), o[1]),
                ("z", r * np.sin(el), o[2]),
            ):
                ok &= np.abs(cols[name] - at - want) <= tol
        if not ok.all():
            i = int(np.flatnonzero(~ok)[0])
            vals = ", ".join(f"{k}={float(v[i])!r}" for k, v in cols.items())
            raise self.fail(
                f"row {start + i + 1}: {vals} (need r in [{d.r_min:g}, {d.r_max:g}], "
                f"0 <= azimuth <= pi, |elevation| <= el_max={d.el_max:.6g}, "
                f"0 < g <= {d.g_max:g}, x, y, z the centre of r, azimuth, elevation"
                f"{' about the origin ' + str(o) if d.kind == 'measured' else ''})"
            )

    def __iter__(self) -> Iterator[Dataset3D]:
        try:
            with open(self.path, "rb") as f:
                yield from self._blocks(f)
        except EyevizError:
            raise
        except (OSError, ValueError) as exc:
            raise self.fail(_one_line(exc)) from None

    def _blocks(self, f: BinaryIO) -> Iterator[Dataset3D]:
        self._crcs = {name: _Crc(m) for name, m in self.members.items()}
        start, prev = 0, dict.fromkeys(EYES, 0)
        if self.n == 0:
            self._check_crcs(f)
        while start < self.n:
            k = min(self.block_rows, self.n - start)
            ptrs = {e: self._ptr_block(f, e, start, k, prev[e]) for e in EYES}
            # fewer rows when their lit lists exceed block_lit (one row at least)
            for e in EYES:
                p = ptrs[e]
                fit = int(np.searchsorted(p - p[0], self.block_lit, side="right")) - 1
                k = max(1, min(k, fit))
            out: dict[str, Any] = {}
            for e in EYES:
                p = ptrs[e][: k + 1]
                ind = self._read(f, f"indices_{e}", int(p[0]), int(p[-1] - p[0]))
                self._check_indices(e, start, p, ind)
                out[f"indptr_{e}"], out[f"indices_{e}"] = p - p[0], ind
                if self.responses:
                    out[f"values_{e}"] = self._read(f, f"values_{e}", int(p[0]), ind.size)
                prev[e] = int(p[-1])
            cols = {name: self._read(f, name, start, k) for name in FLOATS}
            self._check_floats(start, cols)
            if start + k == self.n:  # before the last block is handed out
                self._check_crcs(f)
            block = Dataset3D(**out, **cols, domain=self.domain, params=dict(self.params))
            # a few rows' lit sets re-computed from their stored balls: an edited design or
            # swapped eye members (a valid CRC either way) are refused, not answered
            bad = embedded_eyes.check_lit_rows(self._eyes, block, start, self.n)
            if bad:
                raise self.fail(f"the lit sets do not match {self._eyes_text}: {bad}")
            if self.responses:
                bad = responses3d.check_values(block, start) or responses3d.check_value_rows(
                    self._eyes, block, start, self.n, self.responses
                )
                if bad:
                    raise self.fail(bad)
            yield block
            start += k

    def read_all(self) -> Dataset3D:
        """Every row, checked (an empty data set has n = 0 rows)."""
        blocks = list(self)
        if blocks:
            return Dataset3D.concat(blocks)
        ptr = np.zeros(1, np.int64)
        idx = np.zeros(0, index_dtype(self.npix))
        empty = np.zeros(0)
        floats = dict.fromkeys(FLOATS, empty)
        vals = empty if self.responses else None
        d, p = self.domain, self.params
        return Dataset3D(
            ptr, idx, ptr, idx, **floats, domain=d, params=p, values_a=vals, values_b=vals
        )


def d_kind(dom: dict) -> str:
    """The eye model a stored domain names."""
    return "measured" if "eye" in dom else "spherical"


#: The domain keys of a measured data set (the pair by fingerprint, no nside).
_MEASURED_KEYS = ("h", "l", "eye", "n_a", "n_b", "r_min", "r_max", "g_max", "el_max")


def load3d(path) -> Dataset3D:
    """A whole sparse 3D data set in memory, every row checked (first bad one named)."""
    return Sparse3DReader(path).read_all()


def _one_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0][:200] if text else type(exc).__name__
