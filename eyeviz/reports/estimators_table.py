"""The CSV and Markdown of the estimators report (:mod:`eyeviz.reports.estimators`): the
planar eyes' (:func:`to_csv`, :func:`to_markdown`) and those of the eyes that see lit sets,
spherical or measured (:func:`to_csv_lit`, :func:`to_markdown_lit`)."""

from __future__ import annotations

import csv
import io
import math

from eyeviz.core.domain import DEFAULTS as _D
from eyeviz.reports.errors import with_error
from eyeviz.reports.estimators_measure import (
    LIT_KEYS,
    PAPER_TABLE5,
    TEST_SETS,
    Result,
    _fmt_weights,
    _limit,
)


def _fmt(v, spec: str = ".3f", none: str = "–") -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return none
    return format(v, spec)


def _fmt_time(seconds) -> str:
    if seconds is None:
        return "–"
    s = float(seconds)
    if s < 120:
        return f"{s:.1f} s"
    if s < 7200:
        return f"{s / 60:.1f} min"
    return f"{s / 3600:.2f} h"


CSV_FIELDS = [
    "estimator",
    "status",
    "test_set",
    "n",
    "n_valid",
    "ad_mape_pct",
    "ad_mae_rad",
    "ad_r2",
    "dd_mape_pct",
    "dd_mae",
    "dd_r2",
    "train_seconds",
    "infer_us_per_sample_batched",
    "infer_ms_single",
    "n_weights",
    "label",
]


def to_csv(results: list[Result]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_FIELDS)
    for r in results:
        common_tail = [r.train_seconds, r.batched_us, r.single_ms, r.n_weights, r.label]
        if not r.ok:
            w.writerow([r.name, r.status, "", "", "", "", "", "", "", "", "", *[""] * 4, ""])
            continue
        for mode, e in r.metrics.items():
            w.writerow(
                [
                    r.name,
                    "ok",
                    mode,
                    e["n"],
                    e["n_valid"],
                    e["ad"]["mape"],
                    e["ad"]["mae"],
                    e["ad"]["r2"],
                    e["dd"]["mape"],
                    e["dd"]["mae"],
                    e["dd"]["r2"],
                    *common_tail,
                ]
            )
    t5 = PAPER_TABLE5
    w.writerow(
        [
            "paper Table 5 (quoted)",
            "reference",
            "paper's own test split",
            "20000",
            "",
            t5["ad"]["mape"],
            "",
            t5["ad"]["r2"],
            t5["dd"]["mape"],
            "",
            t5["dd"]["r2"],
            t5["ad"]["train_seconds"] + t5["dd"]["train_seconds"],
            "",
            "",
            t5["n_weights"],
            "R^2 by Eq. 35 (spread of predictions); trained on " + t5["hardware"],
        ]
    )
    return buf.getvalue()


def _descriptions(results: list[Result]) -> list[str]:
    """One line per estimator from its registry entry (the one place its help lives)."""
    from eyeviz.estimators import registry

    lines = []
    for r in results:
        try:
            lines.append(f"- **{r.name}**: {registry.get(r.name).help}")
        except ValueError:
            continue
    return [*lines, ""] if lines else []


