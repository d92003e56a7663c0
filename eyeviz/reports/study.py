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

A 3D study table (``eyeviz study --nside``) gets the 3D figures instead
(:mod:`eyeviz.reports.study3d`); ``--band W`` merges its 500-wide distance bins into bands
W wide first (3D only: a planar table is refused with it).

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
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from eyeviz import EyevizError
from eyeviz.reports.study_design import (
    MIN_COUNT,
    PAPER,
    Design,
    bin_at,
    designs_of,
    heatmap_table,
    l_per_h,
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
    heatmap_figure,
    law_figure,
    save,
)
from eyeviz.reports.study_law import LAW_MAX, LawFit, LawPoint, fit_law, law_points
from eyeviz.reports.study_summary import (
    CAPTIONS,
    _write_text,
    markdown,
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


def write_report(
    path: Path,
    outdir: Path,
    at: float = 3000.0,
    prior: str | None = None,
    l_wanted: float = PAPER[1],
    law_max: float = LAW_MAX,
    target: float = 5.0,
    band: float | None = None,
) -> list[Path]:
    """Read the study table at ``path`` and write every figure and summary into ``outdir``
    (``band``: a 3D table's distance bins merged into bands that wide)."""
    checks = (("--at", at), ("--l", l_wanted), ("--law-max", law_max), ("--target", target))
    for name, v in (*checks, ("--band", BIN_WIDTH if band is None else band)):
        if not (math.isfinite(v) and v > 0):
            raise EyevizError(f"{name} must be a finite number > 0, got {v!r}")
    if is_table3d(path):  # eyeviz study --nside: the 3D report (its own figures)
        from eyeviz.reports.study3d import write_report3d

        return write_report3d(
            path, outdir, prior, l_wanted, band=BIN_WIDTH if band is None else band
        )
    if band is not None:
        raise EyevizError(f"--band applies to a 3D study table only; {path} is a planar one")
    rows = read_study(path)
    if prior is None:  # the table's only prior, else the single-pass one
        have = sorted({r.prior for r in rows})
        prior = have[0] if len(have) == 1 else "single"
    designs = designs_of(rows, prior)
    l_of = l_per_h(designs, l_wanted)
    table = heatmap_table(designs, l_of, at)
    points = law_points(designs, law_max)
    fit = fit_law(points, law_max)
    best = smallest_m(designs, l_of, at, target)
    outdir.mkdir(parents=True, exist_ok=True)
    import matplotlib

    written: list[Path] = []
    with matplotlib.rc_context(_rc()):
        for stem, fig in (
            ("study_dd", curves_figure(designs, l_of, "dd", l_wanted)),
            ("study_ad", curves_figure(designs, l_of, "ad", l_wanted)),
            ("study_heatmap", heatmap_figure(table, l_of, at, l_wanted)),
            ("study_law", law_figure(points, fit)),
        ):
            written += save(fig, outdir, stem)
    args_d = {"table": str(path), "prior": prior, "at": at, "l": l_wanted, "target": target}
    written.append(_write_text(outdir / "summary.csv", summary_csv(table, fit)))
    written.append(
        _write_text(outdir / "summary.json", summary_json(table, fit, args_d, designs, best))
    )
    figs = [p.stem for p in written if p.suffix == ".png"]  # in the order drawn
    written.append(
        _write_text(outdir / "study.md", markdown(table, fit, designs, l_of, best, args_d, figs))
    )
    return written


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
    )
    print(f"wrote {len(paths)} files into {args.output}")
    return 0
