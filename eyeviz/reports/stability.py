"""``eyeviz report stability -o DIR``: the geometry's error against run time, per eye model.

The report has one part per eye model (:data:`PARTS`), each measuring its model's case
classes (:mod:`eyeviz.reference.stability_cases`) against its model's own reference and
writing its own files:

- **planar** (``stability.md``, ``.csv``, ``.png``): three implementations of Eq. 11 and
  22-25 are compared with the mpmath reference (:mod:`eyeviz.reference.digits80`, 80
  digits): (a) the paper's formulas taken literally in float64, (b) the same in float32,
  (c) the eyeviz core. A feature counts as a difference when either eye's bitmap differs.
  The core as it was before issue 14 (:mod:`eyeviz.reference.legacy_fastpath`) is timed
  in the same run, so its cost and the speed-up stand beside the new figures.
- **spherical** (``stability3d.*``, ``--n3d`` balls per class): the lit sets of both eyes
  from (a) astropy-healpix's ``cone_search_lonlat`` (float64, not built to be exact: it
  is what one would reach for) and (b) the eyeviz core
  (:class:`eyeviz.core.geometry3d.EyePair3D`) are compared with the independent
  high-precision reference (:mod:`eyeviz.reference.healpix_reference`). A ball counts as
  a difference when either eye's lit set differs. The core's own diagnostics say how
  many facets needed its slower stages.
"""

from __future__ import annotations

import argparse
import csv
import io
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from eyeviz.core.validation import check_int
from eyeviz.files.atomic import atomic_output

HELP = "numerical stability of the geometry against an 80-digit reference"

METHODS = ("paper float64", "paper float32", "eyeviz core")
OLD = "eyeviz core, before issue 14"
TIMED = (*METHODS, OLD, "reference (mpmath)")
#: Most features per case class (-n): each needs an 80-digit mpmath reference.
MAX_N = 100_000
#: Most balls per case class of the spherical eyes (--n3d): their reference visits every facet.
MAX_N3D = 10_000


@dataclass
class Row:
    case: str
    description: str
    n: int
    m: int
    diffs: dict[str, int]
    seconds_per_feature: dict[str, float]
    exact_fallbacks: int
    exact_ties: int = 0  # decided by the vectorised expansion predicates
    exact_mpmath: int = 0  # decided by mpmath


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-o", "--output", required=True, type=Path, help="output directory")
    parser.add_argument("-n", type=int, default=2000, help="features per case class (default 2000)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--n3d",
        type=int,
        default=12,
        help="balls per case class of the spherical eyes (default 12; 0 leaves them out: "
        "their reference visits every facet, about 0.3-1.5 s a ball)",
    )


def _timed(fn, repeats: int = 3) -> tuple[object, float]:
    best, out = float("inf"), None
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return out, best


def measure_case(cs) -> Row:
    """Differences from the reference and time per feature of each method on one class."""
    from eyeviz.core import geometry
    from eyeviz.reference.digits80 import reference_intervals
    from eyeviz.reference.legacy_fastpath import LegacyEyePair
    from eyeviz.reference.paper_formulas import paper_intervals

    e, x, y, g = cs.eyes, cs.x, cs.y, cs.g
    ref, t_ref = _timed(lambda: np.array(reference_intervals(e, x, y, g)), 1)
    runs = {
        "paper float64": lambda: paper_intervals(e.h, e.m, x, y, g, np.float64),
        "paper float32": lambda: paper_intervals(e.h, e.m, x, y, g, np.float32),
        "eyeviz core": lambda: e.intervals(x, y, g),
    }
    diffs, times = {}, {"reference (mpmath)": t_ref / x.size}
    for method, fn in runs.items():
        out, t = _timed(fn)
        diffs[method] = int((np.array(out) != ref).any(axis=0).sum())
        times[method] = t / x.size
    old = LegacyEyePair.of(e)
    out, t = _timed(lambda: old.intervals(x, y, g), 1)  # slow on ties: once
    if (np.array(out) != ref).any():
        raise AssertionError(f"the legacy core differs from the reference on {cs.name}")
    times[OLD] = t / x.size
    geometry.FALLBACK_COUNTS.clear()
    e.intervals(x, y, g)
    c = geometry.FALLBACK_COUNTS
    return Row(
        cs.name, cs.description, int(x.size), e.m, diffs, times, c["exact"], c["ties"], c["mpmath"]
    )