def to_markdown(results: list[Result], n_test: int, seed: int, png: str | None) -> str:
    lim = _limit(results)
    lines = [
        "# Estimators: error against run time",
        "",
        f"Fresh test sets of {n_test} elements each, generated with the paper's parameters "
        f"(h = {_D['h']:g}, l = {_D['l']:g}, m = {_D['m']}; r in [{_D['r_min']:g}, "
        f"{_D['r_max']:g}], g <= {_D['g_max']:g}), single-pass (seed {seed}) "
        f"and multi-pass (seed {seed + 1}). AD = azimuth phi (radians), DD = distance r.",
        "MAPE is Eq. 34; R^2 is the **standard** coefficient of determination (spread of the "
        "true values, as scikit-learn's `r2_score`), not Eq. 35-36 (docs/conventions.md).",
        "Inference time: per sample when the whole single-pass set is passed at once "
        "(best of 3 for fast estimators), and the median time of one call with one sample.",
        "",
        *_descriptions(results),
    ]
    for mode in TEST_SETS:
        lines += [
            f"## {mode}-pass test set",
            "",
            "| estimator | AD MAPE % | AD MAE (rad) | AD R^2 | DD MAPE % | DD MAE | DD R^2 "
            "| training | µs/sample batched | ms single | weights |",
            "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        ]
        for r in results:
            if not r.ok:
                lines.append(f"| {r.name} | *unavailable: {r.status}* |  |  |  |  |  |  |  |  |  |")
                continue
            e = r.metrics[mode]
            name = f"**{r.name}** (limit)" if r.name == "bayes" else r.name
            cover = "" if e["n_valid"] == e["n"] else f" ({e['n_valid']}/{e['n']} valid)"
            lines.append(
                f"| {name}{cover} | {_fmt(e['ad']['mape'])} | {_fmt(e['ad']['mae'], '.2e')} | "
                f"{_fmt(e['ad']['r2'], '.5f')} | {_fmt(e['dd']['mape'])} | "
                f"{_fmt(e['dd']['mae'], '.1f')} | {_fmt(e['dd']['r2'], '.4f')} | "
                f"{_fmt_time(r.train_seconds)} | {_fmt(r.batched_us, '.3g')} | "
                f"{_fmt(r.single_ms, '.3g')} | {_fmt_weights(r.n_weights)} |"
            )
        t5 = PAPER_TABLE5
        lines.append(
            f"| *paper Table 5 (quoted)* | {t5['ad']['mape']} | – | {t5['ad']['r2']}\\* | "
            f"{t5['dd']['mape']} | – | {t5['dd']['r2']}\\* | "
            f"2 h 3 min 49 s + 48 min 53 s on a Tesla P4 | – | – | "
            f"{_fmt_weights(t5['n_weights'])} |"
        )
        if lim is not None:
            e = lim.metrics[mode]
            lines += [
                "",
                f"Information limit (bayes) on this set: AD MAPE {_fmt(e['ad']['mape'])} %, "
                f"DD MAPE {_fmt(e['dd']['mape'])} %"
                + (f" — {lim.label}" if lim.label else "")
                + ".",
            ]
        lines.append("")
    lines += [
        "\\* Table 5's R^2 is Eq. 35 (divides by the spread of the predictions) on the paper's "
        "own test split; quoted, not re-measured. Training times there are on a GPU.",
        "",
    ]
    notes = [f"- **{r.name}**: {r.label}" for r in results if r.ok and r.label]
    if notes:
        lines += ["Estimator details (from their metadata):", "", *notes, ""]
    if png:
        lines += [f"![error against inference time]({png})", ""]
    return "\n".join(lines)


# --- the eyes that see lit sets (spherical, measured) ----------------------------------------
CSV_FIELDS_LIT = (
    "estimator", "status", "rows", "subset_dd_mape", "subset_ad_mape", "subset_el_mape",
    "subset_el_mae_deg", "subset_flagged", "all_dd_mape", "all_ad_mape", "all_el_mape",
    "all_el_mae_deg", "all_flagged", "batched_us_per_row", "single_ms", "n_weights",
    "subset_dd_se", "subset_ad_se", "subset_el_mape_se", "subset_el_mae_deg_se",
    "all_dd_se", "all_ad_se", "all_el_mape_se", "all_el_mae_deg_se",
)  # fmt: skip


def _num(v: float | None) -> float:
    """A time not measured (None) as NaN, as the lit-set tables print it."""
    return math.nan if v is None else v


def to_csv_lit(results: list[Result]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_FIELDS_LIT)
    for r in results:
        row: list[object] = [r.name, r.status, r.rows]
        for part in ("subset", "all"):
            m = r.metrics.get(part, {})
            row += [f"{m[k]:.6g}" if k in m else "" for k in LIT_KEYS]
            row.append(r.flagged.get(part, ""))
        row += [f"{_num(r.batched_us):.6g}", f"{_num(r.single_ms):.6g}", r.n_weights or 0]
        for part in ("subset", "all"):
            e = r.errors.get(part, {})
            row += [f"{e[k]:.6g}" if k in e else "" for k in LIT_KEYS]
        w.writerow(row)
    return buf.getvalue()


def _cell(m: dict[str, float], e: dict[str, float], k: str, best: float | None) -> str:
    """``value ± se`` to the precision the bootstrap error allows; bold for the best."""
    if k not in m:
        return "—"
    s = with_error(m[k], e.get(k, math.nan))
    return f"**{s}**" if best is not None and m[k] == best else s


def to_markdown_lit(results: list[Result], what: str, png: str) -> str:
    ok = [r for r in results if r.ok]
    lines = [
        "# Estimators of the spherical eyes: error and run time",
        "",
        what,
        "",
        "DD, AD: MAPE (%) of r and of the azimuth (Eq. 34). Elevation: MAPE (%) and mean "
        "absolute error (degrees); the elevation crosses 0, where a relative error blows "
        "up, so read the MAE. Each figure is followed by its standard error (bootstrap "
        "over the test rows) and printed to the precision that error allows. Bold: the "
        "best on the subset.",
        "",
    ]
    for part, head in (("subset", "Every estimator on the same rows (the subset)"),
                       ("all", "Every row (the fast estimators)")):  # fmt: skip
        have = [r for r in ok if part in r.metrics]
        if not have:
            continue
        best = (
            {k: min(r.metrics[part][k] for r in have) for k in LIT_KEYS} if part == "subset" else {}
        )
        lines += [
            f"## {head}",
            "",
            "| estimator | DD MAPE % | AD MAPE % | el MAPE % | el MAE deg | flagged | "
            "µs/row batched | ms one row | weights |",
            "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
        ]
        for r in have:
            m, e = r.metrics[part], r.errors.get(part, {})
            cells = " | ".join(_cell(m, e, k, best.get(k)) for k in LIT_KEYS)
            lines.append(
                f"| {r.name} | {cells} | {r.flagged.get(part, 0)} | "
                f"{_num(r.batched_us):.3g} | {_num(r.single_ms):.3g} | {r.n_weights} |"
            )
        lines.append("")
    bad = [r for r in results if not r.ok]
    if bad:
        lines += ["## Not measured", ""] + [f"- **{r.name}**: {r.status}" for r in bad] + [""]
    lines += [f"![error against run time]({png})", ""]
    return "\n".join(lines)
