"""``eyeviz report estimators --data FILE | --nside N``: the spherical eyes' estimators.

On a sparse 3D data set (``eyeviz generate --nside``; or a fresh one of ``--n-test`` rows
drawn from the 3D Algorithm 1 with ``--seed``), every estimator of kind "spherical" in
the registry (analytic3d, limit3d, learned3d, ...) is scored on distance (DD: MAPE of r,
Eq. 34), azimuth (AD: MAPE of the azimuth) and elevation (MAPE of the elevation, and
its mean absolute error in degrees: the elevation crosses 0, where a relative error
blows up, so the MAE is the figure to read), with the rows it flagged (answered by a
fallback). Run time: microseconds per row when batched, milliseconds for one row alone.

The limit costs milliseconds per row, so it is measured on at most ``--limit-rows``
evenly spaced rows; every estimator is also scored on those same rows (the "subset"
columns), which is the like-for-like comparison. Output: ``estimators3d.md``,
``estimators3d.csv``, ``estimators3d.png`` (error against run time, log axes).
"""

from __future__ import annotations

import csv
import io
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from eyeviz.reports.common import save_figure, write_atomic
from eyeviz.reports.errors import bootstrap_se, with_error

__all__ = ["Result3D", "SLOW", "measure3d", "plot3d", "to_csv3d", "to_markdown3d", "write3d"]

#: estimators measured on the subset only (milliseconds per row)
SLOW = ("limit3d",)
_KEYS = ("dd", "ad", "el_mape", "el_mae_deg")


@dataclass
class Result3D:
    name: str
    status: str = ""  # "" when measured, else why not
    rows: int = 0
    metrics: dict[str, dict[str, float]] = field(default_factory=dict)  # "all"/"subset"
    errors: dict[str, dict[str, float]] = field(default_factory=dict)  # their bootstrap SEs
    flagged: dict[str, int] = field(default_factory=dict)
    batched_us: float = math.nan
    single_ms: float = math.nan
    n_weights: int = 0

    @property
    def ok(self) -> bool:
        return not self.status


def _terms(ds, rows: np.ndarray, r, az, el) -> dict[str, np.ndarray]:
    """Each figure's per-row terms: its value is their mean (MAPE, Eq. 34; MAE)."""
    if np.any(ds.r[rows] == 0) or np.any(ds.azimuth[rows] == 0) or np.any(ds.elevation[rows] == 0):
        raise ValueError("MAPE is undefined where the true value is 0")
    return {
        "dd": 100.0 * np.abs((r - ds.r[rows]) / ds.r[rows]),
        "ad": 100.0 * np.abs((az - ds.azimuth[rows]) / ds.azimuth[rows]),
        "el_mape": 100.0 * np.abs((el - ds.elevation[rows]) / ds.elevation[rows]),
        "el_mae_deg": np.degrees(np.abs(el - ds.elevation[rows])),
    }


def _metrics(ds, rows: np.ndarray, r, az, el) -> tuple[dict[str, float], dict[str, float]]:
    """The figures on ``rows`` and their bootstrap standard errors (eyeviz.reports.errors)."""
    terms = _terms(ds, rows, r, az, el)
    values = {k: float(np.mean(t)) for k, t in terms.items()}
    return values, {k: bootstrap_se(t) for k, t in terms.items()}


def measure3d(ds, names: list[str], limit_rows: int = 1000, progress=None) -> list[Result3D]:
    """Score each estimator ``names`` (registry kind "spherical") on the Dataset3D ``ds``."""
    from eyeviz import EyevizError
    from eyeviz.estimators import registry
    from eyeviz.estimators.base import take_rows

    n = len(ds)
    step = max(1, math.ceil(n / max(1, limit_rows)))
    subset = np.arange(0, n, step)
    out = []
    for name in names:
        res = Result3D(name)
        try:
            est = registry.load(name, domain=ds.domain)
        except (EyevizError, ValueError, OSError, ImportError, RuntimeError) as exc:
            res.status = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            out.append(res)
            continue
        res.n_weights = int(getattr(est, "n_weights", 0))
        rows = subset if name in SLOW else np.arange(n)
        la = take_rows(ds.indptr_a, ds.indices_a, rows)
        lb = take_rows(ds.indptr_b, ds.indices_b, rows)
        t0 = time.perf_counter()
        p = est.predict(la, lb)
        res.batched_us = (time.perf_counter() - t0) / max(1, rows.size) * 1e6
        valid = np.asarray(p.valid, bool)
        if not valid.all():
            res.status = f"no answer for {int((~valid).sum())} of {rows.size} rows"
            out.append(res)
            continue
        res.rows = int(rows.size)
        flagged = np.asarray(getattr(p, "flagged", np.zeros(rows.size, bool)), bool)
        at = np.searchsorted(rows, subset)
        r, az, el = (np.asarray(v, float) for v in (p[0], p[1], p[2]))
        res.metrics["subset"], res.errors["subset"] = _metrics(ds, subset, r[at], az[at], el[at])
        res.flagged["subset"] = int(flagged[at].sum())
        if name not in SLOW:
            res.metrics["all"], res.errors["all"] = _metrics(ds, rows, r, az, el)
            res.flagged["all"] = int(flagged.sum())
        one_a = take_rows(ds.indptr_a, ds.indices_a, subset[:1])
        one_b = take_rows(ds.indptr_b, ds.indices_b, subset[:1])
        t0 = time.perf_counter()
        est.predict(one_a, one_b)
        res.single_ms = (time.perf_counter() - t0) * 1e3
        out.append(res)
        if progress is not None:
            progress(name)
    return out