def measure(n: int = 2000, seed: int = 0, progress=None) -> list[Row]:
    """Run every case class; returns one :class:`Row` per class."""
    from eyeviz.reference import stability_cases

    return _measure_classes(stability_cases.CLASSES, "planar", measure_case, n, seed, progress)


def _measure_classes(classes, kind: str, measure_one, n: int, seed: int, progress) -> list:
    """``measure_one`` of each case class of ``kind`` (class i drawn with ``seed + i``)."""
    from eyeviz.reference import stability_cases

    rows = []
    for i, name in enumerate(classes):
        rows.append(measure_one(stability_cases.make(name, n, seed + i, kind)))
        if progress:
            progress(name)
    return rows


def _markdown(rows: list[Row]) -> str:
    out = io.StringIO()
    out.write("# Numerical stability of the geometry\n\n")
    out.write(
        "Features whose bitmaps (either eye) differ from an 80-digit mpmath reference, and the\n"
        "time per feature. (a) and (b) are the paper's Eq. 11 and 22-25 taken literally\n"
        "(arccos form, valid for 0 <= phi <= pi only, so features below the x-axis come out\n"
        "mirrored); (c) is eyeviz's core: float64 with an exact fallback on the elements near a\n"
        "boundary ('exact' column: how many of them per class; 'ties' of those were decided\n"
        "vectorised with floating-point expansions, 'mpmath' one at a time). The core as it\n"
        "was before issue 14 is timed in the same run: its cost per feature, and the new\n"
        "core's speed-up over it, stand in the last columns.\n\n"
    )
    out.write("| case | n | m | " + " | ".join(f"{m} diffs" for m in METHODS))
    out.write(" | exact | ties | mpmath | " + " | ".join(f"{m} µs" for m in TIMED))
    out.write(" | speed-up vs before | core / paper regime |\n")
    out.write("|" + "---|" * (3 + len(METHODS) + 3 + len(TIMED) + 2) + "\n")
    paper = rows[0].seconds_per_feature["eyeviz core"] if rows else 1.0
    for r in rows:
        t = r.seconds_per_feature
        cells = [r.case, str(r.n), str(r.m)]
        cells += [f"{r.diffs[m]} ({100 * r.diffs[m] / r.n:.1f} %)" for m in METHODS]
        cells += [str(r.exact_fallbacks), str(r.exact_ties), str(r.exact_mpmath)]
        cells += [f"{1e6 * t[m]:.3g}" for m in TIMED]
        cells += [f"{t[OLD] / t['eyeviz core']:.3g}x", f"{t['eyeviz core'] / paper:.3g}x"]
        out.write("| " + " | ".join(cells) + " |\n")
    out.write("\nCase classes:\n\n")
    for r in rows:
        out.write(f"- **{r.case}**: {r.description}\n")
    return out.getvalue()


