"""``eyeviz report estimators -o DIR``: error against run time for every estimator.

On fresh test sets generated with the paper's parameters (Tables 3 and 4; single- and
multi-pass, seeds unlike any training seed), each estimator is scored on azimuth (AD, phi)
and distance (DD, r): MAPE (Eq. 34), MAE (Eq. 33) and R^2. R^2 is the standard one
(1 - SS_res/SS_tot with SS_tot the spread of the TRUE values, as scikit-learn's
``r2_score``), not Eq. 35-36's spread of the predictions (DESIGN.md §4).
Beside the metrics: training time (from the estimator's metadata), inference time per
sample when batched and for one sample alone, and the number of learned weights. The
paper's Table 5 is quoted as a reference row; the bayes estimator is the information
limit (the best error any estimator can reach from the bitmaps).

Estimators that cannot be loaded (the paper nets without weights, say) are listed with
the reason, never crashed on. Output: ``estimators.md``, ``estimators.csv``,
``estimators.png`` (error against inference time, log axes).
"""

from __future__ import annotations

import argparse
import csv
import io
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from eyeviz.core.domain import DEFAULTS as _D
from eyeviz.files import limits
from eyeviz.model.palette import ESTIMATOR_COLORS, estimator_color

if TYPE_CHECKING:
    from eyeviz.estimators.base import Estimator, Prediction

HELP = "estimators' AD/DD error, training and inference time (error against run time)"

TEST_SEED = 20_231_122  # not a training seed of any shipped estimator
TEST_SETS = ("single", "multi")
TARGETS = (("ad", "phi"), ("dd", "r"))

# Table 5 of the paper, quoted. Its R^2 is Eq. 35 (spread of the predictions).
PAPER_TABLE5: dict[str, Any] = {
    "ad": {
        "mape": 0.832,
        "r2": 0.998,
        "train_seconds": 2 * 3600 + 3 * 60 + 49,
        "setup": "RMSProp, batch 64, lr 0.004",
    },
    "dd": {
        "mape": 7.713,
        "r2": 0.899,
        "train_seconds": 48 * 60 + 53,
        "setup": "SGD, batch 32, lr 0.001",
    },
    "n_weights": 60_671_521 + 32_674_321,  # Appendix A + B layer sizes
    "hardware": "nVidia Tesla P4 (Google Colab)",
}


@dataclass
class Result:
    """One estimator's figures; ``status`` is "ok" or the reason it is unavailable."""

    name: str
    status: str = "ok"
    label: str = ""
    n_weights: int | None = None
    train_seconds: float | None = None
    batched_us: float | None = None  # per sample, batched over the single-pass test set
    single_ms: float | None = None  # one sample alone, median
    metrics: dict = field(default_factory=dict)  # test set -> {"n", "n_valid", "ad", "dd"}
    table_keys: int | None = None  # lookup-table estimators (bayes): stored keys

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def label_short(self) -> str:
        if self.n_weights:
            return f"{self.name} ({_fmt_weights(self.n_weights)} weights)"
        if self.table_keys:
            return f"{self.name} (table of {_fmt_weights(self.table_keys)} keys)"
        return f"{self.name} (no weights)"


# --- shared helpers (also used by the trajectories report) --------------------------------


def parse_names(text: str | None) -> list[str]:
    """Estimator names from "a,b c" (default: all available); ValueError naming unknown ones."""
    from eyeviz import estimators

    avail = estimators.available()
    if text is None:
        return avail
    names = [s for s in str(text).replace(",", " ").split() if s]
    bad = [s for s in names if s not in avail]
    if bad or not names:
        raise ValueError(
            f"unknown estimator(s) {', '.join(bad) or '(none given)'}; available: "
            f"{', '.join(avail)}"
        )
    return list(dict.fromkeys(names))


