"""The geometry core's float64 fast path as it was before issue 14 (report-only).

Kept callable so the stability report and ``scripts/bench_geometry.py`` can show the old
figures beside the new ones, measured in the same run. Results are identical to
:class:`eyeviz.core.geometry.EyePair`; only the speed differs: a per-element tolerance
mask on every block, and every flagged element decided one at a time by
:func:`eyeviz.core.exact.exact_floor_pair` (mpmath). Nothing outside the reports, the
benchmark and the tests imports this module. (About 300 lines of the old code, unchanged.)
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from eyeviz.core import exact
from eyeviz.core.geometry import EyePair, validate_features, validate_points

__all__ = ["LegacyEyePair", "legacy_intervals_to_bitmap"]

_U = 2.0**-53  # unit roundoff of float64
_CHUNK = 1 << 15  # elements per block: keeps the temporaries in cache
_Q_SAFE = 0.75  # g / r_E below this uses one scalar rounding bound per block
# A generous multiple of the forward error of the fast path, in units of u*m:
# atan2, asin, hypot, one subtraction and the scaling each add a few ulps; the asin
# term grows like 1/(1 - g/r_E) near grazing.
_TOL_BASE = 64.0
_TOL_GRAZE = 16.0

#: Diagnostics for the stability report: elements the fast path flagged near a boundary
#: ("flagged") and those of them decided by the exact predicates ("exact").
FALLBACK_COUNTS: Counter[str] = Counter()  # the legacy path counts here, not in core


@dataclass(frozen=True)
class LegacyEyePair:
    """Two compound eyes of the paper's model (Section 3, Figure 2).

    Parameters
    ----------
    h : distance from the origin to each eye centre (eyes are 2h apart), h > l.
    l : eye radius (the ommatidium legs), l > 0.
    m : ommatidia per eye, an even integer >= 4 (Eq. 6, 7).
    """

    h: float = 40.0
    l: float = 20.0
    m: int = 720
    _k: float = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        eyes = EyePair(self.h, self.l, self.m)  # the same validation as the core
        object.__setattr__(self, "_k", eyes.m / (2.0 * math.pi))

    @classmethod
    def of(cls, eyes: EyePair) -> LegacyEyePair:
        """The legacy implementation for the same eye design."""
        return cls(eyes.h, eyes.l, eyes.m)

    # --- constants of the model -------------------------------------------------------
    @property
    def gamma(self) -> float:
        """Ommatidium angle of view, gamma = 2*pi/m (Eq. 6)."""
        return 2.0 * math.pi / self.m

    @property
    def psi(self) -> float:
        """Angle between the right BFV tangent and the x-axis, psi = asin(l/h) (Eq. 15)."""
        return math.asin(self.l / self.h)

    @property
    def theta(self) -> float:
        """BFV angle, theta = pi - 2*asin(l/h) (Eq. 16)."""
        return math.pi - 2.0 * self.psi

    @property
    def centers(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """((-h, 0), (h, 0)): the centres of eye A (left) and eye B (right)."""
        return ((-self.h, 0.0), (self.h, 0.0))

    def _cx(self, eye: str) -> float:
        if eye == "A":
            return -self.h
        if eye == "B":
            return self.h
        raise ValueError(f"eye must be 'A' or 'B', got {eye!r}")

    # --- points -----------------------------------------------------------------------
    def eye_polar(self, x, y, eye: str) -> tuple[np.ndarray, np.ndarray]:
        """Polar coordinates (r_E, phi_E) about an eye centre, phi_E in [0, 2*pi).

        The atan2 form of Eq. 22-25 (docs/conventions.md: arccos loses precision near 0, pi).
        """
        cx = self._cx(eye)
        xa, ya = validate_points(x, y)
        dx = xa - cx
        r = np.hypot(dx, ya)
        phi = np.arctan2(ya, dx)
        phi = np.where(phi < 0, phi + 2 * math.pi, phi)
        phi = np.minimum(phi, np.nextafter(2 * math.pi, 0))
        return r, phi

    def ommatidium(self, x, y, eye: str) -> np.ndarray:
        """Index 0..m-1 of the ommatidium whose sector holds the point (Prop. 1, Eq. 8).

        A point exactly on a boundary belongs to the sector starting there; the eye centre
        itself is given ommatidium 0.
        """
        cx = self._cx(eye)
        xa, ya = validate_points(x, y)
        shape = xa.shape
        xa, ya = xa.ravel(), ya.ravel()
        dx = xa - cx
        t = np.arctan2(ya, dx) * self._k
        k = np.floor(t)
        frac = t - k
        tol = _TOL_BASE * _U * self.m
        near = (frac < tol) | (frac > 1 - tol)
        out = k.astype(np.int64)
        for i in np.flatnonzero(near):
            if dx[i] == 0 and ya[i] == 0:
                out[i] = 0
                continue
            pair = exact.exact_floor_pair(float(xa[i]), float(ya[i]), 0.0, cx, self.m)
            assert pair is not None  # a point (g = 0) off the eye centre is never around it
            out[i] = pair[1]
        return np.mod(out, self.m).reshape(shape)

    # --- features ---------------------------------------------------------------------
    def _eye_floors(
        self, x, y, g, cx: float, refine: bool = True
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Raw (floor(t_lo), floor(t_hi), whole) of Eq. 11 for one eye on 1-D arrays.

        ``refine=False`` skips the exact fallback (benchmarks measure its cost with it).
        """
        n = x.shape[0]
        lo_out = np.empty(n, np.int64)
        hi_out = np.empty(n, np.int64)
        whole = np.zeros(n, bool)
        k = self._k
        tol0 = (_TOL_BASE + _TOL_GRAZE / (1 - _Q_SAFE)) * _U * self.m
        for s in range(0, n, _CHUNK):
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                self._block(
                    x, y, g, cx, refine, slice(s, s + _CHUNK), k, tol0, lo_out, hi_out, whole
                )
        return lo_out, hi_out, whole

    def _block(self, x, y, g, cx, refine, sl, k, tol0, lo_out, hi_out, whole) -> None:
        """Fast path of Eq. 11 on one cache-sized block; flags elements near a boundary."""
        xs, ys, gs = x[sl], y[sl], g[sl]
        dx = xs - cx
        r2 = dx * dx
        r2 += ys * ys
        r = np.sqrt(r2)
        pk = np.arctan2(ys, dx)
        pk *= k
        q = gs / r
        # outside this range the squares may over/underflow: leave those to the exact path
        q[~((r2 >= 1e-290) & (r2 <= 1e300))] = np.nan
        ak = np.arcsin(np.minimum(q, 1.0))
        ak *= k
        t_lo = pk - ak
        t_hi = pk + ak
        f_lo = np.floor(t_lo)
        f_hi = np.floor(t_hi)
        t_lo -= f_lo
        t_hi -= f_hi
        t_lo -= 0.5
        t_hi -= 0.5
        near = np.maximum(np.abs(t_lo), np.abs(t_hi)) > 0.5 - tol0
        near |= ~(q <= _Q_SAFE)  # also NaN
        lo_out[sl] = f_lo
        hi_out[sl] = f_hi
        if not refine:
            whole[sl] = q >= 1
        idx = np.flatnonzero(near)
        if refine and idx.size:
            self._refine(xs, ys, gs, q, t_lo, t_hi, idx, cx, lo_out[sl], hi_out[sl], whole[sl])

    def _refine(self, xs, ys, gs, q, c_lo, c_hi, idx, cx, lo, hi, whole) -> None:
        """Re-decide flagged elements: a per-element rounding bound, then exact."""
        qi = q[idx]
        with np.errstate(divide="ignore"):
            tol = (_TOL_BASE + _TOL_GRAZE / np.maximum(1 - qi, 0)) * _U * self.m
        clear_inside = qi > 1 + 8 * _U * 4
        clear_outside = (qi < 1 - 8 * _U * 4) & (
            np.maximum(np.abs(c_lo[idx]), np.abs(c_hi[idx])) <= 0.5 - tol
        )
        whole[idx[clear_inside]] = True
        todo = idx[~(clear_inside | clear_outside)]
        FALLBACK_COUNTS["flagged"] += idx.size
        FALLBACK_COUNTS["exact"] += todo.size
        for j in todo:
            res = exact.exact_floor_pair(float(xs[j]), float(ys[j]), float(gs[j]), cx, self.m)
            if res is None:
                whole[j] = True
            else:
                lo[j], hi[j] = res

    def _normalised(self, f_lo, f_hi, whole) -> tuple[np.ndarray, np.ndarray]:
        m = self.m
        # floors come from phi in (-pi, pi] and alpha <= pi/2, so f_lo > -m: one wrap at most
        L = f_lo + m * (f_lo < 0)
        R = f_hi - f_lo + L
        L[whole] = 0
        R[whole] = m - 1
        return L, R

    def intervals(self, x, y, g) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Lit intervals (LA, RA, LB, RB) of both eyes (Prop. 2, Eq. 11).

        Eye E lights {k mod m : L_E <= k <= R_E} with 0 <= L_E < m and L_E <= R_E < L_E + m;
        (0, m-1) when the eye centre lies in the closed feature disc.
        """
        return self._intervals(x, y, g)

    def _intervals(
        self, x, y, g, refine: bool = True
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        xa, ya, ga = validate_features(x, y, g)
        shape = xa.shape
        xf, yf, gf = (np.ascontiguousarray(a).reshape(-1) for a in (xa, ya, ga))
        out = []
        for cx in (-self.h, self.h):
            L, R = self._normalised(*self._eye_floors(xf, yf, gf, cx, refine))
            out += [L.reshape(shape), R.reshape(shape)]
        return out[0], out[1], out[2], out[3]

    def bitmaps(self, x, y, g) -> tuple[np.ndarray, np.ndarray]:
        """Whole-eye bitmaps (omega_a, omega_b), bool of shape (..., m)."""
        LA, RA, LB, RB = self.intervals(x, y, g)
        return (
            legacy_intervals_to_bitmap(LA, RA, self.m),
            legacy_intervals_to_bitmap(LB, RB, self.m),
        )

    def visible(self, x, y, g) -> tuple[np.ndarray, np.ndarray]:
        """Definition 1 per eye: seen by at least two ommatidia (vis_a, vis_b)."""
        LA, RA, LB, RB = self.intervals(x, y, g)
        return RA > LA, RB > LB

    def in_bfv(self, x, y, g) -> np.ndarray:
        """The closed disc lies entirely in the binocular field of view (Prop. 4, Eq. 17)."""
        xa, ya, ga = validate_features(x, y, g)
        shape = xa.shape
        xa, ya, ga = xa.ravel(), ya.ravel(), ga.ravel()
        h, l = self.h, self.l
        w = math.sqrt((h - l) * (h + l))
        wy, lx, gh = w * ya, l * xa, ga * h
        right = wy - lx - gh
        left = wy + lx - gh
        scale = np.abs(wy) + np.abs(lx) + np.abs(gh)
        tol = 16 * _U * scale
        out = (right >= 0) & (left >= 0)
        near = (np.abs(right) <= tol) | (np.abs(left) <= tol)
        for i in np.flatnonzero(near):
            out[i] = exact.exact_in_bfv(float(xa[i]), float(ya[i]), float(ga[i]), h, l)
        return out.reshape(shape)

    def overlaps_eye(self, x, y, g) -> tuple[np.ndarray, np.ndarray]:
        """Per eye: the closed feature disc meets the closed eye disc of radius l."""
        xa, ya, ga = validate_features(x, y, g)
        shape = xa.shape
        xa, ya, ga = xa.ravel(), ya.ravel(), ga.ravel()
        res = []
        for cx in (-self.h, self.h):
            dx = xa - cx
            d2 = dx * dx + ya * ya
            s = ga + self.l
            rhs = s * s
            out = d2 <= rhs
            near = np.abs(d2 - rhs) <= 16 * _U * (d2 + rhs)
            for i in np.flatnonzero(near):
                out[i] = exact.exact_overlaps(float(xa[i]), float(ya[i]), float(ga[i]), cx, self.l)
            res.append(out.reshape(shape))
        return res[0], res[1]


def legacy_intervals_to_bitmap(L, R, m: int, width: int | None = None) -> np.ndarray:
    """Bool bitmap (..., width) of ommatidia 0..width-1 lit by {k mod m : L <= k <= R}.

    ``width`` defaults to m (the whole eye); m // 2 gives the paper's Omega (Section 4).
    Built in row blocks so the temporaries stay in cache: ``k - L`` read as unsigned is
    at most ``R - L`` exactly on the lit ommatidia of a run that does not wrap past m - 1;
    the few runs that wrap add ``k <= R - m``.
    """
    L, R = np.broadcast_arrays(np.asarray(L, dtype=np.int64), np.asarray(R, dtype=np.int64))
    width = m if width is None else width
    out = np.empty(L.shape + (width,), dtype=bool)
    flat = out.reshape(-1, width)
    sdt = np.int16 if m < 2**15 else np.int32 if m < 2**31 else np.int64
    udt = np.dtype(sdt).str.replace("i", "u")
    k = np.arange(width, dtype=sdt)
    Lf = L.reshape(-1, 1).astype(sdt)
    Cf = (R - L).reshape(-1, 1).astype(udt)
    rows = max(1, (1 << 19) // max(width, 1))
    for s in range(0, flat.shape[0], rows):
        d = k - Lf[s : s + rows]
        np.less_equal(d.view(udt), Cf[s : s + rows], out=flat[s : s + rows])
    wrap = np.flatnonzero(R.reshape(-1) >= m)
    if wrap.size:
        flat[wrap] |= k <= (R.reshape(-1)[wrap, None] - m)
    return out