def _plot(rows: list[Row], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colors = {
        "paper float64": "#E69F00",
        "paper float32": "#CC79A7",
        "eyeviz core": "#0072B2",
        OLD: "#56B4E9",
    }
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    y = np.arange(len(rows))
    h = 0.27
    for j, m in enumerate(METHODS):
        frac = [100 * r.diffs[m] / r.n for r in rows]
        ax1.barh(y + (j - 1) * h, frac, h, label=m, color=colors[m])
        for yi, f in zip(y, frac, strict=True):
            if f == 0:
                ax1.text(0.3, yi + (j - 1) * h, "0", va="center", fontsize=7, color=colors[m])
    ax1.set_yticks(y, [r.case for r in rows])
    ax1.invert_yaxis()
    ax1.set_xlabel("features with a wrong bitmap (%)")
    ax1.set_title("error against the 80-digit reference")
    ax1.legend(loc="lower right", fontsize=8)
    for m in TIMED:
        t = [1e9 * r.seconds_per_feature[m] for r in rows]
        err = [max(100 * r.diffs.get(m, 0) / r.n, 0.01) for r in rows]
        ax2.scatter(t, err, label=m, color=colors.get(m, "#555555"), s=30)
    ax2.set_xscale("log")
    ax2.set_yscale("log")
    ax2.set_xlabel("run time per feature (ns, log)")
    ax2.set_ylabel("wrong bitmaps (%, 0 drawn at 0.01)")
    ax2.set_title("error against run time (one point per case class)")
    ax2.legend(fontsize=8)
    ax2.grid(True, which="both", alpha=0.3)
    fig.savefig(path, dpi=130)
    plt.close(fig)


def _write_atomic(path: Path, writer) -> None:
    with atomic_output(path) as tmp:
        writer(tmp)


def write(rows: list[Row], outdir: Path) -> None:
    outdir.mkdir(parents=True, exist_ok=True)
    _write_atomic(outdir / "stability.md", lambda p: p.write_text(_markdown(rows)))

    def csv_writer(p: Path) -> None:
        with open(p, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(
                ["case", "n", "m", *(f"diffs {m}" for m in METHODS), "exact fallbacks"]
                + ["exact ties", "exact mpmath"]
                + [f"s/feature {m}" for m in TIMED]
                + ["speed-up vs before"]
            )
            for r in rows:
                t = r.seconds_per_feature
                w.writerow(
                    [r.case, r.n, r.m, *(r.diffs[m] for m in METHODS), r.exact_fallbacks]
                    + [r.exact_ties, r.exact_mpmath]
                    + [t[m] for m in TIMED]
                    + [t[OLD] / t["eyeviz core"]]
                )

    _write_atomic(outdir / "stability.csv", csv_writer)
    _write_atomic(outdir / "stability.png", lambda p: _plot(rows, p))


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
    from eyeviz.reference import stability_cases

    classes = stability_cases.CLASSES3D
    return _measure_classes(classes, "spherical", measure_case3d, n, seed + 100, progress)


def _markdown3d(rows: list[Row3D]) -> str:
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


def _plot3d(rows: list[Row3D], path: Path) -> None:
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
        tmp.write_text(_markdown3d(rows))
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
        _plot3d(rows, tmp)


@dataclass(frozen=True)
class Part:
    """One eye model's part of the report: its case classes, measured and written."""

    kind: str
    #: the progress bar's name and the noun of the summary line
    title: str
    what: str
    #: the files' stem (``<stem>.md``, ``.csv``, ``.png``)
    stem: str
    classes: Callable[[], int]
    measure: Callable[..., list[Any]]
    write: Callable[[list[Any], Path], None]


def _classes(kind: str) -> Callable[[], int]:
    def count() -> int:
        from eyeviz.reference import stability_cases

        return len(stability_cases.KINDS[kind])

    return count


#: The report's parts, in order; ``--n3d 0`` leaves out the spherical one.
PARTS: tuple[Part, ...] = (
    Part("planar", "stability", "", "stability", _classes("planar"), measure, write),
    Part("spherical", "stability 3D", " (spherical eyes)", "stability3d",
         _classes("spherical"), measure3d, write3d),
)  # fmt: skip


def run(args: argparse.Namespace) -> int:
    check_int("-n", args.n, ge=1, le=MAX_N)
    check_int("--n3d", args.n3d, ge=0, le=MAX_N3D)
    from tqdm import tqdm

    core_diffs = 0
    for part, n in zip(PARTS, (args.n, args.n3d), strict=True):
        if not n:
            continue
        with tqdm(total=part.classes(), desc=part.title, unit="class") as bar:
            rows = part.measure(n, args.seed, progress=lambda _name: bar.update())
        part.write(rows, args.output)
        diffs = sum(r.diffs["eyeviz core"] for r in rows)
        print(
            f"wrote {args.output / (part.stem + '.md')} (.csv, .png); eyeviz core differences"
            f"{part.what}: {diffs}"
        )
        core_diffs += diffs
    return 0 if core_diffs == 0 else 1