def _color(name: str) -> str:
    from eyeviz.model.palette import estimator_color

    return estimator_color(name.removesuffix("3d"))


def plot3d(results: list[Result3D]):
    """Figure: DD and AD MAPE and elevation MAE on the subset against time per row, each
    with its bootstrap standard error as an error bar (``Result3D.errors``)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(14, 4.6), constrained_layout=True)
    ok = [r for r in results if r.ok]
    panels = (
        ("dd", "DD: distance, MAPE (%)"),
        ("ad", "AD: azimuth, MAPE (%)"),
        ("el_mae_deg", "elevation, MAE (degrees)"),
    )
    for ax, (key, title) in zip(axes, panels, strict=True):
        for r in ok:
            x = r.batched_us * 1e-6
            y = r.metrics["subset"][key]
            c = _color(r.name)
            ax.plot([x, r.single_ms * 1e-3], [y, y], color=c, lw=1.0, alpha=0.6)
            se = r.errors.get("subset", {}).get(key, math.nan)
            if math.isfinite(se):
                ax.errorbar(
                    [x], [y], yerr=[se], fmt="none", color="black", lw=1.0, capsize=5, zorder=4
                )
            ax.scatter([x], [y], s=70, color=c, edgecolors="black", zorder=3, label=r.name)
            ax.annotate(r.name, (x, y), textcoords="offset points", xytext=(6, 6), fontsize=8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(title)
        ax.set_xlabel("seconds per row (marker: batched; line to: one row alone)")
        ax.grid(True, which="both", alpha=0.3)
    if ok:
        axes[0].legend(loc="best", fontsize=8)
    return fig


CSV_FIELDS3D = (
    "estimator", "status", "rows", "subset_dd_mape", "subset_ad_mape", "subset_el_mape",
    "subset_el_mae_deg", "subset_flagged", "all_dd_mape", "all_ad_mape", "all_el_mape",
    "all_el_mae_deg", "all_flagged", "batched_us_per_row", "single_ms", "n_weights",
    "subset_dd_se", "subset_ad_se", "subset_el_mape_se", "subset_el_mae_deg_se",
    "all_dd_se", "all_ad_se", "all_el_mape_se", "all_el_mae_deg_se",
)  # fmt: skip


def to_csv3d(results: list[Result3D]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_FIELDS3D)
    for r in results:
        row: list[object] = [r.name, r.status or "ok", r.rows]
        for part in ("subset", "all"):
            m = r.metrics.get(part, {})
            row += [f"{m[k]:.6g}" if k in m else "" for k in _KEYS]
            row.append(r.flagged.get(part, ""))
        row += [f"{r.batched_us:.6g}", f"{r.single_ms:.6g}", r.n_weights]
        for part in ("subset", "all"):
            e = r.errors.get(part, {})
            row += [f"{e[k]:.6g}" if k in e else "" for k in _KEYS]
        w.writerow(row)
    return buf.getvalue()


def _cell(m: dict[str, float], e: dict[str, float], k: str, best: float | None) -> str:
    """``value ± se`` to the precision the bootstrap error allows; bold for the best."""
    if k not in m:
        return "—"
    s = with_error(m[k], e.get(k, math.nan))
    return f"**{s}**" if best is not None and m[k] == best else s


def to_markdown3d(results: list[Result3D], what: str, png: str) -> str:
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
        best = {k: min(r.metrics[part][k] for r in have) for k in _KEYS} if part == "subset" else {}
        lines += [
            f"## {head}",
            "",
            "| estimator | DD MAPE % | AD MAPE % | el MAPE % | el MAE deg | flagged | "
            "µs/row batched | ms one row | weights |",
            "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
        ]
        for r in have:
            m, e = r.metrics[part], r.errors.get(part, {})
            cells = " | ".join(_cell(m, e, k, best.get(k)) for k in _KEYS)
            lines.append(
                f"| {r.name} | {cells} | {r.flagged.get(part, 0)} | "
                f"{r.batched_us:.3g} | {r.single_ms:.3g} | {r.n_weights} |"
            )
        lines.append("")
    bad = [r for r in results if not r.ok]
    if bad:
        lines += ["## Not measured", ""] + [f"- **{r.name}**: {r.status}" for r in bad] + [""]
    lines += [f"![error against run time]({png})", ""]
    return "\n".join(lines)


def write3d(results: list[Result3D], outdir: Path, what: str) -> list[Path]:
    import matplotlib.pyplot as plt

    outdir.mkdir(parents=True, exist_ok=True)
    png = outdir / "estimators3d.png"
    fig = plot3d(results)
    save_figure(fig, png)
    plt.close(fig)
    write_atomic(outdir / "estimators3d.csv", to_csv3d(results))
    write_atomic(outdir / "estimators3d.md", to_markdown3d(results, what, png.name))
    return [outdir / "estimators3d.md", outdir / "estimators3d.csv", png]
