"""What ``eyeviz report atlas`` measures on one measured eye pair (no figures, no files).

- :func:`field_counts`: the binocular field on a grid of directions. Small balls
  (angular radius ``ball_deg`` seen from the head's centre, ``Domain3D.origin``) on a
  longitude/latitude grid at distance r; per direction the number of facets of eye A
  and of eye B the ball lights (``pair.lit_csr``, exact). A direction is binocular when
  both counts are >= 2 (Definition 1 per eye); a ball that holds a lens is not in the
  field (``in_bfv``), so such directions are dropped too. :func:`field_extent` sums the
  binocular cells' solid angle.
- :func:`score`: the estimators on a test set drawn from the prior (Algorithm 1 on the
  domain, :mod:`eyeviz.core.animal_scale`), per row the absolute errors of r (relative),
  of the azimuth and the elevation (degrees), and the rule of thumb's relative error
  Z dphi_loc / b (dZ ~ Z^2 dphi / b, dphi_loc the mean interommatidial angle of the lit
  facets, :func:`local_spacing`).
- :func:`binned`: the means per distance bin with their standard errors
  (sample standard deviation / sqrt(count)).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

__all__ = [
    "BallScores",
    "binned",
    "field_counts",
    "field_extent",
    "local_spacing",
    "score",
]


def grid(step: float) -> tuple[np.ndarray, np.ndarray]:
    """(plot longitude, latitude) in degrees of a ``step``-degree grid's cell centres, 2D.
    The plot longitude is 90 - azimuth: 0 straight ahead, +90 to the right (eye B)."""
    lon = np.arange(-180 + step / 2, 180, step)
    lat = np.arange(-90 + step / 2, 90, step)
    return np.meshgrid(lon, lat)


def field_counts(
    pair, origin, r: float, lon: np.ndarray, lat: np.ndarray, ball_deg: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Facets of eye A and of eye B lit by the ball at distance ``r`` (mm) in each grid
    direction, and whether the ball is in the binocular field (``in_bfv``)."""
    o = np.asarray(origin, dtype=np.float64)
    az = np.radians(90.0 - lon.ravel())
    el = np.radians(lat.ravel())
    x = o[0] + r * np.cos(el) * np.cos(az)
    y = o[1] + r * np.cos(el) * np.sin(az)
    z = o[2] + r * np.sin(el)
    g = np.full(x.shape, r * math.sin(math.radians(ball_deg)))
    (pa, _), (pb, _) = pair.lit_csr(x, y, z, g)
    na, nb = np.diff(pa), np.diff(pb)
    both = (na >= 2) & (nb >= 2)
    if both.any():  # only candidates need the lens test
        sel = np.flatnonzero(both)
        both[sel] = pair.in_bfv(x[sel], y[sel], z[sel], g[sel])
    return na.reshape(lon.shape), nb.reshape(lon.shape), both.reshape(lon.shape)


def field_extent(
    both: np.ndarray, na: np.ndarray, nb: np.ndarray, lon: np.ndarray, lat: np.ndarray, step: float
) -> dict[str, float]:
    """The binocular cells' azimuth and elevation ranges (degrees, the cells' bounding
    box), solid angle (sr) and facets per eye (median, max) over them."""
    if not both.any():
        return {"cells": 0, "sr": 0.0}
    az = 90.0 - lon[both]
    cell = math.radians(step) ** 2 * np.cos(np.radians(lat[both]))
    return {
        "cells": int(both.sum()),
        "az_min": float(az.min() - step / 2),
        "az_max": float(az.max() + step / 2),
        "el_min": float(lat[both].min() - step / 2),
        "el_max": float(lat[both].max() + step / 2),
        "sr": float(cell.sum()),
        "a_median": float(np.median(na[both])),
        "a_max": int(na[both].max()),
        "b_median": float(np.median(nb[both])),
        "b_max": int(nb[both].max()),
    }


def facet_spacings(unit_axes: np.ndarray) -> np.ndarray:
    """Per facet, the angle (radians) between its axis and its nearest neighbour's."""
    from scipy.spatial import cKDTree

    u = np.asarray(unit_axes, dtype=np.float64)
    d, _ = cKDTree(u).query(u, k=2)
    return 2.0 * np.arcsin(np.clip(d[:, 1] / 2.0, 0.0, 1.0))


def local_spacing(pair, lit_a, lit_b) -> np.ndarray:
    """Per row, the mean interommatidial angle (radians) of the facets lit in both eyes:
    the local dphi of the rule of thumb."""
    total = np.zeros(len(lit_a[0]) - 1)
    count = np.zeros_like(total)
    for eye, (indptr, indices) in (("A", lit_a), ("B", lit_b)):
        sp = facet_spacings(pair.eye(eye).unit_axes)[np.asarray(indices, np.int64)]
        row = np.repeat(np.arange(total.size), np.diff(indptr))
        total += np.bincount(row, weights=sp, minlength=total.size)
        count += np.diff(indptr)
    with np.errstate(invalid="ignore", divide="ignore"):
        return total / count


