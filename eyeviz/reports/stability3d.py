"""The spherical eyes' part of ``eyeviz report stability``: lit sets against a reference.

For every case class of :mod:`eyeviz.reference.stability_cases3d`, the lit sets of both eyes
from (a) astropy-healpix's ``cone_search_lonlat`` (float64, not built to be exact: it is
what one would reach for) and (b) the eyeviz core (:class:`eyeviz.core.geometry3d.EyePair3D`)
are compared with the independent high-precision reference
(:mod:`eyeviz.reference.healpix_reference`). A ball counts as a difference when either eye's
lit set differs. The core's own diagnostics say how many facets needed its slower stages.
"""

from __future__ import annotations

import csv
import io
import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from eyeviz.files.atomic import atomic_output

__all__ = ["METHODS3D", "Row3D", "measure3d", "write3d"]

METHODS3D = ("astropy-healpix cone search", "eyeviz core")
REFERENCE = "reference (mpmath)"


@dataclass
class Row3D:
    case: str
    description: str
    n: int
    nside: int
    diffs: dict[str, int]
    seconds_per_ball: dict[str, float]
    tested: int  # facets the vertex/edge stage could not clear at once
    sampled: int  # facets that needed edge sampling
    exact: int  # facets decided in mpmath


def _astropy_lit(nside: int, x, y, z, g, cx: float) -> list[np.ndarray]:
    """Each ball's lit set by astropy-healpix's cone search (radius asin(g/|d|), the whole
    sphere when the eye centre is inside the ball)."""
    import astropy.units as u
    from astropy_healpix import HEALPix

    hp = HEALPix(nside, order="ring")
    out = []
    for xi, yi, zi, gi in zip(x, y, z, g, strict=True):
        dx, dy, dz = xi - cx, yi, zi
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        if d <= gi:
            out.append(np.arange(12 * nside * nside))
            continue
        lon = math.atan2(dy, dx) % (2 * math.pi)
        lat = math.asin(max(-1.0, min(1.0, dz / d)))
        rad = math.asin(min(1.0, gi / d))
        out.append(np.sort(hp.cone_search_lonlat(lon * u.rad, lat * u.rad, rad * u.rad)))
    return out


def measure_case3d(cs) -> Row3D:
    """Differences from the reference and time per ball of each method on one class."""
    from eyeviz.core import geometry3d
    from eyeviz.reference.healpix_reference import reference_lit

    e, n = cs.eyes, int(cs.x.size)
    t = time.perf_counter()
    balls = [(float(cs.x[i]), float(cs.y[i]), float(cs.z[i]), float(cs.g[i])) for i in range(n)]
    ref = [[reference_lit(e.nside, *b, cx) for b in balls] for cx in (-e.h, e.h)]
    times = {REFERENCE: (time.perf_counter() - t) / n}
    geometry3d.FALLBACK_COUNTS.clear()
    t = time.perf_counter()
    (pa, ia), (pb, ib) = e.lit_csr(cs.x, cs.y, cs.z, cs.g)
    times["eyeviz core"] = (time.perf_counter() - t) / n
    counts = dict(geometry3d.FALLBACK_COUNTS)
    core = [
        [ia[pa[i] : pa[i + 1]] for i in range(n)],
        [ib[pb[i] : pb[i + 1]] for i in range(n)],
    ]
    t = time.perf_counter()
    ap = [_astropy_lit(e.nside, cs.x, cs.y, cs.z, cs.g, cx) for cx in (-e.h, e.h)]
    times["astropy-healpix cone search"] = (time.perf_counter() - t) / n
    diffs = {}
    for name, sets in (("eyeviz core", core), ("astropy-healpix cone search", ap)):
        wrong = [any(not np.array_equal(sets[k][i], ref[k][i]) for k in range(2)) for i in range(n)]
        diffs[name] = int(sum(wrong))
    return Row3D(
        cs.name,
        cs.description,
        n,
        e.nside,
        diffs,
        times,
        counts.get("tested", 0),
        counts.get("sampled", 0),
        counts.get("exact", 0),
    )


