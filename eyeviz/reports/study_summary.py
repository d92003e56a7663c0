"""The summary files of the eye-design study (:mod:`eyeviz.reports.study`).

Planar eyes: ``summary.csv`` (the table behind the heatmap with the law's value per
cell), ``summary.json`` (the fitted constant, its spread and the paper's design) and the
Markdown text of ``study.md``. Spherical eyes: ``summary3d.json`` (the estimator drawn,
the law with its bootstrap spread and the free power law, every design and distance bin,
the table's other estimators; :func:`summary3d_json`).
"""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

from eyeviz.files.atomic import atomic_output
from eyeviz.reports.study_design import MIN_COUNT, PAPER, Design3D, bin_errors
from eyeviz.reports.study_law import (
    FIT_MAX,
    FLAG_MAX,
    REL_MAX,
    LawFit,
    LawPoint,
    law_uncertainty,
)

CAPTIONS = {
    "study_dd": "DD limit (MAPE %) against distance, a panel per h, a curve per m",
    "study_ad": "AD limit (MAPE %) against distance, a panel per h, a curve per m",
    "study_heatmap": "DD limit at --at over (h, m), values in the cells",
    "study_law": "relative DD error against gamma r / (2h) with the fitted C",
}


def _write_text(path: Path, text: str) -> Path:
    with atomic_output(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def summary_csv(table: list[dict], fit: LawFit) -> str:
    buf = io.StringIO()
    cols = [*table[0].keys(), "law_dd_mape"]
    w = csv.DictWriter(buf, fieldnames=cols, lineterminator="\n")
    w.writeheader()
    for t in table:
        x = t["gamma"] * 0.5 * (t["r_lo"] + t["r_hi"]) / (2 * t["h"])  # the bin centre
        w.writerow({**t, "law_dd_mape": "" if fit.C is None else round(100 * fit.C * x, 6)})
    return buf.getvalue()


def _clean(v):
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def summary_json(table, fit: LawFit, args_d: dict, designs: dict, best: dict) -> str:
    paper = designs.get(PAPER)
    out = {
        "source": args_d,
        "law": {
            "formula": "relative DD error (MAPE/100) = C * gamma * r / (2h), gamma = 2 pi / m",
            "C": fit.C,
            "method": fit.method,
            "log_sd": fit.log_sd,
            "factor_1sd": fit.factor,
            "points_fitted": fit.n,
            "x_max": fit.x_max,
            "min_count": MIN_COUNT,
            "excluded": "the first and last bin of each design (the prior's bounds truncate "
            "the posterior there) and bins with gamma r / (2h) > x_max (saturation)",
            "free_slope": fit.slope,
            "free_C": fit.C_free,
        },
        "paper_design": None
        if paper is None
        else {
            "h": PAPER[0],
            "l": PAPER[1],
            "m": PAPER[2],
            "dd_mape": paper.all.dd_mape,
            "ad_mape": paper.all.ad_mape,
            "n": paper.all.n,
        },
        "smallest_m_for_target": {f"{h:g}": m for h, m in best.items()},
        "heatmap": [{k: _clean(v) for k, v in t.items()} for t in table],
    }
    return json.dumps(out, indent=1, allow_nan=False) + "\n"


def markdown(table, fit, designs, l_of, best, args_d, figures) -> str:
    at, target = args_d["at"], args_d["target"]
    lines = [
        "# The eye-design study: the information limit against h, l, m and distance",
        "",
        f"Source: `{args_d['table']}`, prior `{args_d['prior']}`, {len(designs)} designs. "
        "MAPE (Eq. 34) of the information limit: no estimator that sees only the two "
        "bitmaps has a lower expected error under the prior.",
        "",
    ]
    paper = designs.get(PAPER)
    if paper is None:
        lines += ["The paper's eyes (h 40, l 20, m 720) are not in this table: no figure marks "
                  "them.", ""]  # fmt: skip
    else:
        lines += [
            f"The paper's eyes (h 40, l 20, m 720): DD {paper.all.dd_mape:.2f} %, "
            f"AD {paper.all.ad_mape:.3f} % over r in [{paper.all.r_min:g}, "
            f"{paper.all.r_max:g}] (n = {paper.all.n}).",
            "",
        ]
    if fit.C is not None:
        lines += [
            f"**The law**: relative DD error = C γ r / (2h) with C = {fit.C:.3g} "
            f"(×÷ {fit.factor:.2f} for one standard deviation, {fit.n} bins; {fit.method}; "
            f"bins with γ r/(2h) <= {fit.x_max:g}, not the first or last bin of a design). "
            f"A free log-log fit gives slope {fit.slope:.2f}.",
            "",
        ]
    lines += [
        f"Fewest ommatidia m for a DD error <= {target:g} % at r = {at:g}:",
        "",
        "| h | l | m |",
        "|---:|---:|---:|",
    ]
    for h, m in best.items():
        lines.append(f"| {h:g} | {l_of[h]:g} | {m if m is not None else 'none in the grid'} |")
    formats = ", ".join(f.upper() for f in args_d.get("formats", ("pdf", "svg", "png")))
    lines += ["", f"Figures (each as {formats}):", ""]
    for name in figures:
        f = Path(name).stem
        lines += [f"**{f}**: {CAPTIONS.get(f, '')}", "", f"![{f}]({name})", ""]
    return "\n".join(lines) + "\n"


def _no_nan(v):
    """``v`` with every NaN float (a bin of one row has no standard error) as None."""
    if isinstance(v, dict):
        return {k: _no_nan(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_no_nan(x) for x in v]
    return None if isinstance(v, float) and math.isnan(v) else v


def summary3d_json(
    path: Path,
    rows: list[dict],
    prior: str,
    est: str,
    is_limit: bool,
    designs: dict[tuple, Design3D],
    points: list[LawPoint],
    fit: LawFit,
    power: dict | None,
    band: float,
) -> str:
    """``summary3d.json`` of a 3D table's report: ``est``'s designs (of ``prior``), their
    law with its spread, the free power law and the table's other estimators."""
    summary = {
        "table": str(path),
        "estimator": est,
        "is_the_limit": is_limit,
        "prior": prior,
        "law_slope_1": {
            "C": fit.C,
            "factor_1sd": fit.factor,
            "n": fit.n,
            "free_slope": fit.slope,
            "C_free": fit.C_free,
            **law_uncertainty(points),
        },
        "power_law": power,
        "band": band,
        "fit_rule": f"interior distance bins ({band:g} wide), >= {MIN_COUNT} elements, "
        f"<= {FLAG_MAX:.0%} flagged, relative DD error <= {FIT_MAX:g}, sampling error of "
        f"the DD <= {REL_MAX:.0%} of it where stated",
        "designs": [
            {
                "h": d.h,
                "l": d.l,
                "nside": d.nside,
                "gamma": d.gamma,
                "n": d.all["n"],
                **{
                    k: d.all[k]
                    for k in (
                        "dd_mape",
                        "dd_se",
                        "ad_mape",
                        "el_mae_deg",
                        "el_se",
                        "az_mae_deg",
                        "flagged",
                        "seconds",
                    )
                },
                "el_mae_over_gamma": d.all["el_mae_deg"] / math.degrees(d.gamma),
            }
            for d in sorted(designs.values(), key=lambda d: d.key)
        ],
        "bins": bin_errors(designs),
        "other_estimators": [  # the table's other estimators, overall, beside the drawn one
            {
                "estimator": r["estimator"],
                "h": r["h"],
                "l": r["l"],
                "nside": r["nside"],
                "n": r["n"],
                "seed": r["seed"],
                **{k: r[k] for k in ("dd_mape", "ad_mape", "el_mae_deg", "az_mae_deg")},
            }
            for r in rows
            if r["bin"] == "all" and r["estimator"] != est and r["prior"] == prior
        ],
    }
    return json.dumps(_no_nan(summary), indent=1, allow_nan=False) + "\n"
