"""Extreme scenes and hostile inputs are drawn or refused about as fast as ordinary ones
(issue 13): the speed claims the tests used to make with wall-clock assertions.

The tests check what makes these cases quick without timing them (bound_figure leaves
nothing far outside the figure, a refusal comes before any figure is made, a bad model
file is refused before its network is built; tests/render/test_bounded.py,
tests/render/test_export.py, tests/estimators/test_model_files.py). This script times
each case against a baseline measured in the same run, in the same process, and prints
the ratio: on a shared machine the seconds stretch with the load, the ratios much less.
The targets sit far below what the original bugs cost (Agg subdividing a disc that spans
1e11 pixels ran for minutes) and above run-to-run noise.

    .venv/bin/python scripts/bench_bounded.py [--repeat N]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import torch  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402

from eyeviz import EyevizError  # noqa: E402
from eyeviz.estimators import compact  # noqa: E402
from eyeviz.model import scene as S  # noqa: E402
from eyeviz.render.mpl import bounded, vector  # noqa: E402
from eyeviz.render.mpl.export import export  # noqa: E402
from eyeviz.resources import models_dir, scenes_dir  # noqa: E402

ALL = '"features", "tangents", "ambiguity", "bitmaps", "readout", "bfv", "eyes", "labels"'


def median_s(fn: Callable[[], object], repeat: int) -> float:
    fn()  # warm: imports, font cache
    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        runs.append(time.perf_counter() - t0)
    return statistics.median(runs)


def refused(fn: Callable[[], object]) -> Callable[[], None]:
    def run() -> None:
        try:
            fn()
        except EyevizError:
            return
        raise AssertionError("expected a refusal")

    return run


def _fig(*patches, texts=()) -> Figure:
    fig = Figure(figsize=(3, 3), dpi=100)
    ax = fig.add_subplot()
    ax.set_xlim(0, 10)
    ax.set_ylim(0, 10)
    for p in patches:
        ax.add_patch(p)
    for x, y, s in texts:
        ax.text(x, y, s, clip_on=True)
    return fig


def draw_small() -> None:
    FigureCanvasAgg(_fig(Circle((5, 5), 1.0), texts=[(5, 5, "near")])).draw()


def draw_huge_bounded() -> None:
    fig = _fig(
        Circle((5, -1e12 + 5), 1e12, facecolor="r"),
        Circle((1e9, 1e9), 1.0),
        Circle((5, 5), 1.0),
        texts=[(1e12, 0, "far"), (5, 5, "near")],
    )
    bounded.bound_figure(fig)
    FigureCanvasAgg(fig).draw()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    print(
        f"load average: {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs; "
        f"median of {args.repeat} runs each\n"
    )
    default = S.load(scenes_dir() / "default.toml")
    huge = S.loads(
        '[eyes]\nm = 6\n[[features]]\nname = "cc"\nx = 0.0\ny = 0.0\ng = 1e12\n'
        f"[layers]\nshow = [{ALL}]\n[view]\ncenter = [6235.4, 0.0]\nwidth = 8000.0\n",
        "huge.toml",
    )
    tiny = S.loads(
        '[eyes]\nm = 5000\n[layers]\nshow = ["eyes", "sectors", "labels"]\n'
        "[view]\ncenter = [57.5517, 9.5885]\nwidth = 1e-2\n",
        "tiny.toml",
    )
    names = default.copy()
    names.features[0].name = r"$\undefined$ x"
    names.features[1].name = "n" * 1_000_000
    names.title = "$\\frac{1}{0}$ " + "t" * 1_000_000
    far = default.copy()
    far.features[0].x = 1e308
    many = default.copy()
    f = many.features[0]
    many.features = [S.Feature(f"f{i}", f.x + i, f.y, f.g) for i in range(vector.MAX_FEATURES + 1)]
    rows: list[tuple[str, float, str, float]] = []  # name, seconds, baseline, target ratio
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        base_draw = median_s(draw_small, args.repeat)
        base_png = median_s(lambda: export(default, out / "d.png"), args.repeat)
        base_svg = median_s(lambda: export(default, out / "d.svg"), args.repeat)
        rows.append(("Agg draw: a huge disc, bounded", median_s(draw_huge_bounded, args.repeat),
                     "draw", 10.0))  # fmt: skip
        cases = [
            ("snapshot .png: disc of radius 1e12", lambda: export(huge, out / "h.png"), "png", 5),
            ("snapshot .svg: view 1e-2 inside m = 5000", lambda: export(tiny, out / "t.svg"),
             "svg", 40),
            ("snapshot .png + .svg: 1e6-character names",
             lambda: (export(names, out / "n.png"), export(names, out / "n.svg")), "png", 10),
            ("refusal: a feature at x = 1e308", refused(lambda: export(far, out / "f.png")),
             "png", 0.25),
            ("refusal: 10001 features", refused(lambda: export(many, out / "m.png")), "png", 0.25),
        ]  # fmt: skip
        for name, fn, base, target in cases:
            rows.append((name, median_s(fn, args.repeat), base, target))

        d = out / "m"
        d.mkdir()
        for name in ("compact.json", "compact_dd.pt", "compact_ad.pt"):
            shutil.copy(models_dir() / name, d / name)
        base_load = median_s(lambda: compact.load(d), args.repeat)
        bad = out / "bad"
        shutil.copytree(d, bad)
        torch.save({"hidden": 30000, "state": {}}, bad / "compact_dd.pt")
        rows.append(("refusal: compact hidden = 30000", median_s(refused(lambda: compact.load(bad)),
                     args.repeat), "load", 1.0))  # fmt: skip

    bases = {"draw": base_draw, "png": base_png, "svg": base_svg, "load": base_load}
    labels = {
        "draw": "Agg draw of one small disc",
        "png": "snapshot .png of the default scene",
        "svg": "snapshot .svg of the default scene",
        "load": "loading the shipped compact model",
    }
    print(f"{'baseline':52s} {'ms':>9s}")
    for key, s in bases.items():
        print(f"{labels[key]:52s} {1e3 * s:9.1f}")
    print(f"\n{'case':52s} {'ms':>9s} {'ratio':>7s} {'target':>8s}  against")
    failed = 0
    for name, s, base, target in rows:
        ratio = s / bases[base]
        ok = ratio <= target
        failed += not ok
        print(
            f"{name:52s} {1e3 * s:9.1f} {ratio:7.2f} {'<= ' + format(target, 'g'):>8s}  "
            f"{labels[base]}{'' if ok else '  FAIL'}"
        )
    print(f"\n{len(rows) - failed} of {len(rows)} within target")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
