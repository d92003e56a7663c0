"""`eyeviz snapshot` of many features (a fixed-size PNG) and `--min-font` (issue 25)."""

from __future__ import annotations

import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from eyeviz.model.scene import Eyes, Feature, Scene, View, save

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "assets" / "scenes"


def _scene_file(tmp_path: Path, n: int) -> Path:
    rng = np.random.default_rng(n)
    feats = [
        Feature(
            f"f{i}",
            round(float(rng.uniform(-3000, 3000)), 1),
            round(float(rng.uniform(600, 5000)), 1),
            round(float(rng.uniform(20, 200)), 1),
            "#0072B2",
        )
        for i in range(n)
    ]
    sc = Scene(
        Eyes(),
        feats,
        ["eyes", "bfv", "features", "bitmaps", "readout", "labels"],
        [],
        View((0.0, 2500.0), 8000.0),
        f"{n} features",
    )
    path = tmp_path / f"s{n}.toml"
    save(sc, path)
    return path


def _snapshot(*args) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "eyeviz", "snapshot", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
        env={**__import__("os").environ, "MPLBACKEND": "Agg"},
    )


def _png_size(path: Path) -> tuple[int, int]:
    w, h = struct.unpack(">II", path.read_bytes()[16:24])
    return w, h


@pytest.mark.slow
def test_png_size_does_not_grow_with_features(tmp_path, eyeviz_main):
    """400 features once made a 1050 x 31,620 px PNG; now 400 and 4000 are one size."""
    sizes = {}
    for n in (400, 4000):
        out = tmp_path / f"o{n}.png"
        run = eyeviz_main("snapshot", _scene_file(tmp_path, n), "-o", out)
        assert run.returncode == 0, run.stderr
        sizes[n] = _png_size(out)
    assert sizes[400] == sizes[4000]
    assert sizes[400][0] == 1050 and sizes[400][1] < 3000


@pytest.mark.slow
def test_min_font_makes_a_taller_figure_and_bad_values_are_refused(tmp_path, eyeviz_main):
    scene = SCENES / "default.toml"
    heights = {}
    for pt in (None, "8"):
        out = tmp_path / f"m{pt}.png"
        extra = [] if pt is None else ["--min-font", pt]
        run = eyeviz_main("snapshot", scene, "-o", out, *extra)
        assert run.returncode == 0, run.stderr
        heights[pt] = _png_size(out)[1]
    assert heights["8"] > heights[None]
    for bad in ("4", "30", "nan", "big"):
        run = eyeviz_main("snapshot", scene, "-o", tmp_path / "bad.png", "--min-font", bad)
        assert run.returncode == 2, run.stderr
        assert run.stderr.count("\n") == 1 and "min-font" in run.stderr, run.stderr
    assert not (tmp_path / "bad.png").exists()


def test_emoji_in_names_print_one_warning_line(tmp_path):
    """Three emoji in a name printed three warning pairs (the warning and its source
    line) per export; now one line naming each character once."""
    text = (SCENES / "default.toml").read_text(encoding="utf-8")
    scene = tmp_path / "emoji.toml"
    scene.write_text(
        text.replace('name = "target"', 'name = "bee \U0001f41d\U0001f98b\U0001f41e\U0001f41d"'),
        encoding="utf-8",
    )
    for suffix in ("png", "svg"):
        run = _snapshot(scene, "-o", tmp_path / f"e.{suffix}")
        assert run.returncode == 0, run.stderr
        lines = run.stderr.strip().splitlines()
        assert len(lines) == 1, run.stderr
        assert lines[0].startswith("eyeviz: warning: 3 characters not in the figure's font")
        for ch in "\U0001f41d\U0001f98b\U0001f41e":
            assert lines[0].count(ch) == 1


def test_other_warnings_pass_through_the_glyph_collector(capsys):
    import warnings

    from eyeviz.render.mpl.glyphs import one_glyph_warning

    with pytest.warns(RuntimeWarning, match="something else"), one_glyph_warning():
        warnings.warn("Glyph 9731 (\\N{SNOWMAN}) missing from font(s) DejaVu Sans.", stacklevel=1)
        warnings.warn("Glyph 9731 (\\N{SNOWMAN}) missing from font(s) DejaVu Sans.", stacklevel=1)
        warnings.warn("something else", RuntimeWarning, stacklevel=1)
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "1 character not in" in err and "\u2603" in err