def measure3d(n: int = 12, seed: int = 0, progress=None) -> list[Row3D]:
    """Run every 3D case class (``n`` balls each); one :class:`Row3D` per class."""
    from eyeviz.reference import stability_cases3d

    rows = []
    for i, name in enumerate(stability_cases3d.CLASSES):
        rows.append(measure_case3d(stability_cases3d.make(name, n, seed + 100 + i)))
        if progress:
            progress(name)
    return rows


def _markdown(rows: list[Row3D]) -> str:
    out = io.StringIO()
    out.write("# Numerical stability of the spherical eyes\n\n")
    out.write(
        "Balls whose lit facets (either eye) differ from the independent mpmath reference,\n"
        "and the time per ball. astropy-healpix's cone search is float64 and not meant to\n"
        "be exact; the eyeviz core certifies each facet (float64 with rounding and\n"
        "curvature bounds; 'tested', 'sampled' and 'mpmath' count the facets that needed\n"
        "its slower stages).\n\n"
    )
    timed = (*METHODS3D, REFERENCE)
    out.write("| case | n | nside | " + " | ".join(f"{m} diffs" for m in METHODS3D))
    out.write(" | tested | sampled | mpmath | " + " | ".join(f"{m} µs" for m in timed) + " |\n")
    out.write("|" + "---|" * (3 + len(METHODS3D) + 3 + len(timed)) + "\n")
    for r in rows:
        cells = [r.case, str(r.n), str(r.nside)]
        cells += [f"{r.diffs[m]} ({100 * r.diffs[m] / r.n:.1f} %)" for m in METHODS3D]
        cells += [str(r.tested), str(r.sampled), str(r.exact)]
        cells += [f"{1e6 * r.seconds_per_ball[m]:.3g}" for m in timed]
        out.write("| " + " | ".join(cells) + " |\n")
    out.write("\nCase classes:\n\n")
    for r in rows:
        out.write(f"- **{r.case}**: {r.description}\n")
    out.write("\n![stability of the spherical eyes](stability3d.png)\n")
    return out.getvalue()


def _plot(rows: list[Row3D], path: Path) -> None:
    from matplotlib.figure import Figure

    colors = {"astropy-healpix cone search": "#E69F00", "eyeviz core": "#0072B2"}
    fig = Figure(figsize=(7.5, 3.6), layout="constrained")
    ax = fig.add_subplot()
    y = np.arange(len(rows))
    h = 0.38
    for j, m in enumerate(METHODS3D):
        frac = [100 * r.diffs[m] / r.n for r in rows]
        ax.barh(y + (j - 0.5) * h, frac, h, label=m, color=colors[m])
        for yi, f in zip(y, frac, strict=True):
            if f == 0:
                ax.text(0.5, yi + (j - 0.5) * h, "0", va="center", fontsize=7, color=colors[m])
    ax.set_yticks(y, [f"{r.case} (nside {r.nside})" for r in rows], fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("balls with a wrong lit set (%)")
    ax.set_title("spherical eyes: lit sets against the mpmath reference", fontsize=10)
    ax.legend(loc="lower right", fontsize=8)
    fig.savefig(path, dpi=130)


def write3d(rows: list[Row3D], outdir: Path) -> None:
    """stability3d.md, .csv and .png in ``outdir``, each written atomically."""
    outdir.mkdir(parents=True, exist_ok=True)
    with atomic_output(outdir / "stability3d.md") as tmp:
        tmp.write_text(_markdown(rows))
    with atomic_output(outdir / "stability3d.csv") as tmp, open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        timed = (*METHODS3D, REFERENCE)
        w.writerow(
            ["case", "n", "nside", *(f"diffs {m}" for m in METHODS3D)]
            + ["tested", "sampled", "mpmath", *(f"s/ball {m}" for m in timed)]
        )
        for r in rows:
            w.writerow(
                [r.case, r.n, r.nside, *(r.diffs[m] for m in METHODS3D)]
                + [r.tested, r.sampled, r.exact, *(r.seconds_per_ball[m] for m in timed)]
            )
    with atomic_output(outdir / "stability3d.png") as tmp:
        _plot(rows, tmp)
