"""The certified float64 fast path of the measured eyes' seen rule (docs/measured.md).

The rule (:mod:`eyeviz.core.measured_exact`): with v = c - p, s = v . a, q = |v x a|,
N = |a|, C = cos(dr / 2), S = sin(dr / 2),

    seen  <=>  |v|^2 <= g^2  or  (E = s C + q S >= 0  and  M = q C - s S - g N <= 0).

Each of the three quantities is computed in float64 with a rigorous bound of its error;
a test decides only when the computed value is beyond its bound, and the few (ball,
facet) pairs that stay undecided, or whose inputs leave the range where the bound holds,
go to the exact fallback. The bounds (u = 2^-53, magnitudes of the computed values;
each is about half the constant used, which covers the final subtraction's rounding too):

* v = fl(c - p): one rounding per component, |v^ - v| <= u |v^| (componentwise);
* |v|^2: 3 roundings of the sum of squares plus 2u from v: <= 5.1 u |v^|^2; g^2: u g^2;
  used: 16 u (|v^|^2 + g^2);
* s: <= 4.1 u sum |v^_k a_k| <= 4.1 u |v^| N;  q = |w|, w = v x a: each w_k within
  3.1 u (|v_j a_l| + |v_l a_j|), the norm of that vector <= sqrt(2) |v| N, the norm's own
  rounding 2.6 u q: |q^ - q| <= 7.1 u |v^| N;
* C, S are the float nearest the values mpmath computes at 80 bits (relative error u);
  E: 4.1 + 1 + 7.1 + 1 + 2 (products and sum, |s| C + q S <= |v| N) = 15.2 u |v| N;
  used: 32 u |v|^ N^ with |v|^, N^ upper bounds of |v^|, N;
* M: as E, plus g N^ (N^ within 2.6 u, product u) and the subtraction:
  used 32 u N^ (|v|^ + g).

The axes are first scaled by a power of two (exact) so that the largest component is in
[1, 2); a facet whose scaling would not be exact (components 2^1000 apart) is always
decided exactly. The bounds assume no overflow and no harmful underflow: a pair is left
to the exact path unless the largest |v_k| lies in [2^-480, 2^480] and g <= 2^480 (the
squares and products of v then are normal numbers; g^2 and g N may underflow, by at most
2^-1074, far below the bounds, which are >= 2^-1009 there); v^ = 0 means c = p exactly
(IEEE subtraction), a lens in the ball: seen.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mpmath
import numpy as np

from eyeviz.core import kernels
from eyeviz.core.measured_exact import seen_exact

__all__ = ["EyeTables", "eye_tables", "decide_pairs", "use_jit", "FALLBACK_COUNTS"]

_U = 2.0**-53
_LO, _HI = 2.0**-480, 2.0**480

#: Diagnostics: pairs decided by the fast path ("fast") and by the exact path ("exact").
FALLBACK_COUNTS: dict[str, int] = {"fast": 0, "exact": 0}


@dataclass(frozen=True)
class EyeTables:
    """Per-facet arrays of one eye, in the layout the fast path reads (columns)."""

    px: np.ndarray
    py: np.ndarray
    pz: np.ndarray
    ax: np.ndarray  # axes scaled by a power of two: max |component| in [1, 2)
    ay: np.ndarray
    az: np.ndarray
    nrm: np.ndarray  # upper bound of |scaled axis|
    cos: np.ndarray  # cos(dr / 2), correctly rounded
    sin: np.ndarray
    exact_only: np.ndarray  # bool: the scaling was not exact; decide exactly
    positions: np.ndarray  # the inputs as given (the exact path reads them)
    axes: np.ndarray
    acceptance: np.ndarray

    def columns(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The lens positions' x, y, z columns."""
        return self.px, self.py, self.pz


