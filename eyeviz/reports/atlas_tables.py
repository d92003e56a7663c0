"""The atlas's tables: CSV files and the Markdown report (:func:`write_all`)."""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path

__all__ = ["bins_csv", "field_csv", "summary_csv", "times_csv", "to_markdown", "write_all"]


def _f(v, fmt: str = ".4g") -> str:
    if isinstance(v, int):
        return str(v)
    return "" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, fmt)


def _csv(header: tuple[str, ...], rows: list[list]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for row in rows:
        w.writerow([_f(v) if isinstance(v, float) else v for v in row])
    return buf.getvalue()


SUMMARY = (
    "pair",
    "facets_a",
    "facets_b",
    "b_mm",
    "dphi_deg",
    "r_min_mm",
    "r_max_mm",
    "r_min_b",
    "r_max_b",
    "g_max_mm",
    "el_max_deg",
    "estimator",
    "status",
    "rows",
    "dd_pct",
    "dd_se",
    "az_deg",
    "az_se",
    "el_deg",
    "el_se",
    "rule_pct",
    "exponent",
    "flagged",
    "us_per_row",
)


def summary_csv(atlases) -> str:
    rows = []
    for a in atlases:
        p = a.prior
        head = [
            a.label,
            a.facets[0],
            a.facets[1],
            p["b_mm"],
            p["dphi_deg"],
            p["r_min_mm"],
            p["r_max_mm"],
            p["r_min_b"],
            p["r_max_b"],
            p["g_max_mm"],
            p["el_max_deg"],
        ]
        for s in a.scores:
            o = a.overall.get(s.name, {})
            rows.append(
                head
                + [s.name, s.status or "ok", int(o.get("rows", 0))]
                + [
                    o.get(k, math.nan)
                    for k in (
                        "dd",
                        "dd_se",
                        "az",
                        "az_se",
                        "el",
                        "el_se",
                        "rule",
                        "exponent",
                    )
                ]
                + [int(o.get("flagged", 0)), o.get("us_per_row", math.nan)]
            )
    return _csv(SUMMARY, rows)


BINS = (
    "pair",
    "estimator",
    "lo_mm",
    "hi_mm",
    "lo_b",
    "hi_b",
    "count",
    "dd_pct",
    "dd_se",
    "az_deg",
    "az_se",
    "el_deg",
    "el_se",
    "rule_pct",
    "dd_over_rule",
)


def bins_csv(atlases) -> str:
    rows = []
    for a in atlases:
        for name, bins in a.bins.items():
            for b in bins:
                rows.append(
                    [a.label, name]
                    + [
                        b[k]
                        for k in (
                            "lo_mm",
                            "hi_mm",
                            "lo_b",
                            "hi_b",
                            "count",
                            "dd",
                            "dd_se",
                            "az",
                            "az_se",
                            "el",
                            "el_se",
                            "rule",
                            "ratio",
                        )
                    ]
                )
    return _csv(BINS, rows)


FIELD = (
    "pair",
    "r_mm",
    "r_b",
    "cells",
    "solid_angle_sr",
    "az_min_deg",
    "az_max_deg",
    "el_min_deg",
    "el_max_deg",
    "facets_a_median",
    "facets_a_max",
    "facets_b_median",
    "facets_b_max",
)


def field_csv(atlases) -> str:
    rows = []
    for a in atlases:
        for f in a.fields:
            rows.append(
                [a.label, f["r_mm"], f["r_b"], f["cells"], f["sr"]]
                + [
                    f.get(k, math.nan)
                    for k in (
                        "az_min",
                        "az_max",
                        "el_min",
                        "el_max",
                        "a_median",
                        "a_max",
                        "b_median",
                        "b_max",
                    )
                ]
            )
    return _csv(FIELD, rows)


def times_csv(atlases, fig_s: float, total: float) -> str:
    rows = [[a.label, step, s] for a in atlases for step, s in a.times.items()]
    rows += [["all", "figures", fig_s], ["all", "whole atlas", total]]
    return _csv(("pair", "step", "seconds"), rows)


def _pm(v: float, se: float, fmt: str = ".3g") -> str:
    if math.isnan(v):
        return "—"
    return f"{v:{fmt}} ± {se:.2g}" if not math.isnan(se) else f"{v:{fmt}}"


def _pair_md(a) -> list[str]:
    p = a.prior
    lines = [
        f"## {a.label}",
        "",
        f"{a.facets[0]} + {a.facets[1]} facets; baseline b = {p['b_mm']:.3f} mm; "
        f"interommatidial angle dphi = {p['dphi_deg']:.3f} deg. Prior: r in "
        f"[{p['r_min_mm']:.3g}, {p['r_max_mm']:.3g}] mm = [{p['r_min_b']:.3g}, "
        f"{p['r_max_b']:.3g}] b, g <= {p['g_max_mm']:.3g} mm, |el| <= {p['el_max_deg']:.3g} "
        f"deg; {a.rows} test balls.",
        "",
        "| r | binocular solid angle | azimuth (deg) | elevation (deg) | facets A (median, max) "
        "| facets B (median, max) |",
        "|---|---:|---|---|---|---|",
    ]
    for f in a.fields:
        where = (
            (
                f"{f['az_min']:.1f} to {f['az_max']:.1f} | {f['el_min']:.1f} to "
                f"{f['el_max']:.1f} | {f['a_median']:.0f}, {f['a_max']} | {f['b_median']:.0f}, "
                f"{f['b_max']}"
            )
            if f["cells"]
            else "— | — | — | —"
        )
        lines.append(
            f"| {f['r_mm']:.3g} mm ({f['r_b']:.3g} b) | {f['sr']:.4f} sr "
            f"({f['sr'] * (180 / math.pi) ** 2:.0f} deg²) | {where} |"
        )
    lines += [
        "",
        "| estimator | rows | DD % | azimuth MAE deg | elevation MAE deg | "
        "rule Z dphi/b % | DD ~ Z^k, k | flagged | µs/row |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for s in a.scores:
        if not s.ok:
            lines.append(f"| {s.name} | — | not measured: {s.status} | | | | | | |")
            continue
        o = a.overall[s.name]
        lines.append(
            f"| {s.name} | {int(o['rows'])} | {_pm(o['dd'], o['dd_se'])} | "
            f"{_pm(o['az'], o['az_se'])} | {_pm(o['el'], o['el_se'])} | {o['rule']:.3g} | "
            f"{_f(o['exponent'], '.2f') or '—'} | {int(o['flagged'])} | {o['us_per_row']:.3g} |"
        )
    lines += [
        "",
        "Per distance bin (DD and the rule's relative error Z dphi_loc / b, %):",
        "",
        "| estimator | r (mm) | r (b) | n | DD % | rule % | DD / rule | az deg | el deg |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for name, bins in a.bins.items():
        for b in bins:
            lines.append(
                f"| {name} | {b['lo_mm']:.3g}–{b['hi_mm']:.3g} | {b['lo_b']:.3g}–{b['hi_b']:.3g} "
                f"| {b['count']} | {_pm(b['dd'], b['dd_se'])} | {_f(b['rule'], '.3g')} | "
                f"{_f(b['ratio'], '.2f')} | {_pm(b['az'], b['az_se'])} | "
                f"{_pm(b['el'], b['el_se'])} |"
            )
    lines += ["", "Run time: " + ", ".join(f"{k} {v:.2f} s" for k, v in a.times.items()), ""]
    return lines


def to_markdown(atlases, args, figs: list[Path], fig_s: float, total: float) -> str:
    lines = [
        "# Atlas of measured eyes: what they can know about distance",
        "",
        f"Command: `eyeviz report atlas` with --rows {args.rows}, --limit-rows "
        f"{args.limit_rows}, --bins {args.bins}, --seed {args.seed}, --mode {args.mode}, "
        f"--field-step {args.field_step:g}, --ball-deg {args.ball_deg:g}. Whole atlas: "
        f"{total:.1f} s (figures {fig_s:.1f} s).",
        "",
        "DD is the mean absolute relative error of r (%); azimuth and elevation errors are "
        "mean absolute errors in degrees; ± is the standard error of the mean. The rule of "
        "thumb is dZ ~ Z^2 dphi / b, as a relative error Z dphi_loc / b with dphi_loc the "
        "mean interommatidial angle of the lit facets. k is the exponent of DD against r "
        "over the bins (the rule says 1). The limit (a name with 'limit') is measured on "
        "an evenly spaced subset of the rows.",
        "",
    ]
    for a in atlases:
        lines += _pair_md(a)
    more = [f for f in args.formats[1:]]
    lines += (
        ["## Figures", ""]
        + [f"![{p.stem}]({p.name})" + "".join(f" [{f}]({p.stem}.{f})" for f in more) for p in figs]
        + [""]
    )
    return "\n".join(lines)


def write_all(atlases, args, outdir: Path, figs: list[Path], fig_s: float, total: float):
    from eyeviz.reports.common import write_atomic

    files = {
        "atlas_summary.csv": summary_csv(atlases),
        "atlas_bins.csv": bins_csv(atlases),
        "atlas_field.csv": field_csv(atlases),
        "atlas_times.csv": times_csv(atlases, fig_s, total),
        "atlas.md": to_markdown(atlases, args, figs, fig_s, total),
    }
    for name, text in files.items():
        write_atomic(outdir / name, text)
    return [outdir / n for n in files]
