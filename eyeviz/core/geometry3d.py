"""The spherical binocular eye: two HEALPix eyes, features are balls (docs/spherical.md).

Two spherical eyes of radius l at A = (-h, 0, 0) and B = (h, 0, 0); x right, y forward,
z up; the plane z = 0 is the paper's planar model (Section 8 names this as its next goal).
Facets are HEALPix cells in RING order (:mod:`eyeviz.core.healpix`), 12 nside^2 per eye.

A facet is lit iff some direction of the closed tangent cone from the eye centre to the
ball (the cap of half-angle alpha = asin(g / |d|) about d / |d|; the whole eye when
|d| <= g) maps to it under ang2pix, in exact real arithmetic on the float inputs: the 3D
Proposition 2. The cap is closed with interior and a cell is the closure of its interior
minus part of its boundary, so a cell is lit iff the distance from the cap centre to the
cell's closure is < alpha, or = alpha with a touch point that ang2pix maps to the cell.

The float64 fast path, per ball and eye: the rings the cap's z-range meets; per ring the
candidate cells from the cap's widest longitude span over the ring's z-band and the
surely lit cells from its span on the ring's own z (where each cell's W-E diagonal lies);
the few cells between are tested on their vertices and edges with a proven
second-derivative bound of the edge curves plus the rounding bound of float64. Only the
cells that stay within both bounds of the cap's boundary reach :mod:`eyeviz.core.exact3d`.
Lit sets come out as per-ring runs, hence sorted without a sort of the indices. The fast
path lives in :mod:`eyeviz.core.healpix_fast`; this module holds the pair.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import ClassVar

import numpy as np

from eyeviz.core import exact3d, healpix, kernels, paper, tiny_caps
from eyeviz.core.bounds import MAX_NSIDE, check_nside
from eyeviz.core.geometry import _first_at, check_h_l, eye_x
from eyeviz.core.healpix_fast import (
    _EPS,
    FALLBACK_COUNTS,
    MAX_LIT,
    _lit_runs_fast,
    _ring_info_tables,
    _ring_tables,
)
from eyeviz.core.lit_views import LitSetViews

__all__ = ["EyePair3D", "lit_csr_eye", "validate_balls", "MAX_NSIDE", "MAX_LIT", "FALLBACK_COUNTS"]

_BLOCK = 512  # balls per block of the fast path at nside 64 (more at smaller nside)


def _block(n: int) -> int:
    """Balls per block: about _BLOCK * 64 / nside (the (ball, ring) pairs and boundary
    cells per ball grow like nside), within [256, 2048] (measured best at 16, 64, 180)."""
    return int(min(2048, max(256, _BLOCK * 64 // n)))


def validate_balls(x, y, z, g) -> tuple[np.ndarray, ...]:
    """Broadcast x, y, z, g to float64; refuse non-finite values and g <= 0."""
    try:
        arrs = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (x, y, z, g)))
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"x, y, z, g must be real numbers of broadcastable shapes: {exc}"
        ) from None
    for name, a in zip("xyzg", arrs, strict=True):
        bad = ~np.isfinite(a)
        if bad.any():
            raise ValueError(
                f"{name} has {int(bad.sum())} non-finite value(s) (NaN or inf){_first_at(bad)}"
            )
    bad = arrs[3] <= 0
    if bad.any():
        raise ValueError(
            f"g (feature radius) must be > 0: {int(bad.sum())} value(s) are not{_first_at(bad)}"
        )
    return tuple(arrs)


def _lit_runs(n: int, x, y, z, g, cx: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The lit facets of one eye for flat float64 arrays of balls, as runs: (lit facets
    per ball, run starts, run lengths), the runs sorted by ball, then start. The compiled
    kernel (:mod:`eyeviz.core.kernels.healpix_lit`) where it is in use, else the numpy
    reference :func:`_lit_runs_ref`."""
    if kernels.use(x.shape[0]):
        return _lit_runs_jit(n, x, y, z, g, cx)
    return _lit_runs_ref(n, x, y, z, g, cx)


