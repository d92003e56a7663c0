"""The certified decision of :mod:`eyeviz.core.measured_fast` compiled with numba.

The same formulas and the same error bounds, one (ball, facet) pair at a time without
temporaries; numba compiles without fast-math, so every operation rounds as IEEE float64
does (a fused multiply-add, if LLVM chose one, only shrinks an error). The numpy function
``measured_fast._certified`` stays the reference: ``EYEVIZ_JIT=0`` runs it instead, and
the tests compare the two on the same pairs.
"""

from __future__ import annotations

import math
import os

import numpy as np

__all__ = ["enabled", "certified"]

_U = 2.0**-53
_LO, _HI = 2.0**-480, 2.0**480


_HAVE: list[bool] = []


def enabled() -> bool:
    """numba imports and EYEVIZ_JIT is not 0 (or false, no, off)."""
    if os.environ.get("EYEVIZ_JIT", "1").strip().lower() in ("0", "false", "no", "off"):
        return False
    if not _HAVE:
        try:
            import numba  # noqa: F401
        except ImportError:  # pragma: no cover - numba is a core dependency
            return False
        _HAVE.append(True)
    return True


def _kernel(cx, cy, cz, g, bi, fi, px, py, pz, ax, ay, az, nrm, cs, sn, exact_only, seen, sure):
    for k in range(bi.size):
        b, i = bi[k], fi[k]
        gb = g[b]
        vx, vy, vz = cx[b] - px[i], cy[b] - py[i], cz[b] - pz[i]
        mag = max(abs(vx), abs(vy), abs(vz))
        if mag == 0.0:  # c = p exactly: the lens is in the ball
            seen[k], sure[k] = True, True
            continue
        if not (_LO <= mag <= _HI and gb <= _HI) or exact_only[i]:
            seen[k], sure[k] = False, False
            continue
        a0, a1, a2 = ax[i], ay[i], az[i]
        v2 = vx * vx + vy * vy + vz * vz
        g2 = gb * gb
        da = v2 - g2
        ba = 16 * _U * (v2 + g2)
        s = vx * a0 + vy * a1 + vz * a2
        wx = vy * a2 - vz * a1
        wy = vz * a0 - vx * a2
        wz = vx * a1 - vy * a0
        q = math.sqrt(wx * wx + wy * wy + wz * wz)
        cc, ss, nn = cs[i], sn[i], nrm[i]
        vn = math.sqrt(v2) * (1 + 4 * _U) * nn
        e = s * cc + q * ss
        be = 32 * _U * vn
        m = q * cc - s * ss - gb * nn
        bm = 32 * _U * (vn + gb * nn)
        yes = da <= -ba or (e >= be and m <= -bm)
        no = da > ba and (e < -be or m > bm)
        seen[k], sure[k] = yes, yes or no


_COMPILED: list = []


def certified(t, balls, bi, fi) -> tuple[np.ndarray, np.ndarray]:
    """(seen, sure) of the pairs, as ``measured_fast._certified`` gives them."""
    if not _COMPILED:
        import numba

        _COMPILED.append(numba.njit(cache=True, nogil=True)(_kernel))
    seen = np.empty(bi.size, np.bool_)
    sure = np.empty(bi.size, np.bool_)
    _COMPILED[0](
        *balls, bi, fi, t.px, t.py, t.pz, t.ax, t.ay, t.az, t.nrm, t.cos, t.sin,
        t.exact_only, seen, sure,
    )  # fmt: skip
    return seen, sure