def _cos_sin(acceptance: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """cos and sin of dr / 2 (dr / 2 exactly), evaluated in mpmath at 80 bits and rounded
    to float64 once: relative error <= u (1 + 2^-27) whatever the platform's libm does."""
    uniq, inv = np.unique(acceptance, return_inverse=True)
    cs = np.empty((uniq.size, 2))
    with mpmath.workprec(80):
        for k, dr in enumerate(uniq):
            al = mpmath.mpf(float(dr)) / 2
            cs[k] = float(mpmath.cos(al)), float(mpmath.sin(al))
    return cs[inv, 0], cs[inv, 1]


def eye_tables(positions: np.ndarray, axes: np.ndarray, acceptance: np.ndarray) -> EyeTables:
    """The fast path's tables for one eye (validated arrays of :class:`MeasuredEye`)."""
    big = np.abs(axes).max(axis=1)
    _, ex = np.frexp(big)
    scaled = np.ldexp(axes, (1 - ex)[:, None])
    exact_only = ~(np.ldexp(scaled, (ex - 1)[:, None]) == axes).all(axis=1)
    nrm = np.sqrt((scaled * scaled).sum(axis=1)) * (1 + 8 * _U)
    c, s = _cos_sin(acceptance)
    px, py, pz, ax, ay, az = (np.ascontiguousarray(a) for a in (*positions.T, *scaled.T))
    return EyeTables(px, py, pz, ax, ay, az, nrm, c, s, exact_only, positions, axes, acceptance)


def _certified(t: EyeTables, cx, cy, cz, g, fi) -> tuple[np.ndarray, np.ndarray]:
    """(seen, sure) for the pairs (ball values cx, cy, cz, g gathered per pair, facet
    indices fi): ``seen`` is the answer where ``sure``; elsewhere the exact path decides."""
    vx, vy, vz = cx - t.px[fi], cy - t.py[fi], cz - t.pz[fi]
    ax, ay, az = t.ax[fi], t.ay[fi], t.az[fi]
    v2 = vx * vx + vy * vy + vz * vz
    g2 = g * g
    da = v2 - g2
    ba = 16 * _U * (v2 + g2)
    s = vx * ax + vy * ay + vz * az
    wx = vy * az - vz * ay
    wy = vz * ax - vx * az
    wz = vx * ay - vy * ax
    q = np.sqrt(wx * wx + wy * wy + wz * wz)
    cc, ss, nn = t.cos[fi], t.sin[fi], t.nrm[fi]
    vn = np.sqrt(v2) * (1 + 4 * _U) * nn
    e = s * cc + q * ss
    be = 32 * _U * vn
    m = q * cc - s * ss - g * nn
    bm = 32 * _U * (vn + g * nn)
    in_lens = da <= -ba
    edge_ok = (e >= be) & (m <= -bm)
    seen = in_lens | edge_ok
    unseen = (da > ba) & ((e < -be) | (m > bm))
    mag = np.maximum(np.maximum(np.abs(vx), np.abs(vy)), np.abs(vz))
    ok = (mag >= _LO) & (mag <= _HI) & (g <= _HI) & ~t.exact_only[fi]
    zero = mag == 0  # v^ = 0 only when c = p exactly (no underflow in a subtraction)
    sure = (ok & (seen | unseen)) | zero
    return seen | zero, sure


_RAN: list[bool] = []


def use_jit(work: int) -> bool:
    """Run the compiled path for a call of ``work`` balls: the core's policy
    (:func:`eyeviz.core.kernels.use`: EYEVIZ_JIT, numba, cold kernels only for large calls
    or once warm), and always once the measured kernels have run in this process."""
    if not kernels.enabled():
        return False
    return bool(_RAN) or kernels.use(work)


def _certified_jit(t: EyeTables, balls, bi, fi) -> tuple[np.ndarray, np.ndarray]:
    """(seen, sure) of the pairs from the compiled twin of :func:`_certified`."""
    from eyeviz.core.kernels.measured_lit import certified_kernel

    seen = np.empty(bi.size, np.bool_)
    sure = np.empty(bi.size, np.bool_)
    cx, cy, cz, g = balls
    certified_kernel(
        cx, cy, cz, g, bi, fi, t.px, t.py, t.pz, t.ax, t.ay, t.az, t.nrm, t.cos, t.sin,
        t.exact_only, seen, sure,
    )  # fmt: skip
    if not _RAN:
        _RAN.append(True)
    return seen, sure


def decide_pairs(
    t: EyeTables, balls: tuple[np.ndarray, ...], bi, fi, *, jit: bool = False
) -> np.ndarray:
    """Whether facet fi[k] sees ball bi[k] (balls: flat float64 cx, cy, cz, g), exactly:
    the certified float64 test (compiled with ``jit``, else numpy), then the exact
    path for the pairs it leaves."""
    if jit:
        seen, sure = _certified_jit(t, balls, bi, fi)
        cx, cy, cz, g = balls[0], balls[1], balls[2], balls[3]
        bk = bi
    else:
        cx, cy, cz, g = (b[bi] for b in balls)
        bk = np.arange(bi.size)
        with np.errstate(all="ignore"):
            seen, sure = _certified(t, cx, cy, cz, g, fi)
    todo = np.flatnonzero(~sure)
    FALLBACK_COUNTS["fast"] += int(bi.size - todo.size)
    FALLBACK_COUNTS["exact"] += int(todo.size)
    for k in todo.tolist():
        i, j = int(fi[k]), int(bk[k])
        seen[k] = seen_exact(
            (float(cx[j]), float(cy[j]), float(cz[j])),
            float(g[j]),
            t.positions[i].tolist(),
            t.axes[i].tolist(),
            float(t.acceptance[i]),
        )
    return seen


def lens_bound(positions: np.ndarray, centre: np.ndarray) -> float:
    """An upper bound of max |p_i - centre| (float rounding covered)."""
    with np.errstate(all="ignore"):
        diff = positions - centre
        big = float(np.abs(diff).max())
        if big == 0 or not math.isfinite(big):
            return big
        d = float(np.sqrt(((diff / big) ** 2).sum(axis=1)).max()) * big
    return d * (1 + 1e-12) + math.ulp(float(np.abs(centre).max())) + 5e-324