@dataclass
class BallScores:
    """One estimator on one test set: per-row errors, or why it did not answer."""

    name: str
    status: str = ""
    rows: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    ape: np.ndarray = field(default_factory=lambda: np.zeros(0))  # |r^ - r| / r
    az_deg: np.ndarray = field(default_factory=lambda: np.zeros(0))
    el_deg: np.ndarray = field(default_factory=lambda: np.zeros(0))
    flagged: int = 0
    seconds: float = math.nan

    @property
    def ok(self) -> bool:
        return not self.status


def score(ds, names: list[str], limit_rows: int) -> list[BallScores]:
    """Each estimator of ``names`` (registry, for ``ds.domain``) on the rows of ``ds``;
    a name containing "limit" on at most ``limit_rows`` evenly spaced rows (the limit
    costs milliseconds per row); the others on every row. A name the registry cannot
    load for these eyes is kept with its one-line reason."""
    from eyeviz.estimators.base import take_rows
    from eyeviz.reports.common import try_load

    n = len(ds)
    subset = np.unique(np.linspace(0, n - 1, min(n, max(1, limit_rows))).astype(np.int64))
    out = []
    for name in names:
        res = BallScores(name)
        est, why = try_load(name, domain=ds.domain)
        if est is None:
            res.status = why
            out.append(res)
            continue
        rows = subset if "limit" in name else np.arange(n)
        la = take_rows(ds.indptr_a, ds.indices_a, rows)
        lb = take_rows(ds.indptr_b, ds.indices_b, rows)
        t0 = time.perf_counter()
        p = est.predict(la, lb)
        res.seconds = time.perf_counter() - t0
        valid = np.asarray(p.valid, bool)
        if not valid.all():
            res.status = f"no answer for {int((~valid).sum())} of {rows.size} rows"
            out.append(res)
            continue
        r, az, el = (np.asarray(v, np.float64) for v in (p[0], p[1], p[2]))
        res.rows = rows
        res.ape = np.abs(r - ds.r[rows]) / ds.r[rows]
        res.az_deg = np.degrees(np.abs(az - ds.azimuth[rows]))
        res.el_deg = np.degrees(np.abs(el - ds.elevation[rows]))
        res.flagged = int(np.asarray(getattr(p, "flagged", np.zeros(rows.size)), bool).sum())
        out.append(res)
    return out


def mean_se(v: np.ndarray) -> tuple[float, float]:
    """The mean of ``v`` and its standard error (NaN for fewer than 2 values)."""
    v = np.asarray(v, np.float64)
    if v.size == 0:
        return math.nan, math.nan
    if v.size == 1:
        return float(v[0]), math.nan
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(v.size))


def binned(
    res: BallScores, r: np.ndarray, rule: np.ndarray, edges: np.ndarray, b: float
) -> list[dict[str, float]]:
    """Per distance bin of ``edges`` (mm): count, the DD (mean |r^ - r| / r, %), the
    azimuth and elevation mean absolute errors (degrees), each with its standard error,
    and the rule of thumb's mean relative error Z dphi_loc / b (%) on the same rows.
    ``r``, ``rule``: per row of the test set; the estimator's rows are ``res.rows``."""
    rr = r[res.rows]
    out = []
    for i in range(edges.size - 1):
        lo, hi = float(edges[i]), float(edges[i + 1])
        last = i == edges.size - 2
        sel = (rr >= lo) & ((rr <= hi) if last else (rr < hi))
        dd, dd_se = mean_se(100.0 * res.ape[sel])
        az, az_se = mean_se(res.az_deg[sel])
        el, el_se = mean_se(res.el_deg[sel])
        rule_pct, _ = mean_se(100.0 * rule[res.rows][sel])
        out.append(
            {
                "lo_mm": lo,
                "hi_mm": hi,
                "lo_b": lo / b,
                "hi_b": hi / b,
                "r_mid_mm": float(np.mean(rr[sel])) if sel.any() else 0.5 * (lo + hi),
                "count": int(sel.sum()),
                "dd": dd,
                "dd_se": dd_se,
                "az": az,
                "az_se": az_se,
                "el": el,
                "el_se": el_se,
                "rule": rule_pct,
                "ratio": dd / rule_pct if rule_pct and rule_pct > 0 else math.nan,
            }
        )
    return out


def slope(x: np.ndarray, y: np.ndarray) -> float:
    """The least-squares exponent k of y ~ x^k over the positive finite pairs (NaN when
    fewer than 2): the rule of thumb says k = 1 for the relative error against Z."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    if ok.sum() < 2 or np.ptp(np.log(x[ok])) == 0:
        return math.nan
    return float(np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)[0])
