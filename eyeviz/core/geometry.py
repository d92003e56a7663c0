"""The paper's planar binocular compound-eye model, vectorised and exact.

Two circular eyes of radius l, each a ring of m ommatidia, centred at A = (-h, 0) (left)
and B = (h, 0) (right) (docs/conventions.md fixes the paper's Prop. 5 typo). Ommatidia are
numbered counter-clockwise from the +x direction; sector k is the half-open angle
[k*gamma, (k+1)*gamma) (Eq. 6, 8).

Every public method takes scalars or broadcastable arrays. Results equal exact real
arithmetic on the float inputs: a float64 fast path decides each element, and the
few whose answer lies within a proven rounding bound of a boundary are decided again by
:mod:`eyeviz.core.exact` (rational predicates, mpmath where those cannot apply).

This module imports numpy and the standard library only (no Qt, VTK or torch). It is
over 400 lines because EyePair's public methods and the block-wise fast path they share
(with its rounding bounds) are one unit; the exact predicates live in
:mod:`eyeviz.core.exact`, the bit expansion in :mod:`eyeviz.core.bits`.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from eyeviz.core import bits, exact, paper
from eyeviz.core.bounds import check_m

__all__ = ["EyePair", "intervals_to_bitmap", "validate_features", "validate_points"]

_U = 2.0**-53  # unit roundoff of float64
_TINY_SCALE = 2.0**-960  # above this, underflow in a product errs below 16 u of the scale
_CHUNK = 1 << 15  # elements per block: keeps the temporaries in cache
_Q_SAFE = 0.75  # g / r_E below this uses one scalar rounding bound per block
# A generous multiple of the forward error of the fast path, in units of u*m:
# atan2, asin, hypot, one subtraction and the scaling each add a few ulps; the asin
# term grows like 1/(1 - g/r_E) near grazing.
_TOL_BASE = 64.0
_TOL_GRAZE = 16.0


#: Diagnostics for the stability report: elements the fast path flagged near a boundary
#: ("flagged") and those of them decided by the exact predicates ("exact").
FALLBACK_COUNTS: Counter[str] = Counter()


def _first_index(mask: np.ndarray) -> int | tuple[int, ...]:
    idx = tuple(int(i) for i in np.argwhere(mask)[0])
    return idx[0] if len(idx) == 1 else idx


def _first_at(mask: np.ndarray) -> str:
    """'; first at index i' for an array of values; nothing for a single scalar."""
    return "" if mask.ndim == 0 else f"; first at index {_first_index(mask)}"


def validate_points(x, y) -> tuple[np.ndarray, np.ndarray]:
    """Broadcast x, y to float64 arrays; refuse NaN/inf with count and first index."""
    try:
        xa, ya = np.broadcast_arrays(
            np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
        )
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"coordinates must be real numbers of broadcastable shapes: {exc}"
        ) from None
    for name, a in (("x", xa), ("y", ya)):
        bad = ~np.isfinite(a)
        if bad.any():
            raise ValueError(
                f"{name} has {int(bad.sum())} non-finite value(s) (NaN or inf){_first_at(bad)}"
            )
    return xa, ya


def validate_features(x, y, g) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Broadcast x, y, g to float64; refuse non-finite values and g <= 0."""
    try:
        xa, ya, ga = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (x, y, g)))
    except (TypeError, ValueError) as exc:
        raise ValueError(f"x, y, g must be real numbers of broadcastable shapes: {exc}") from None
    for name, a in (("x", xa), ("y", ya), ("g", ga)):
        bad = ~np.isfinite(a)
        if bad.any():
            raise ValueError(
                f"{name} has {int(bad.sum())} non-finite value(s) (NaN or inf){_first_at(bad)}"
            )
    bad = ga <= 0
    if bad.any():
        raise ValueError(
            f"g (feature radius) must be > 0: {int(bad.sum())} value(s) are not{_first_at(bad)}"
        )
    return xa, ya, ga


def _short(value) -> str:
    """repr of a parameter for a one-line message, ints beyond float range shortened."""
    text = repr(value)
    return text if len(text) <= 40 else f"{text[:12]}...({len(text)} characters)"


