"""Measured compound eyes: a pair of eyes given as lists of ommatidia (docs/measured.md).

Each ommatidium i of an eye has a lens position p_i (mm, eyeviz's frame: x towards eye B,
y forward, z up), an optical axis a_i (any non-zero vector; only its direction counts) and
a full acceptance angle dr_i in (0, pi). Facet i *sees* a ball (c, g) iff the closed ball
meets the closed acceptance cone {p_i + t u : t >= 0, angle(u, a_i) <= dr_i / 2}, that is,
iff the ball's distance from that cone is <= g (tangency counts as seen, as in the planar
and HEALPix models). Cones may overlap, as in real eyes; the head does not occlude.

This is the third eye model behind the seam of :mod:`eyeviz.core.eyes`; it answers the
same calls as :class:`eyeviz.core.geometry3d.EyePair3D` (``lit``, ``lit_csr``,
``bitmaps``, ``visible``, ``in_bfv``, ``overlaps_eye``).

SKELETON: the decisions below are plain float64 on all facets; the certified fast path,
the exact fallback and the spatial index replace them (issue: real eyes).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.geometry3d import validate_balls
from eyeviz.core.lit_views import LitSetViews
from eyeviz.core.measured_exact import lens_in_ball_exact
from eyeviz.core.measured_fast import EyeTables, decide_pairs, eye_tables, lens_bound, use_jit
from eyeviz.core.measured_index import AxisIndex

__all__ = ["MeasuredEye", "MeasuredEyePair", "MAX_FACETS"]

#: Largest number of ommatidia one eye may have (a file controls it: bounded).
MAX_FACETS = 1_000_000
_CHUNK = 1 << 15  # candidate (ball, facet) pairs per block of the decision
_U = 2.0**-53
_LO, _HI = 2.0**-480, 2.0**480  # the range of |c - p| and g where the float bound holds


def _check_eye_arrays(name: str, positions, axes, acceptance):
    pos = np.asarray(positions, dtype=np.float64)
    ax = np.asarray(axes, dtype=np.float64)
    acc = np.asarray(acceptance, dtype=np.float64)
    if pos.ndim != 2 or pos.shape[1] != 3:
        raise EyevizError(f"eye {name}: lens positions must have shape (n, 3), got {pos.shape}")
    n = pos.shape[0]
    if n < 1:
        raise EyevizError(f"eye {name}: has no ommatidia")
    if n > MAX_FACETS:
        raise EyevizError(f"eye {name}: {n} ommatidia, more than the bound {MAX_FACETS}")
    if ax.shape != (n, 3):
        raise EyevizError(f"eye {name}: axes must have shape ({n}, 3), got {ax.shape}")
    if acc.shape != (n,):
        raise EyevizError(f"eye {name}: acceptance angles must have shape ({n},), got {acc.shape}")
    for what, a in (("lens position", pos), ("axis", ax), ("acceptance angle", acc)):
        bad = ~np.isfinite(a)
        if bad.any():
            i = int(np.flatnonzero(bad.reshape(n, -1).any(axis=1))[0])
            raise EyevizError(f"eye {name}: ommatidium {i}: {what} is not finite")
    zero = ~(ax != 0).any(axis=1)
    if zero.any():
        raise EyevizError(f"eye {name}: ommatidium {int(np.flatnonzero(zero)[0])}: axis is zero")
    bad = ~((acc > 0) & (acc < math.pi))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise EyevizError(
            f"eye {name}: ommatidium {i}: acceptance angle must be in (0, pi) rad, got {acc[i]!r}"
        )
    return pos, ax, acc


@dataclass(frozen=True, eq=False)
class MeasuredEye:
    """One eye: n ommatidia in eyeviz's frame, millimetres.

    positions (n, 3) lens positions; axes (n, 3) optical axes (non-zero; not necessarily
    unit: the model uses each float vector's exact direction); acceptance (n,) full
    acceptance angles in radians, in (0, pi); focal_offset (n,) or None (kept for
    round trips of the file formats, unused by the geometry).
    """

    positions: np.ndarray
    axes: np.ndarray
    acceptance: np.ndarray
    focal_offset: np.ndarray | None = None
    name: str = "eye"

    def __post_init__(self) -> None:
        pos, ax, acc = _check_eye_arrays(self.name, self.positions, self.axes, self.acceptance)
        for k, v in (("positions", pos), ("axes", ax), ("acceptance", acc)):
            v = np.ascontiguousarray(v)
            v.setflags(write=False)
            object.__setattr__(self, k, v)
        if self.focal_offset is not None:
            fo = np.ascontiguousarray(np.asarray(self.focal_offset, dtype=np.float64))
            if fo.shape != acc.shape:
                raise EyevizError(
                    f"eye {self.name}: focal offsets must have shape {acc.shape}, got {fo.shape}"
                )
            fo.setflags(write=False)
            object.__setattr__(self, "focal_offset", fo)

    @property
    def n(self) -> int:
        """Number of ommatidia."""
        return int(self.positions.shape[0])

    @property
    def centroid(self) -> np.ndarray:
        """Mean lens position (mm)."""
        return self.positions.mean(axis=0)

    @property
    def unit_axes(self) -> np.ndarray:
        """The axes normalised (float64; for drawing and indexing, not for decisions).
        Each axis is first scaled by its largest component: no overflow or underflow."""
        a = self.axes / np.abs(self.axes).max(axis=1)[:, None]
        return a / np.linalg.norm(a, axis=1)[:, None]


@dataclass(frozen=True, eq=False)
class MeasuredEyePair(LitSetViews):
    """Two measured eyes, A (left, at -x) and B (right, at +x), in eyeviz's frame (mm).

    ``h`` is half the distance between the two eyes' lens centroids and ``l`` the largest
    distance of a lens from its eye's centroid: the numbers the seam's callers that need a
    scale (cameras, ranges) read. They are derived, not parameters.
    """

    eye_a: MeasuredEye
    eye_b: MeasuredEye
    name: str = "measured eyes"
    source: str = ""
    _cache: dict = field(default_factory=dict, repr=False, compare=False)
    #: the binocular fields Algorithm 1 draws in: a real pair's own (``in_bfv``), as no
    #: tangent cones bound it
    binocular_fields: ClassVar[tuple[str, ...]] = ("both-eyes",)

    # --- what the seam (eyeviz.core.eyes.EyeModel) asks -------------------------------
    @property
    def kind(self) -> str:
        """``"measured"``: eyes given as lists of ommatidia."""
        return "measured"

    @property
    def dims(self) -> int:
        return 3

    @property
    def facet_counts(self) -> tuple[int, int]:
        """(n_A, n_B): ommatidia per eye (the two eyes may differ)."""
        return (self.eye_a.n, self.eye_b.n)

    @property
    def h(self) -> float:
        ca, cb = self.eye_a.centroid, self.eye_b.centroid
        return float(np.linalg.norm(cb - ca) / 2)

    @property
    def l(self) -> float:  # noqa: E743  (the seam's name)
        return float(
            max(
                np.linalg.norm(e.positions - e.centroid, axis=1).max()
                for e in (self.eye_a, self.eye_b)
            )
        )

    @property
    def centers(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """The two eyes' lens centroids."""
        a, b = self.eye_a.centroid, self.eye_b.centroid
        return (tuple(map(float, a)), tuple(map(float, b)))  # type: ignore[return-value]

    @property
    def fingerprint(self) -> str:
        """sha256 of the two eyes' arrays (bit for bit): what a data set stores."""
        if "fp" not in self._cache:
            hsh = hashlib.sha256()
            for e in (self.eye_a, self.eye_b):
                hsh.update(np.int64(e.n).tobytes())
                for a in (e.positions, e.axes, e.acceptance):
                    hsh.update(np.ascontiguousarray(a, dtype="<f8").tobytes())
            self._cache["fp"] = hsh.hexdigest()
        return self._cache["fp"]

    @property
    def design(self) -> dict[str, float | int | str]:
        """What a data set or an estimator must agree on: the eyes' fingerprint."""
        return {"eye": self.fingerprint, "n_a": self.eye_a.n, "n_b": self.eye_b.n}

    def eye(self, eye: str) -> MeasuredEye:
        if eye == "A":
            return self.eye_a
        if eye == "B":
            return self.eye_b
        raise ValueError(f"eye must be 'A' or 'B', got {eye!r}")

    def facets(self, eye: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(positions (n, 3) mm, axes (n, 3), full acceptance angles (n,) rad) of one eye."""
        e = self.eye(eye)
        return e.positions, e.axes, e.acceptance

    # --- the geometry ------------------------------------------------------------------
    def _prepared(self, which: str) -> tuple[EyeTables, AxisIndex]:
        """The fast path's tables and the axis index of one eye, built once per pair."""
        key = ("prepared", which)
        if key not in self._cache:
            e = self.eye(which)
            centre = e.centroid
            tables = eye_tables(e.positions, e.axes, e.acceptance)
            index = AxisIndex(
                e.unit_axes,
                centre,
                lens_bound(e.positions, centre),
                float(e.acceptance.max()) / 2,
            )
            self._cache[key] = (tables, index)
        return self._cache[key]

    def _lit_eye(self, which: str, balls, *, index: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """CSR (indptr, indices) of the facets of one eye that see each ball: candidates
        from the axis index (or every facet: ``index=False``, the brute-force pass), then
        the certified decision with its exact fallback (docs/measured.md)."""
        tables, ix = self._prepared(which)
        nb, n = balls[0].size, ix.n
        jit = use_jit(nb)
        if index:
            bi, fi = ix.candidates(*balls, jit=jit)
        else:
            bi, fi = np.repeat(np.arange(nb), n), np.tile(np.arange(n), nb)
        lit = []
        for k in range(0, bi.size, _CHUNK):
            b, f = bi[k : k + _CHUNK], fi[k : k + _CHUNK]
            seen = decide_pairs(tables, balls, b, f, jit=jit)
            lit.append(b[seen] * n + f[seen])
        keys = np.sort(np.concatenate(lit)) if lit else np.zeros(0, np.int64)
        indptr = np.searchsorted(keys, np.arange(nb + 1, dtype=np.int64) * n)
        return indptr.astype(np.int64), (keys % n).astype(np.int64)

    def _flat_balls(self, x, y, z, g) -> tuple[tuple[int, ...], tuple[np.ndarray, ...]]:
        xa, ya, za, ga = validate_balls(x, y, z, g)
        return xa.shape, tuple(np.ascontiguousarray(a).reshape(-1) for a in (xa, ya, za, ga))

    def lit_csr(self, x, y, z, g) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
        """Per eye (A, B): (indptr, indices) of the facets that see each ball, CSR over
        the flattened balls, indices sorted int64."""
        _, balls = self._flat_balls(x, y, z, g)
        return self._lit_eye("A", balls), self._lit_eye("B", balls)

    def _lens_in_ball(self, which: str, balls) -> np.ndarray:
        """Per ball: the closed ball contains a lens of the eye, exactly. Only balls whose
        centre is within L + g of the eye's centre can (the index's ``every`` case); their
        |c - p|^2 - g^2 is decided in float64 with the bound 16 u (|c - p|^2 + g^2) of
        :mod:`eyeviz.core.measured_fast`, the rest in rationals."""
        tables, ix = self._prepared(which)
        cx, cy, cz, g = balls
        out = np.zeros(cx.size, bool)
        near = np.flatnonzero(~np.isfinite(ix.search(*balls)[1]))
        n = ix.n
        step = max(1, _CHUNK // n)
        for k in range(0, near.size, step):
            b = near[k : k + step]
            with np.errstate(all="ignore"):
                v = [
                    c[b][:, None] - p[None, :]
                    for c, p in zip(balls[:3], tables.columns(), strict=True)
                ]
                v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
                g2 = (g[b] * g[b])[:, None]
                da, bound = v2 - g2, 16 * _U * (v2 + g2)
                mag = np.maximum(np.maximum(np.abs(v[0]), np.abs(v[1])), np.abs(v[2]))
                ok = (mag >= _LO) & (mag <= _HI) & (g[b] <= _HI)[:, None]
            inside = (ok & (da <= -bound)) | (mag == 0)
            unsure = ~inside & ~(ok & (da > bound))
            hit = inside.any(axis=1)
            for r in np.flatnonzero(~hit & unsure.any(axis=1)).tolist():
                c = (float(cx[b[r]]), float(cy[b[r]]), float(cz[b[r]]))
                hit[r] = any(
                    lens_in_ball_exact(c, float(g[b[r]]), tables.positions[i].tolist())
                    for i in np.flatnonzero(unsure[r]).tolist()
                )
            out[b] = hit
        return out

    def responses(self, x, y, z, g, kind: str | None = None, support: str = "cone"):
        """Graded responses per eye (A, B): (indptr, indices, values), the lit sets of
        :meth:`lit_csr` with each lit facet's response in [0, 1]; ``kind`` ``"flat"``
        (the default) or ``"gaussian"``; ``support="sphere"`` gives the gaussian kernel
        untruncated, normalised over the sphere, on the same lit facets
        (docs/responses.md)."""
        from eyeviz.core.responses import check_kind, measured_values

        k = check_kind("measured", kind)
        if support not in ("cone", "sphere") or (support == "sphere" and k != "gaussian"):
            raise EyevizError(
                f"support {support!r}: 'cone', or 'sphere' for the gaussian kernel only"
            )
        _, balls = self._flat_balls(x, y, z, g)
        out = []
        for w in "AB":
            indptr, indices = self._lit_eye(w, balls)
            e = self.eye(w)
            vals = measured_values(
                e.positions, e.unit_axes, e.acceptance, balls, indptr, indices, k, support
            )
            out.append((indptr, indices, vals))
        return out[0], out[1]

    def overlaps_eye(self, x, y, z, g) -> tuple[np.ndarray, np.ndarray]:
        """Per eye: the closed ball contains a lens of that eye (exact)."""
        shape, balls = self._flat_balls(x, y, z, g)
        return tuple(self._lens_in_ball(w, balls).reshape(shape) for w in "AB")  # type: ignore[return-value]

    def in_bfv(self, x, y, z, g) -> np.ndarray:
        """The binocular field of a measured pair: the ball lights at least two facets of
        each eye and contains no lens of either eye (docs/measured.md)."""
        va, vb = self.visible(x, y, z, g)
        oa, ob = self.overlaps_eye(x, y, z, g)
        return va & vb & ~oa & ~ob