def _lit_runs_jit(n: int, x, y, z, g, cx: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The kernel's runs; the balls it leaves to the exact branches go through
    :func:`_lit_runs_ref` and are merged in."""
    from eyeviz.core.kernels.healpix_lit import lit_runs_kernel

    sth, zr, unit = _ring_tables(n)
    first, nr, shifted, delta, o = _ring_info_tables(n)
    x, y, z, g = (np.ascontiguousarray(v, dtype=np.float64) for v in (x, y, z, g))
    status, per, st, ln, bl = lit_runs_kernel(
        n, x, y, z, g, float(cx), sth, zr, unit, first, nr, shifted, delta, o
    )
    kernels.mark_ready()
    return _merge_ref(n, x, y, z, g, cx, status, per, st, ln, bl)


def _merge_ref(n: int, x, y, z, g, cx: float, status, per, st, ln, bl):
    """The kernel's runs with the reference's for the balls it handed back (status 1)."""
    ref = np.flatnonzero(status)
    if ref.size == 0:
        return per, st, ln
    FALLBACK_COUNTS["kernel -> reference balls"] += ref.size
    p2, s2, l2 = _lit_runs_ref(n, x[ref], y[ref], z[ref], g[ref], cx)
    per[ref] = p2
    bl = np.concatenate([bl, ref[tiny_caps.run_balls(p2, l2)]])
    st = np.concatenate([st, s2])
    ln = np.concatenate([ln, l2])
    order = np.lexsort((st, bl))
    return per, st[order], ln[order]


def _lit_csr_jit(n: int, x, y, z, g, h: float) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
    """:meth:`EyePair3D.lit_csr` through the kernel: per eye the runs, then the indices
    written from them in compiled code (no temporaries per ball, no Python per block)."""
    out = _lit_csr_eye_jit(n, x, y, z, g, -h), _lit_csr_eye_jit(n, x, y, z, g, h)
    kernels.mark_ready()
    return out


def _lit_csr_eye_jit(n: int, x, y, z, g, cx: float) -> tuple[np.ndarray, np.ndarray]:
    """One eye's (at x = ``cx``) part of :func:`_lit_csr_jit` (flat float64 arrays)."""
    from eyeviz.core.kernels.healpix_lit import csr_kernel, empty_indices, lit_runs_kernel

    sth, zr, unit = _ring_tables(n)
    first, nr, shifted, delta, o = _ring_info_tables(n)
    # two compiled calls: lit_runs_kernel called from another kernel ran 1.6x slower
    # (measured), so the CSR is written by a kernel of its own
    status, per, st, ln, bl = lit_runs_kernel(
        n, x, y, z, g, cx, sth, zr, unit, first, nr, shifted, delta, o
    )
    if status.any():
        return _runs_to_csr(*_merge_ref(n, x, y, z, g, cx, status, per, st, ln, bl))
    idx = empty_indices(int(per.sum()))
    return csr_kernel(per, st, ln, idx), idx


def lit_csr_eye(pair: EyePair3D, eye: int, x, y, z, g) -> tuple[np.ndarray, np.ndarray]:
    """``pair.lit_csr(x, y, z, g)[eye]`` (finite flat float64 arrays, g > 0) without the
    other eye's lit sets: the same (indptr, indices) at half the cost (the spherical
    limit's inner and outer caps, limit3d_eye._Eye, need one eye each). Through the
    kernel where :func:`kernels.use`, else ``pair.lit_csr`` itself (the reference)."""
    if kernels.use(x.shape[0]):
        xf, yf, zf, gf = (np.ascontiguousarray(v, np.float64) for v in (x, y, z, g))
        out = _lit_csr_eye_jit(pair.nside, xf, yf, zf, gf, (-pair.h, pair.h)[eye])
        kernels.mark_ready()
        return out
    return pair.lit_csr(x, y, z, g)[eye]


def _one_ball(x, y, z, g) -> tuple[float, float, float, float] | None:
    """The four numbers of a call on one ball of Python or numpy float64 (or Python int)
    scalars, finite with g > 0 (a drag frame, a draw); None for anything else, which
    :func:`validate_balls` broadcasts, checks and names."""
    v4 = (x, y, z, g)
    if not all(isinstance(v, (float, int)) for v in v4):
        return None
    try:
        f = (float(x), float(y), float(z), float(g))
    except OverflowError:
        return None
    if math.isfinite(f[0] + f[1] + f[2] + f[3]) and f[3] > 0:
        return f
    return None


def _estimate_one(x: float, y: float, z: float, g: float, h: float, npix: int) -> float:
    """:meth:`EyePair3D.lit_csr`'s size estimate for one ball, in Python floats."""
    est = 0.0
    for cx in (-h, h):
        d = math.hypot(math.hypot(x - cx, y), z)
        q = g / d if d > 0 else math.inf
        est += (1.0 if q >= 1 else 0.5 * q * q) * npix
    return est


def _lit_runs_ref(n: int, x, y, z, g, cx: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_lit_runs` in numpy (the reference). Caps far below their direction's
    rounding error go through :mod:`eyeviz.core.tiny_caps`."""
    tiny = tiny_caps.tiny_mask(x, y, z, g, cx)
    if not tiny.any():
        return _lit_runs_fast(n, x, y, z, g, cx)
    parts = []
    for sel, fn in ((~tiny, _lit_runs_fast), (tiny, _lit_runs_tiny)):
        idx = np.flatnonzero(sel)
        per, st, ln = fn(n, x[idx], y[idx], z[idx], g[idx], cx)
        parts.append((idx[tiny_caps.run_balls(per, ln)], st, ln, idx, per))
    bl, st, ln = (np.concatenate([p[k] for p in parts]) for k in range(3))
    order = np.lexsort((st, bl))
    per_ball = np.zeros(x.shape[0], np.int64)
    for p in parts:
        per_ball[p[3]] = p[4]
    return per_ball, st[order], ln[order]


def _lit_runs_tiny(n: int, x, y, z, g, cx: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return tiny_caps.tiny_lit_runs(n, x, y, z, g, cx, _lit_runs_fast)


def _runs_to_csr(per_ball, st, ln) -> tuple[np.ndarray, np.ndarray]:
    """(indptr, indices) from runs (start, length) sorted by ball, then start."""
    nb = per_ball.size
    indptr = np.zeros(nb + 1, np.int64)
    np.cumsum(per_ball, out=indptr[1:])
    total = int(indptr[-1])
    # runs -> indices in one pass: steps of 1 inside a run, a jump at each run's start
    indices = np.ones(total, np.int64)
    if total:
        pos = np.cumsum(ln) - ln
        jump = st.copy()
        jump[1:] -= st[:-1] + ln[:-1] - 1
        indices[pos] = jump
        np.cumsum(indices, out=indices)
    return indptr, indices


def _lit_eye(n: int, x, y, z, g, cx: float) -> tuple[np.ndarray, np.ndarray]:
    """(indptr, indices) of the lit facets of one eye for flat float64 arrays of balls."""
    return _runs_to_csr(*_lit_runs(n, x, y, z, g, cx))


@dataclass(frozen=True)
class EyePair3D(LitSetViews):
    """Two spherical HEALPix eyes (docs/spherical.md; the paper's Section 8 goal).

    Parameters
    ----------
    h : distance from the origin to each eye centre (eyes 2h apart), h > l.
    l : eye radius, l > 0.
    nside : HEALPix resolution, an even integer in [2, MAX_NSIDE]; 12 nside^2 facets per
        eye, m = 4 nside of them on the equator (the planar eye EyePair(h, l, 4 nside)).
    """

    h: float = paper.H
    l: float = paper.L
    nside: int = paper.NSIDE
    #: the binocular fields Algorithm 1 draws in (eyeviz.dataset.algorithm1_3d.FIELDS),
    #: the default first: the tangent cones' wedge, or what touches neither eye
    binocular_fields: ClassVar[tuple[str, ...]] = ("wedge", "both-eyes")

    def __post_init__(self) -> None:
        h, l = check_h_l(self.h, self.l)
        n = check_nside(self.nside)
        object.__setattr__(self, "h", h)
        object.__setattr__(self, "l", l)
        object.__setattr__(self, "nside", n)

    @property
    def npix(self) -> int:
        """Facets per eye, 12 nside^2."""
        return 12 * self.nside * self.nside

    @property
    def m(self) -> int:
        """Facets on the equator, 4 nside (the planar eye's m)."""
        return 4 * self.nside

    @property
    def psi(self) -> float:
        """Half-angle of each eye's tangent cone from the origin, asin(l / h) (Eq. 15)."""
        return math.asin(self.l / self.h)

    @property
    def centers(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """((-h, 0, 0), (h, 0, 0)): eye A (left) and eye B (right)."""
        return ((-self.h, 0.0, 0.0), (self.h, 0.0, 0.0))

    # --- the eye-model seam (eyeviz.core.eyes.EyeModel) --------------------------------
    @property
    def kind(self) -> str:
        """``"spherical"``: HEALPix eyes in space (docs/spherical.md)."""
        return "spherical"

    @property
    def dims(self) -> int:
        """Coordinates of a feature centre: 3 (x, y, z)."""
        return 3

    @property
    def facet_counts(self) -> tuple[int, int]:
        """Facets of eye A and of eye B: (12 nside^2, 12 nside^2)."""
        return (self.npix, self.npix)

    @property
    def design(self) -> dict[str, float | int]:
        """{"h", "l", "nside"}: what a scene, a data set or an estimator must agree on."""
        return {"h": self.h, "l": self.l, "nside": self.nside}

    def _cx(self, eye: str) -> float:
        return eye_x(self.h, eye)

    def facet(self, x, y, z, eye: str) -> np.ndarray:
        """RING index of the direction from the eye centre to the point (Prop. 1 in 3D).

        Exact on the float inputs: a point within rounding of a cell edge is decided by
        ang2pix in mpmath with the floors snapped (:func:`exact3d.ang2pix_snap`); the eye
        centre itself is given the facet of the north pole (0), as atan2(0, 0) = 0.
        """
        cx = self._cx(eye)
        xa, ya, za, _ = validate_balls(x, y, z, 1.0)
        shape = xa.shape
        xa, ya, za = xa.ravel(), ya.ravel(), za.ravel()
        n = self.nside
        dx = xa - cx
        out = healpix.vec2pix_ring(n, dx, ya, za)
        # a point is near a boundary when a cap of the rounding radius about it is not
        # inside one cell: the lit set of a tiny ball says so, exactly
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            r = np.sqrt(dx * dx + ya * ya + za * za)
        ok = (r > 1e-150) & (r < 1e150)
        i = np.flatnonzero(ok)
        # the lit set of a ball of angular radius 1e-8 about the point is exact: one cell
        # means the point's direction lies inside it
        ip, idx = _lit_eye(n, xa[i], ya[i], za[i], 1e-8 * r[i], cx)
        one = np.diff(ip) == 1
        out[i[one]] = idx[ip[:-1][one]]
        todo = i[~one]
        todo = np.concatenate([todo, np.flatnonzero(~ok)])
        import mpmath

        for j in todo:
            X = Fraction(float(xa[j])) - Fraction(cx)
            Y, Z = Fraction(float(ya[j])), Fraction(float(za[j]))
            if X == 0 and Y == 0 and Z == 0:
                out[j] = 0
                continue
            prec = 200 + 2 * max(
                abs(v.numerator).bit_length() + v.denominator.bit_length() for v in (X, Y, Z)
            )
            with mpmath.workprec(prec):
                v = tuple(mpmath.mpf(q.numerator) / q.denominator for q in (X, Y, Z))
                out[j] = exact3d.ang2pix_snap(n, v, mpmath.ldexp(1, -prec // 2))
        return out.reshape(shape)

    def lit_csr(self, x, y, z, g) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
        """Per eye (A, B): (indptr, indices) of the lit facets, CSR over the flattened
        balls; indices sorted int64 RING indices per row (the 3D Proposition 2)."""
        one = _one_ball(x, y, z, g)
        if one is not None and kernels.use(1):
            # one ball: no broadcasting, estimate in Python floats, straight to the kernel
            est = _estimate_one(*one, self.h, self.npix)
            if est <= MAX_LIT:
                xf, yf, zf, gf = (np.array((v,)) for v in one)
                return _lit_csr_jit(self.nside, xf, yf, zf, gf, self.h)
        xa, ya, za, ga = validate_balls(x, y, z, g)
        xf, yf, zf, gf = (np.ascontiguousarray(a).reshape(-1) for a in (xa, ya, za, ga))
        nb, n = xf.shape[0], self.nside
        est = 0.0
        with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
            for cx in (-self.h, self.h):
                q = gf / np.hypot(np.hypot(xf - cx, yf), zf)
                est += float(np.where(q >= 1, 1.0, 0.5 * q * q).sum()) * self.npix
        if est > MAX_LIT:
            raise ValueError(
                f"the lit sets would hold about {est:.3g} facets (more than {MAX_LIT}): "
                "use fewer or smaller balls per call, or a smaller nside"
            )
        if kernels.use(nb):
            return _lit_csr_jit(n, xf, yf, zf, gf, self.h)
        out = []
        block = _block(n)
        for cx in (-self.h, self.h):
            # blocks of balls keep the temporaries in cache; the indices are written once,
            # from the runs of every block
            runs = [
                _lit_runs(n, xf[s:e], yf[s:e], zf[s:e], gf[s:e], cx)
                for s, e in ((s, min(nb, s + block)) for s in range(0, nb, block))
            ]
            if runs:
                cat = [np.concatenate(r) for r in zip(*runs, strict=True)]
                out.append(_runs_to_csr(*cat))
            else:
                out.append((np.zeros(1, np.int64), np.zeros(0, np.int64)))
        return out[0], out[1]

    def responses(self, x, y, z, g, kind: str | None = None):
        """Graded responses per eye (A, B): (indptr, indices, values), the lit sets of
        :meth:`lit_csr` with each lit cell's share of its area inside the ball's cap of
        directions from the eye centre (kind ``"cell"``, the only one; docs/responses.md)."""
        from eyeviz.core.responses import check_kind, healpix_values

        check_kind("spherical", kind)
        csr = self.lit_csr(x, y, z, g)  # validates the balls
        xa, ya, za, ga = validate_balls(x, y, z, g)
        balls = tuple(np.ascontiguousarray(a).reshape(-1) for a in (xa, ya, za, ga))
        out = []
        for (indptr, indices), cx in zip(csr, (-self.h, self.h), strict=True):
            vals = healpix_values(self.nside, cx, balls, indptr, indices)
            out.append((indptr, indices, vals))
        return out[0], out[1]

    def in_bfv(self, x, y, z, g) -> np.ndarray:
        """The closed ball lies in the 3D binocular field of view (Prop. 4 generalised).

        In front (y >= g) and outside both open tangent cones from the origin to the eyes:
        w * sqrt(y^2 + z^2) - l * |x| >= g * h with w = sqrt(h^2 - l^2); on z = 0 this is
        Eq. 17 (docs/spherical.md derives it).
        """
        xa, ya, za, ga = validate_balls(x, y, z, g)
        shape = xa.shape
        xa, ya, za, ga = xa.ravel(), ya.ravel(), za.ravel(), ga.ravel()
        h, l = self.h, self.l
        with np.errstate(over="ignore", invalid="ignore", under="ignore"):
            w = math.sqrt((h - l) * (h + l))
            b = np.hypot(ya, za)
            lhs = w * b
            rhs = l * np.abs(xa) + ga * h
            tol = 16 * _EPS * (lhs + rhs)
            near = (np.abs(lhs - rhs) <= tol) | ~np.isfinite(lhs + rhs)
            near |= ~(lhs + rhs >= 2.0**-900) & (ya >= ga)
        out = (ya >= ga) & (lhs >= rhs)
        for i in np.flatnonzero(near & (ya >= ga)):
            X, Y, Z, G = (Fraction(float(v[i])) for v in (xa, ya, za, ga))
            H, L = Fraction(h), Fraction(l)
            # w b >= l|x| + g h  <=>  (h^2 - l^2)(y^2 + z^2) >= (l|x| + g h)^2, both >= 0
            out[i] = (H * H - L * L) * (Y * Y + Z * Z) >= (L * abs(X) + G * H) ** 2
        return out.reshape(shape)

    def overlaps_eye(self, x, y, z, g) -> tuple[np.ndarray, np.ndarray]:
        """Per eye: the closed ball meets the closed eye ball of radius l."""
        xa, ya, za, ga = validate_balls(x, y, z, g)
        shape = xa.shape
        xa, ya, za, ga = xa.ravel(), ya.ravel(), za.ravel(), ga.ravel()
        res = []
        for cx in (-self.h, self.h):
            with np.errstate(over="ignore", invalid="ignore", under="ignore"):
                dx = xa - cx
                d2 = dx * dx + ya * ya + za * za
                s = ga + self.l
                rhs = s * s
                tot = d2 + rhs
                near = np.abs(d2 - rhs) <= 16 * _EPS * tot + 8 * _EPS * (np.abs(xa) + self.h) * s
                near |= ~(tot >= 2.0**-900) | ~np.isfinite(tot)
            out = d2 <= rhs
            for i in np.flatnonzero(near):
                X = Fraction(float(xa[i])) - Fraction(cx)
                Y, Z = Fraction(float(ya[i])), Fraction(float(za[i]))
                S = Fraction(float(ga[i])) + Fraction(self.l)
                out[i] = X * X + Y * Y + Z * Z <= S * S
            res.append(out.reshape(shape))
        return res[0], res[1]