def try_load(name: str):
    """(estimator, "") or (None, one-line reason) — never raises for a missing estimator."""
    from eyeviz import estimators

    try:
        return estimators.load(name), ""
    except (ValueError, OSError, ImportError, RuntimeError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        if name == "paper" and "not found" in msg:
            return None, "not trained here (make the weights with `eyeviz train paper`)"
        return None, msg


def write_atomic(path: Path, data: bytes | str) -> None:
    """Write a file via a temporary file in the same directory and ``os.replace``."""
    from eyeviz.files.atomic import atomic_output

    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(path) as tmp:
        tmp.write_bytes(data.encode("utf-8") if isinstance(data, str) else data)


def save_figure(fig, path: Path, dpi: int = 150) -> None:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    write_atomic(path, buf.getvalue())


def accuracy_metrics(y, yhat) -> dict[str, float]:
    """MAPE, MAE, R^2 over the rows where the prediction is finite (eyeviz.estimators.metrics)."""
    from eyeviz.estimators import metrics

    y = np.asarray(y, np.float64)
    yhat = np.asarray(yhat, np.float64)
    ok = np.isfinite(yhat)
    if not ok.any():
        return {"mape": math.nan, "mae": math.nan, "r2": math.nan}
    out = {"mape": metrics.mape(y[ok], yhat[ok]), "mae": metrics.mae(y[ok], yhat[ok])}
    try:
        out["r2"] = metrics.r2(y[ok], yhat[ok])
    except ValueError:
        out["r2"] = math.nan
    return out


# --- measuring ----------------------------------------------------------------------------


def make_test_sets(n: int, seed: int = TEST_SEED) -> dict:
    """Fresh single- and multi-pass test sets with the paper's parameters (Tables 3, 4)."""
    from eyeviz import dataset

    return {mode: dataset.generate(n, mode=mode, seed=seed + i) for i, mode in enumerate(TEST_SETS)}


def _time_batched(est: Estimator, oa: np.ndarray, ob: np.ndarray) -> tuple[Prediction, float]:
    t = time.perf_counter()
    pred = est.predict(oa, ob)
    best = time.perf_counter() - t
    if best < 1.0:  # fast estimators: best of three
        for _ in range(2):
            t = time.perf_counter()
            est.predict(oa, ob)
            best = min(best, time.perf_counter() - t)
    return pred, best


def _time_single(est, oa, ob, max_calls: int = 300, max_seconds: float = 3.0) -> float:
    est.predict(oa[0], ob[0])  # warm-up
    times = []
    t_end = time.perf_counter() + max_seconds
    for i in range(min(max_calls, len(oa))):
        t = time.perf_counter()
        est.predict(oa[i], ob[i])
        times.append(time.perf_counter() - t)
        if time.perf_counter() > t_end and len(times) >= 5:
            break
    return float(np.median(times))


def measure_one(name: str, est, test_sets: dict) -> Result:
    """Score and time a loaded estimator on every test set."""
    md = getattr(est, "metadata", {}) or {}
    label = str(md.get("label", ""))
    if not label and "sample_size" in md:  # the bayes table
        label = (
            f"{md.get('target', '')} posterior per interval key from "
            f"{int(md['sample_size']):,} samples ({int(md.get('keys', 0)):,} keys)"
        )
    res = Result(
        name=name,
        label=label,
        n_weights=int(est.n_weights),
        train_seconds=md.get("train_seconds"),
        table_keys=int(md["keys"]) if "keys" in md else None,
    )
    for mode, data in test_sets.items():
        pred, secs = _time_batched(est, data.omega_a, data.omega_b)
        r_hat, phi_hat = pred
        valid = np.asarray(getattr(pred, "valid", np.isfinite(r_hat)))
        entry: dict[str, Any] = {"n": int(len(data.r)), "n_valid": int(valid.sum())}
        for key, col in TARGETS:
            truth = data.phi if col == "phi" else data.r
            entry[key] = accuracy_metrics(truth, phi_hat if col == "phi" else r_hat)
        res.metrics[mode] = entry
        if mode == TEST_SETS[0]:
            res.batched_us = 1e6 * secs / max(1, len(data.r))
            res.single_ms = 1e3 * _time_single(est, data.omega_a, data.omega_b)
    return res


def measure(names: list[str], n_test: int, seed: int = TEST_SEED, progress=None) -> list[Result]:
    test_sets = make_test_sets(n_test, seed)
    out = []
    for name in names:
        est, why = try_load(name)
        out.append(
            measure_one(name, est, test_sets) if est is not None else Result(name=name, status=why)
        )
        if progress is not None:
            progress(name)
    return out


# --- writing ------------------------------------------------------------------------------


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


def _fmt_weights(n) -> str:
    if n is None:
        return "–"
    return f"{n / 1e6:.1f} M" if n >= 1e6 else f"{n:,}"


def _limit(results: list[Result]) -> Result | None:
    for r in results:
        if r.name == "bayes" and r.ok:
            return r
    return None


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
        "true values, as scikit-learn's `r2_score`), not Eq. 35-36 (DESIGN.md §4).",
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


# one colour per estimator name, the same in the app, the figures and every report
# (eyeviz.model.palette); kept under this name for the reports that import it
_COLORS = ESTIMATOR_COLORS


def plot(results: list[Result]):
    """Figure: AD and DD MAPE against inference time per sample (log-log).

    Markers sit at the batched time; a thin line runs from there to the time of one call
    with one sample (the latency an interactive user sees).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    from matplotlib.ticker import FuncFormatter, LogLocator

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.8), constrained_layout=True)
    lim = _limit(results)
    ok = [r for r in results if r.ok and r.batched_us]
    handles: dict[str, Line2D] = {}
    for ax, (key, title) in zip(axes, (("ad", "AD: azimuth"), ("dd", "DD: distance")), strict=True):
        for i, r in enumerate(ok):
            c = estimator_color(r.name)
            size = 45 + 45 * (len(ok) - 1 - i)  # coincident points show as concentric rings
            assert r.batched_us is not None  # ok keeps only timed results
            x = r.batched_us * 1e-6
            y = r.metrics["single"][key]["mape"]
            if r.single_ms and math.isfinite(y):
                ax.plot(
                    [x, r.single_ms * 1e-3],
                    [y, y],
                    color=c,
                    lw=1.0,
                    alpha=0.6,
                    marker="|",
                    markevery=[1],
                    ms=10,
                    zorder=2,
                )
            for mode, marker, face in (("single", "o", c), ("multi", "s", "none")):
                y = r.metrics[mode][key]["mape"]
                if math.isfinite(y):
                    ax.scatter(
                        [x],
                        [y],
                        marker=marker,
                        s=size,
                        facecolors=face,
                        edgecolors=c,
                        linewidths=1.5,
                        zorder=3 + i,
                    )
            handles.setdefault(
                r.name, Line2D([], [], marker="o", ls="", color=c, label=r.label_short())
            )
        t5 = PAPER_TABLE5[key]["mape"]
        ax.axhline(t5, color="#555555", ls=":", lw=1.3)
        if lim is not None:
            ax.axhline(
                lim.metrics["single"][key]["mape"],
                color=estimator_color("bayes"),
                ls="--",
                lw=1.0,
                alpha=0.8,
            )
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.margins(x=0.2, y=0.25)
        lo, hi = ax.get_ylim()
        major = (
            (1.0, 2.0, 5.0)
            if math.log10(hi / lo) > 1.2
            else (1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0)
        )
        ax.yaxis.set_major_locator(LogLocator(subs=major))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_locator(LogLocator(subs=tuple(float(k) for k in range(1, 10))))
        ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: ""))
        ax.set_xlabel("inference time per sample (s)")
        ax.set_ylabel("MAPE (%)")
        ax.set_title(title)
        ax.grid(True, which="major", alpha=0.35)
        ax.grid(True, which="minor", alpha=0.12)
    extra = [
        Line2D([], [], marker="o", ls="", color="k", label="single-pass test set, batched"),
        Line2D(
            [],
            [],
            marker="s",
            ls="",
            markerfacecolor="none",
            color="k",
            label="multi-pass test set, batched",
        ),
        Line2D(
            [], [], marker="|", ms=10, color="k", lw=1.0, alpha=0.6, label="one sample per call"
        ),
        Line2D([], [], ls=":", color="#555555", lw=1.3, label="paper Table 5 (quoted)"),
    ]
    if lim is not None:
        extra.append(
            Line2D(
                [],
                [],
                ls="--",
                color=estimator_color("bayes"),
                label="information limit (bayes, single-pass)",
            )
        )
    missing = [r.name for r in results if not r.ok]
    if missing:
        extra.append(Line2D([], [], ls="", label="unavailable: " + ", ".join(missing)))
    fig.legend(
        handles=[*handles.values(), *extra],
        loc="outside lower center",
        ncol=4,
        fontsize=8,
        frameon=False,
    )
    return fig


def write(results: list[Result], outdir: Path, n_test: int, seed: int) -> list[Path]:
    import matplotlib.pyplot as plt

    outdir.mkdir(parents=True, exist_ok=True)
    png = outdir / "estimators.png"
    fig = plot(results)
    save_figure(fig, png)
    plt.close(fig)
    write_atomic(outdir / "estimators.csv", to_csv(results))
    write_atomic(outdir / "estimators.md", to_markdown(results, n_test, seed, png.name))
    return [outdir / "estimators.md", outdir / "estimators.csv", png]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-o", "--output", required=True, type=Path, help="output directory")
    parser.add_argument(
        "--n-test",
        type=int,
        default=20000,
        help="elements per test set (default 20000, the paper's test sample)",
    )
    parser.add_argument(
        "--estimators", default=None, help="comma-separated names (default: all available)"
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=TEST_SEED,
        help=f"test-set seed; multi-pass uses seed+1 (default {TEST_SEED})",
    )


def run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    limits.check_int("--n-test", args.n_test, 10, limits.MAX_ROWS)
    names = parse_names(args.estimators)
    bar = tqdm(total=len(names), desc="estimators", unit="est", leave=False)

    def progress(name):
        bar.set_postfix_str(name)
        bar.update(1)

    results = measure(names, args.n_test, args.seed, progress)
    bar.close()
    paths = write(results, args.output, args.n_test, args.seed)
    for r in results:
        if r.ok:
            e = r.metrics["single"]
            print(
                f"{r.name:9s} AD MAPE {e['ad']['mape']:.3f} %  DD MAPE {e['dd']['mape']:.3f} %  "
                f"R^2 {e['dd']['r2']:.4f}  {r.batched_us:.3g} µs/sample  "
                f"{r.single_ms:.3g} ms single"
            )
        else:
            print(f"{r.name:9s} unavailable: {r.status}")
    print("wrote " + ", ".join(str(p) for p in paths))
    return 0
