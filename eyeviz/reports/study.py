"""``eyeviz report study STUDY.csv -o DIR``: figures of the eye-design study (issue 11).

The study table (``eyeviz study``, read by :mod:`eyeviz.reports.study_table`) holds the
information limit's AD and DD error (MAPE, Eq. 34) per eye design (h, l, m; Table 3) and
distance bin. The paper's open question (Section 8) is how accuracy depends on h, l and
m. This report draws, in PDF, SVG and PNG (house style of :mod:`eyeviz.render.mpl.style`,
Okabe-Ito colours, text >= 7 pt at print size):

``study_dd``  DD limit (MAPE %) against distance, one panel per h, one curve per m;
``study_ad``  the same for AD;
``study_heatmap``  DD MAPE in the distance bin holding ``--at`` over (h, m), values in
    the cells;
``study_law``  the law relative DD error = C * gamma * r / (2h) (gamma = 2 pi / m, Prop. 1):
    every measured bin against gamma r / (2h) on log-log axes with the fitted C.

The report has one part per eye model (:data:`PARTS`): a planar table gets the figures
above, a 3D study table (``eyeviz study --nside``; :func:`_write_spherical`) the 3D ones.

For each h the panels and the heatmap use the paper's l (``--l``, default 20) when the
table has it, else the l nearest to it (stated in the label). The paper's design
(h = 40, l = 20, m = 720) is marked in every figure. ``summary.json`` holds the fitted
constant and its spread, ``summary.csv`` the table behind the heatmap, ``study.md`` the
answer to "which m and h give a DD error below --target % at --at".

The fit of C: least squares in log space with the slope fixed at 1, i.e.
log C = mean(log y - log x), over bins with at least :data:`MIN_COUNT` test elements,
x = gamma r_mid / (2h) <= ``--law-max`` (beyond it the error saturates: the prior's range
bounds it) and not the first or last bin of a design (there the prior's bounds r_min,
r_max truncate the posterior and lower the error). Its spread is the standard deviation
of the log residuals (a factor exp(sd)); a free log-log slope is reported beside it.

The 3D table (:mod:`eyeviz.study.table`) holds, per design of the spherical eyes (h, l,
nside) and estimator, the DD and AD error (MAPE, Eq. 34) and the elevation and azimuth
error (mean absolute, degrees) overall, per distance bin and per elevation bin. Its report
answers the 3D study's questions:

1. How does accuracy depend on h, l, nside, distance and elevation?
   ``study3d_design``: DD MAPE and elevation error (overall) against h, l and nside.
2. Does the planar law, relative DD error = C gamma r / (2h), carry over?
   ``study3d_dd``: DD MAPE against r, a panel per h, a curve per nside, each with its law
   line C gamma r / (2h) (gamma = 2 pi / (4 nside), the equatorial facet width; C fitted
   in 3D with the slope fixed at 1, as the planar report does); ``study3d_law``: every
   distance bin against gamma r / (2h) on log-log axes. ``summary3d.json`` adds a free
   power law, relative DD = K gamma^a r^b h^c l^d, fitted by least squares in log space:
   the planar law is a = b = 1, c = -1, d = 0.
3. How does the elevation error behave (the baseline is horizontal, so each eye alone sees
   the elevation)? ``study3d_elevation``: elevation and azimuth error against elevation
   and against r, a curve per nside, at the paper's h and l (or the nearest).

Its fitted bins: :mod:`eyeviz.reports.study_law`'s docstring. ``--band W`` first merges
the table's 500-wide distance bins into bands W wide
(:func:`~eyeviz.reports.study_design.merge_bins`; 3D only: a planar table is refused with
it), so that each holds enough balls for that error; the figures, the fit and the summary
then use the bands. The estimator is named in every figure's title: only the limit is the
accuracy limit (``limit3d``); any other (``analytic3d``) is an upper bound on its MAPE.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from eyeviz import EyevizError
from eyeviz.reports.common import add_formats_option, parse_formats
from eyeviz.reports.study_design import (
    LIMITS,
    MIN_COUNT,
    PAPER,
    PAPER3D,
    Design,
    _nearest,
    band_designs,
    bin_at,
    choose_estimator,
    designs3d,
    designs_of,
    heatmap_table,
    l_per_h,
    read_study3d,
    smallest_m,
)
from eyeviz.reports.study_figures import (
    DASHES,
    FORMATS,
    OKABE_ITO,
    ONE_COLUMN,
    PNG_DPI,
    PT,
    TWO_COLUMNS,
    _cell,
    _rc,
    curves_figure,
    dd_figure,
    design_figure,
    elevation_figure,
    heatmap_figure,
    law_figure,
    law_figure3d,
    save,
)
from eyeviz.reports.study_law import (
    LAW_MAX,
    LawFit,
    LawPoint,
    fit_law,
    fit_power,
    law_points,
    law_points3d,
)
from eyeviz.reports.study_summary import (
    CAPTIONS,
    _write_text,
    markdown,
    summary3d_json,
    summary_csv,
    summary_json,
)
from eyeviz.reports.study_table import Row, read_study
from eyeviz.study.point import BIN_WIDTH
from eyeviz.study.table import is_table3d

# The analysis, figures and summaries live in study_design, study_law, study_figures and
# study_summary; their names stay importable from here (the tests use several of them).
__all__ = [
    "CAPTIONS",
    "DASHES",
    "FORMATS",
    "HELP",
    "LAW_MAX",
    "MIN_COUNT",
    "ONE_COLUMN",
    "OKABE_ITO",
    "PAPER",
    "PARTS",
    "PNG_DPI",
    "PT",
    "TWO_COLUMNS",
    "Design",
    "LawFit",
    "LawPoint",
    "Row",
    "_cell",
    "add_arguments",
    "bin_at",
    "curves_figure",
    "designs_of",
    "fit_law",
    "heatmap_figure",
    "heatmap_table",
    "l_per_h",
    "law_figure",
    "law_points",
    "markdown",
    "read_study",
    "run",
    "save",
    "smallest_m",
    "summary_csv",
    "summary_json",
    "write_report",
]

HELP = "figures of the eye-design study: the limit against h, l, m and distance"


@dataclass(frozen=True)
class Asked:
    """What the report was asked for (the command's options): ``at``, ``law_max`` and
    ``target`` apply to a planar table, ``band`` and ``estimator`` to a 3D one."""

    prior: str | None
    l_wanted: float
    at: float
    law_max: float
    target: float
    band: float | None
    estimator: str | None = None
    formats: tuple[str, ...] = FORMATS


def _prior(have: set[str], prior: str | None) -> str:
    """``prior``, else the table's only prior, else the single-pass one."""
    if prior is not None:
        return prior
    return sorted(have)[0] if len(have) == 1 else "single"


def _write_planar(path: Path, outdir: Path, a: Asked) -> list[Path]:
    """The planar report: the study_* figures, summary.csv, summary.json and study.md."""
    if a.band is not None:
        raise EyevizError(f"--band applies to a 3D study table only; {path} is a planar one")
    rows = read_study(path)
    prior = _prior({r.prior for r in rows}, a.prior)
    designs = designs_of(rows, prior)
    l_of = l_per_h(designs, a.l_wanted)
    table = heatmap_table(designs, l_of, a.at)
    points = law_points(designs, a.law_max)
    fit = fit_law(points, a.law_max)
    best = smallest_m(designs, l_of, a.at, a.target)
    outdir.mkdir(parents=True, exist_ok=True)
    written = _save_figures(outdir, a.formats, (
        ("study_dd", lambda: curves_figure(designs, l_of, "dd", a.l_wanted)),
        ("study_ad", lambda: curves_figure(designs, l_of, "ad", a.l_wanted)),
        ("study_heatmap", lambda: heatmap_figure(table, l_of, a.at, a.l_wanted)),
        ("study_law", lambda: law_figure(points, fit)),
    ))  # fmt: skip
    args_d = {"table": str(path), "prior": prior, "at": a.at, "l": a.l_wanted, "target": a.target}
    args_d["formats"] = a.formats
    written.append(_write_text(outdir / "summary.csv", summary_csv(table, fit)))
    written.append(
        _write_text(outdir / "summary.json", summary_json(table, fit, args_d, designs, best))
    )
    shown = "png" if "png" in a.formats else a.formats[0]  # the one study.md shows
    figs = [p.name for p in written if p.suffix == f".{shown}"]  # in the order drawn
    written.append(
        _write_text(outdir / "study.md", markdown(table, fit, designs, l_of, best, args_d, figs))
    )
    return written


def _write_spherical(path: Path, outdir: Path, a: Asked) -> list[Path]:
    """The 3D report: the study3d_* figures and summary3d.json, the distance bins merged
    into bands ``a.band`` wide (:func:`~eyeviz.reports.study_design.merge_bins`)."""
    band = BIN_WIDTH if a.band is None else a.band
    rows = read_study3d(path)
    prior = _prior({r["prior"] for r in rows}, a.prior)
    est = a.estimator or choose_estimator(rows)
    designs = designs3d(rows, est, prior)
    if band != BIN_WIDTH:
        designs = band_designs(designs, band)
    points = law_points3d(designs)
    fit: LawFit = fit_law(points, x_max=math.inf)
    power = fit_power(points)
    hs = sorted({k[0] for k in designs})
    l_of = {h: _nearest([k[1] for k in designs if k[0] == h], a.l_wanted) for h in hs}
    h_star = _nearest(hs, PAPER3D[0])
    is_limit = est in LIMITS
    label = est if is_limit else f"{est} (an upper bound on the limit, not the limit)"
    outdir.mkdir(parents=True, exist_ok=True)
    written = _save_figures(outdir, a.formats, (
        ("study3d_design", lambda: design_figure(designs, l_of, h_star, label)),
        ("study3d_dd", lambda: dd_figure(designs, l_of, fit, label)),
        ("study3d_law", lambda: law_figure3d(points, fit, power, label)),
        ("study3d_elevation", lambda: elevation_figure(designs, h_star, l_of[h_star], label)),
    ))  # fmt: skip
    text = summary3d_json(path, rows, prior, est, is_limit, designs, points, fit, power, band)
    written.append(_write_text(outdir / "summary3d.json", text))
    return written


def _save_figures(
    outdir: Path, formats: tuple[str, ...], figures: Sequence[tuple[str, Callable[[], object]]]
) -> list[Path]:
    """Each (stem, draw) figure drawn in the report's style and saved in ``formats``
    (:func:`save`)."""
    import matplotlib

    written: list[Path] = []
    with matplotlib.rc_context(_rc()):
        for stem, draw in figures:
            written += save(draw(), outdir, stem, formats)
    return written


@dataclass(frozen=True)
class Part:
    """One eye model's report: which tables are its own, and its writer."""

    kind: str
    holds: Callable[[Path], bool]
    write: Callable[[Path, Path, Asked], list[Path]]


#: The report's part per eye model, the first whose ``holds`` takes the table.
PARTS = (
    Part("spherical", is_table3d, _write_spherical),  # eyeviz study --nside
    Part("planar", lambda path: True, _write_planar),
)


def write_report(
    path: Path,
    outdir: Path,
    at: float = 3000.0,
    prior: str | None = None,
    l_wanted: float = PAPER[1],
    law_max: float = LAW_MAX,
    target: float = 5.0,
    band: float | None = None,
    estimator: str | None = None,
    formats: tuple[str, ...] = FORMATS,
) -> list[Path]:
    """Read the study table at ``path`` and write every figure and summary of its eye
    model's part (:data:`PARTS`) into ``outdir`` (``band``: a 3D table's distance bins
    merged into bands that wide; ``estimator``: a 3D table's estimator to draw, default
    the limit where the table has it; ``formats``: the figures' file formats)."""
    checks = (("--at", at), ("--l", l_wanted), ("--law-max", law_max), ("--target", target))
    for name, v in (*checks, ("--band", BIN_WIDTH if band is None else band)):
        if not (math.isfinite(v) and v > 0):
            raise EyevizError(f"{name} must be a finite number > 0, got {v!r}")
    formats = parse_formats(",".join(formats))
    asked = Asked(prior, l_wanted, at, law_max, target, band, estimator, formats)
    part = next(p for p in PARTS if p.holds(path))
    return part.write(path, outdir, asked)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("table", type=Path, help="the study table (eyeviz study -o STUDY.csv)")
    parser.add_argument("-o", "--output", required=True, type=Path, help="output directory")
    parser.add_argument(
        "--at", type=float, default=3000.0, help="distance of the heatmap (default 3000)"
    )
    parser.add_argument(
        "--prior",
        default=None,
        choices=("single", "multi"),
        help="which prior's rows to draw (default: the table's only prior, else single)",
    )
    parser.add_argument(
        "--l",
        type=float,
        default=PAPER[1],
        dest="l_wanted",
        help="eye radius l of the curves and the heatmap (default 20, the "
        "paper's; an h without it uses the nearest l)",
    )
    parser.add_argument(
        "--law-max",
        type=float,
        default=LAW_MAX,
        help=f"fit the law where gamma r/(2h) <= this (default {LAW_MAX:g})",
    )
    parser.add_argument(
        "--target",
        type=float,
        default=5.0,
        help="DD error (%%) for the 'fewest ommatidia' table (default 5)",
    )
    parser.add_argument(
        "--band",
        type=float,
        default=None,
        help=f"3D table: merge its {BIN_WIDTH:g}-wide distance bins into bands this wide "
        "(a multiple) for the figures, the law's fit and the summary (default: as they are)",
    )
    add_formats_option(parser, FORMATS)


def run(args: argparse.Namespace) -> int:
    paths = write_report(
        args.table,
        args.output,
        args.at,
        args.prior,
        args.l_wanted,
        args.law_max,
        args.target,
        args.band,
        formats=parse_formats(args.formats),
    )
    print(f"wrote {len(paths)} files into {args.output}")
    return 0