def _check_param(name: str, value, rule: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        msg = f"{name} must be a finite real number ({rule}), got {_short(value)}"
        raise ValueError(msg) from None
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite ({rule}), got {value!r}")
    return v


def check_h_l(h, l) -> tuple[float, float]:
    """(h, l) as floats: finite, 0 < l < h (both eye models); ValueError naming them."""
    lf = _check_param("l", l, "0 < l < h")
    hf = _check_param("h", h, "0 < l < h")
    if lf <= 0:
        raise ValueError(f"l (eye radius) must be > 0, got {l!r}")
    if hf <= lf:
        raise ValueError(f"h must be > l (eyes may not touch the y-axis), got h={h!r}, l={l!r}")
    return hf, lf


def eye_x(h: float, eye: str) -> float:
    """x of eye A (-h) or B (+h): both eye models put the centres on the x-axis."""
    if eye == "A":
        return -h
    if eye == "B":
        return h
    raise ValueError(f"eye must be 'A' or 'B', got {eye!r}")


@dataclass(frozen=True)
class EyePair:
    """Two compound eyes of the paper's model (Section 3, Figure 2).

    Parameters
    ----------
    h : distance from the origin to each eye centre (eyes are 2h apart), h > l.
    l : eye radius (the ommatidium legs), l > 0.
    m : ommatidia per eye, an even integer in [4, MAX_M] (Eq. 6, 7; eyeviz.core.bounds).
    """

    h: float = paper.H
    l: float = paper.L
    m: int = paper.M
    _k: float = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        h, l = check_h_l(self.h, self.l)
        mi = check_m(self.m)  # the one bound of m (eyeviz.core.bounds.MAX_M)
        object.__setattr__(self, "h", h)
        object.__setattr__(self, "l", l)
        object.__setattr__(self, "m", mi)
        object.__setattr__(self, "_k", mi / (2.0 * math.pi))

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

    # --- the eye-model seam (eyeviz.core.eyes.EyeModel) --------------------------------
    @property
    def kind(self) -> str:
        """``"planar"``: rings of m ommatidia in the plane (Section 3)."""
        return "planar"

    @property
    def dims(self) -> int:
        """Coordinates of a feature centre: 2 (x, y)."""
        return 2

    @property
    def facet_counts(self) -> tuple[int, int]:
        """Ommatidia of eye A and of eye B: (m, m)."""
        return (self.m, self.m)

    @property
    def design(self) -> dict[str, float | int]:
        """{"h", "l", "m"}: what a scene, a data set or an estimator must agree on."""
        return {"h": self.h, "l": self.l, "m": self.m}

    def _cx(self, eye: str) -> float:
        return eye_x(self.h, eye)

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
        idx = np.flatnonzero(near & ~((dx == 0) & (ya == 0)))
        out[near & (dx == 0) & (ya == 0)] = 0
        if idx.size and tol < 0.25:  # boundaries at 30/45-degree multiples: vectorised
            n = out[idx] + (frac[idx] > 0.5)
            zero = np.zeros(idx.size)
            res = exact.ties_at_or_past(xa[idx], ya[idx], zero, cx, n, self.m, True)
            out[idx[res >= 0]] = (n - 1 + res)[res >= 0]
            idx = idx[res < 0]
        for i in idx:
            fl = exact.exact_floor_pair(float(xa[i]), float(ya[i]), 0.0, cx, self.m)
            assert fl is not None  # g = 0 and (x, y) is not the eye centre (excluded above)
            out[i] = fl[1]
        return np.mod(out, self.m).reshape(shape)

    # --- features ---------------------------------------------------------------------
    def _fast_intervals(self, x, y, g, refine: bool, outs) -> None:
        """Eq. 11 for both eyes, block by block, into ``outs`` = (LA, RA, LB, RB) int64.

        Per block: y*y once for both eyes, every temporary in a reused buffer, and the
        rounding bound checked by a few min/max reductions (r^2 in range, g/r_E <= 0.75,
        every fractional part of t at least ``tol0`` from an integer) instead of per-element
        masks. L and R go straight into the outputs; in a block that fails the check, only
        the elements a per-element mask flags (a tie, a graze, a huge m, an over/underflow)
        are handed to :meth:`_block`, the per-element path with the exact fallback.
        ``refine=False`` skips that fallback (benchmarks measure its cost with it).
        """
        n = x.shape[0]
        k, m = self._k, self.m
        tol0 = (_TOL_BASE + _TOL_GRAZE / (1 - _Q_SAFE)) * _U * m
        c = min(_CHUNK, max(n, 1))
        yy, dx, r2, q, pk, ak, tlo, thi = (np.empty(c) for _ in range(8))
        wrap = np.empty(c, np.int64)
        eyes = ((-self.h, outs[0], outs[1]), (self.h, outs[2], outs[3]))
        with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
            for s in range(0, n, c):
                e = min(n, s + c)
                b = e - s
                xs, ys, gs = x[s:e], y[s:e], g[s:e]
                yy_, dx_, r2_, q_, pk_, ak_, tlo_, thi_ = (
                    v[:b] for v in (yy, dx, r2, q, pk, ak, tlo, thi)
                )
                np.multiply(ys, ys, out=yy_)
                for cx, Lo, Ro in eyes:
                    np.subtract(xs, cx, out=dx_)
                    np.multiply(dx_, dx_, out=r2_)
                    r2_ += yy_
                    np.sqrt(r2_, out=q_)
                    np.divide(gs, q_, out=q_)
                    clean = r2_.min() >= 1e-290 and r2_.max() <= 1e300 and q_.max() <= _Q_SAFE
                    np.arctan2(ys, dx_, out=pk_)
                    pk_ *= k
                    np.arcsin(q_, out=ak_)  # NaN where q > 1: such blocks are not clean
                    ak_ *= k
                    np.subtract(pk_, ak_, out=tlo_)
                    np.add(pk_, ak_, out=thi_)
                    np.floor(tlo_, out=pk_)  # floor(t_lo)
                    np.floor(thi_, out=ak_)  # floor(t_hi)
                    tlo_ -= pk_  # fractional parts in [0, 1)
                    thi_ -= ak_
                    clean = clean and (
                        min(tlo_.min(), thi_.min()) >= tol0
                        and max(tlo_.max(), thi_.max()) <= 1 - tol0
                    )
                    L, R = Lo[s:e], Ro[s:e]
                    # phi in (-pi, pi] and alpha <= pi/2: floor(t_lo) > -m, one wrap at most
                    L[...] = pk_
                    ak_ -= pk_  # R - L
                    np.right_shift(L, 63, out=wrap[:b])
                    wrap[:b] &= m
                    L += wrap[:b]
                    R[...] = ak_
                    R += L
                    if not clean:  # the few elements near a boundary, out of range or grazing
                        near = (tlo_ < tol0) | (tlo_ > 1 - tol0) | (thi_ < tol0)
                        near |= thi_ > 1 - tol0
                        near |= ~((r2_ >= 1e-290) & (r2_ <= 1e300) & (q_ <= _Q_SAFE))
                        idx = np.flatnonzero(near)
                        L[idx], R[idx] = self._slow_block(xs[idx], ys[idx], gs[idx], cx, refine)

    def _slow_block(self, xs, ys, gs, cx, refine) -> tuple[np.ndarray, np.ndarray]:
        """(L, R) of one eye by the per-element path with its exact fallback (the few
        elements of a block that the block check could not clear)."""
        b = xs.shape[0]
        lo, hi, whole = np.empty(b, np.int64), np.empty(b, np.int64), np.zeros(b, bool)
        tol0 = (_TOL_BASE + _TOL_GRAZE / (1 - _Q_SAFE)) * _U * self.m
        self._block(xs, ys, gs, cx, refine, slice(None), self._k, tol0, lo, hi, whole)
        FALLBACK_COUNTS["slow elements"] += b
        return self._normalised(lo, hi, whole)

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
        """Re-decide flagged elements: a per-element rounding bound, then exact.

        An endpoint within the bound of an integer n has floor n or n - 1; when beta_n is a
        multiple of 30 or 45 degrees (every tie of the ground line, an eye's vertical line
        and the 30/60-degree ties) :func:`exact.ties_at_or_past` decides which, vectorised
        with floating-point expansions. Only what that cannot decide reaches mpmath.
        """
        qi = q[idx]
        with np.errstate(divide="ignore", invalid="ignore"):
            tol = (_TOL_BASE + _TOL_GRAZE / np.maximum(1 - qi, 0)) * _U * self.m
        outside = qi < 1 - 8 * _U * 4
        clear_inside = qi > 1 + 8 * _U * 4
        clear_outside = outside & (np.maximum(np.abs(c_lo[idx]), np.abs(c_hi[idx])) <= 0.5 - tol)
        whole[idx[clear_inside]] = True
        rest = ~(clear_inside | clear_outside)
        todo, tol = idx[rest], tol[rest]
        FALLBACK_COUNTS["flagged"] += idx.size
        if not todo.size:
            return
        valid = outside[rest] & (tol < 0.25)
        scalar = ~valid
        parts = []
        for c_arr, f_arr, upper in ((c_lo, lo, False), (c_hi, hi, True)):
            c = c_arr[todo]
            need = valid & (np.abs(c) > 0.5 - tol)
            j = np.flatnonzero(need)
            n = f_arr[todo[j]] + (c[j] > 0)
            parts.append((j, n, upper, f_arr))
        js = np.concatenate([p[0] for p in parts])
        if js.size:
            el = todo[js]
            ns = np.concatenate([p[1] for p in parts])
            ups = np.concatenate([np.full(p[0].size, p[2]) for p in parts])
            res = exact.ties_at_or_past(xs[el], ys[el], gs[el], cx, ns, self.m, ups)
            scalar[js[res < 0]] = True
            k = 0
            for j, n, _upper, f_arr in parts:
                r = res[k : k + j.size]
                k += j.size
                ok = r >= 0
                f_arr[todo[j[ok]]] = n[ok] - 1 + r[ok]
        todo_s = todo[scalar]
        FALLBACK_COUNTS["exact"] += todo.size
        FALLBACK_COUNTS["ties"] += todo.size - todo_s.size
        FALLBACK_COUNTS["mpmath"] += todo_s.size
        for j in todo_s:
            fl = exact.exact_floor_pair(float(xs[j]), float(ys[j]), float(gs[j]), cx, self.m)
            if fl is None:
                whole[j] = True
            else:
                lo[j], hi[j] = fl

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
        outs = tuple(np.empty(xf.shape[0], np.int64) for _ in range(4))
        self._fast_intervals(xf, yf, gf, refine, outs)
        la, ra, lb, rb = (o.reshape(shape) for o in outs)
        return la, ra, lb, rb

    def responses(self, x, y, g, kind: str | None = None):
        """Graded responses per eye (A, B): (indptr, indices, values) over the flattened
        features, indices the lit ommatidia of :meth:`intervals` (sorted), values the
        share of each sector's angle the disc covers (kind ``"cell"``, the only one;
        docs/responses.md)."""
        from eyeviz.core.responses import check_kind, planar_responses

        check_kind("planar", kind)
        xa, ya, ga = validate_features(x, y, g)
        flat = (np.ascontiguousarray(v).reshape(-1) for v in (xa, ya, ga))
        return planar_responses(self, *flat)

    def bitmaps(self, x, y, g) -> tuple[np.ndarray, np.ndarray]:
        """Whole-eye bitmaps (omega_a, omega_b), bool of shape (..., m)."""
        LA, RA, LB, RB = self.intervals(x, y, g)
        return intervals_to_bitmap(LA, RA, self.m), intervals_to_bitmap(LB, RB, self.m)

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
        with np.errstate(over="ignore", invalid="ignore", under="ignore"):
            w = float(np.sqrt(np.float64(h - l) * (h + l)))
            wy, lx, gh = w * ya, l * xa, ga * h
            right = wy - lx - gh
            left = wy + lx - gh
            scale = np.abs(wy) + np.abs(lx) + np.abs(gh)
            tol = 16 * _U * scale
            near = (np.abs(right) <= tol) | (np.abs(left) <= tol)
        out = (right >= 0) & (left >= 0)
        # products that overflow (inf, NaN) or fall where underflow is no longer relative
        near |= ~(scale >= _TINY_SCALE) | ~np.isfinite(scale)
        if not 2.0**-400 < w < 2.0**400:  # h^2 - l^2 itself over- or underflowed
            near[:] = True
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
            with np.errstate(over="ignore", invalid="ignore", under="ignore"):
                dx = xa - cx
                d2 = dx * dx + ya * ya
                s = ga + self.l
                rhs = s * s
                tot = d2 + rhs
                near = np.abs(d2 - rhs) <= 16 * _U * tot
            out = d2 <= rhs
            # squares that overflow (inf, NaN) or underflow: decided exactly, as intervals does
            near |= ~(tot >= _TINY_SCALE) | ~np.isfinite(tot)
            for i in np.flatnonzero(near):
                out[i] = exact.exact_overlaps(float(xa[i]), float(ya[i]), float(ga[i]), cx, self.l)
            res.append(out.reshape(shape))
        return res[0], res[1]


def intervals_to_bitmap(L, R, m: int, width: int | None = None) -> np.ndarray:
    """Bool bitmap (..., width) of ommatidia 0..width-1 lit by {k mod m : L <= k <= R}.

    ``width`` defaults to m (the whole eye); m // 2 gives the paper's Omega (Section 4).
    One memcpy-sized window per row (:func:`eyeviz.core.bits.bool_bitmaps`).
    """
    return bits.bool_bitmaps(L, R, m, width)
