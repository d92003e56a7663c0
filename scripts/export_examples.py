"""Regenerate the README's exported figures, docs/img/figure_*.png (and .pdf/.svg with --all).

    .venv/bin/python scripts/export_examples.py [--all] [--width single|double|INCHES]

Every figure is `eyeviz.render.mpl.export.export` of a shipped scene (assets/scenes), plus one
variant of the default scene built here that shows the predictions (analytic estimator)
and ambiguity layers and a feature outside the networks' domain, and a close-up of one
feature's ambiguity region.
"""

from __future__ import annotations

import argparse
import copy
from pathlib import Path

from eyeviz.model import scene as scene_mod
from eyeviz.render.mpl.export import export

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "assets" / "scenes"
OUT = ROOT / "docs" / "img"


def predictions_scene() -> scene_mod.Scene:
    sc = copy.deepcopy(scene_mod.load(SCENES / "default.toml"))
    sc.title = "Predictions (analytic) and the centres with the same bitmaps"
    sc.features.append(scene_mod.Feature("outside", 3000.0, 800.0, 100.0, "#E69F00"))
    sc.layers = ["eyes", "bfv", "features", "predictions", "ambiguity", "readout", "labels"]
    sc.estimators = ["analytic"]
    return sc


def ambiguity_scene() -> scene_mod.Scene:
    sc = scene_mod.Scene(
        eyes=scene_mod.Eyes(40.0, 20.0, 720),
        features=[scene_mod.Feature("target", 0.0, 1500.0, 50.0, "#D55E00")],
        layers=["features", "ambiguity", "tangents", "labels", "readout"],
        view=scene_mod.View((0.0, 1600.0), 500.0),
        title="The hatched needle: centres with the same two bitmaps",
    )
    return sc


def posterior_scene() -> scene_mod.Scene:
    """The default scene with the limit's posterior over centres (issue 10): for "side" the
    same bitmaps come from centres at r ~ 2700-5000 (every g), not only its own g's needle."""
    sc = copy.deepcopy(scene_mod.load(SCENES / "default.toml"))
    sc.title = "The limit's posterior over centres, over every g"
    sc.layers = ["eyes", "bfv", "features", "ambiguity", "posterior", "predictions", "readout"]
    sc.layers.append("labels")
    sc.estimators = ["limit"]
    return sc


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--all", action="store_true", help="also write .svg and .pdf")
    ap.add_argument(
        "--width", default="single", help="'single' (3.5 in, default), 'double' or inches"
    )
    args = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    figures = {
        "figure_default": scene_mod.load(SCENES / "default.toml"),
        "figure_3b": scene_mod.load(SCENES / "figure3b.toml"),
        "figure_bfv": scene_mod.load(SCENES / "figure5.toml"),
        "figure_2": scene_mod.load(SCENES / "figure2.toml"),
        "figure_predictions": predictions_scene(),
        "figure_ambiguity": ambiguity_scene(),
        "figure_posterior": posterior_scene(),
    }
    for name, sc in figures.items():
        for suffix in (".png", ".svg", ".pdf") if args.all else (".png",):
            print(export(sc, OUT / f"{name}{suffix}", width=args.width).relative_to(ROOT))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
