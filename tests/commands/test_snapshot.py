"""`eyeviz snapshot`: headless, light (no torch/Qt/VTK), one-line errors."""

import json
import struct
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "assets" / "scenes"

PROBE = """
import json, sys
from eyeviz.cli import main
rc = main(sys.argv[1:])
heavy = sorted(m for m in ("torch", "PyQt5", "vtk", "pyvista", "pyvistaqt", "matplotlib.pyplot")
               if m in sys.modules)
print(json.dumps({"rc": rc, "heavy": heavy}))
"""


def run_probe(*args):
    out = subprocess.run(
        [sys.executable, "-c", PROBE, *map(str, args)],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=ROOT,
    )
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.strip().splitlines()[-1]), out


def test_snapshot_png_without_heavy_imports(tmp_path):
    res, _ = run_probe(
        "snapshot", SCENES / "default.toml", "-o", tmp_path / "s.png", "--scale", "0.5"
    )
    assert res == {"rc": 0, "heavy": []}
    data = (tmp_path / "s.png").read_bytes()
    assert struct.unpack(">II", data[16:24])[0] == 525


@pytest.mark.slow
def test_snapshot_svg_and_pdf(tmp_path):
    for suffix in (".svg", ".pdf"):
        out = tmp_path / f"s{suffix}"
        res, _ = run_probe("snapshot", SCENES / "figure3b.toml", "-o", out)
        assert res == {"rc": 0, "heavy": []}
        assert out.stat().st_size > 1000


@pytest.mark.slow
def test_snapshot_bad_input_is_one_line(tmp_path, eyeviz_main):
    cases = [
        [SCENES / "default.toml", "-o", tmp_path / "x.gif"],
        [tmp_path / "missing.toml", "-o", tmp_path / "x.png"],
        [SCENES / "default.toml", "-o", tmp_path / "x.png", "--scale", "-2"],
    ]
    bad = tmp_path / "bad.toml"
    bad.write_text("[eyes]\nm = 7\n")
    cases.append([bad, "-o", tmp_path / "x.png"])
    for args in cases:
        out = eyeviz_main("snapshot", *args)
        assert out.returncode == 2, out
        lines = out.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("eyeviz: error:"), out.stderr
        assert "Traceback" not in out.stderr
    assert [p.name for p in tmp_path.iterdir()] == ["bad.toml"]


@pytest.mark.slow
def test_snapshot_width_and_toggles(tmp_path, eyeviz_main):
    scene = SCENES / "default.toml"
    out = tmp_path / "d.png"
    run = eyeviz_main("snapshot", scene, "-o", out, "--width", "double")
    assert run.returncode == 0, run.stderr
    assert struct.unpack(">II", out.read_bytes()[16:24])[0] == round(7.2 * 300)
    svg = tmp_path / "bare.svg"
    run = eyeviz_main(
        "snapshot", scene, "-o", svg, "--width", "4", "--no-title", "--no-table", "--no-bitmaps"
    )
    assert run.returncode == 0, run.stderr
    text = svg.read_text()
    assert 'id="readout"' not in text and 'id="bitmaps"' not in text
    assert 'id="title"' not in text and 'width="288pt"' in text
    run = eyeviz_main("snapshot", scene, "-o", tmp_path / "x.png", "--width", "triple")
    assert run.returncode == 2 and run.stderr.count("\n") == 1 and "width" in run.stderr


@pytest.mark.slow
def test_snapshot_aspect_frames_the_view_and_bad_ones_are_refused(tmp_path, eyeviz_main):
    """--aspect sets the main view's height / width (a wide scene wastes less of the
    figure); outside [0.3, 1.6] it is refused in one line and nothing is written."""
    scene = SCENES / "figure5.toml"
    heights = {}
    for a in ("0.5", "0.86"):
        out = tmp_path / f"f{a}.png"
        run = eyeviz_main("snapshot", scene, "-o", out, "--aspect", a, "--no-table", "--no-title")
        assert run.returncode == 0, run.stderr
        heights[a] = struct.unpack(">II", out.read_bytes()[16:24])[1]
    # the same width: only the view's height changes, by (0.86 - 0.5) of the view width
    w = 3.5 * 300
    assert heights["0.86"] - heights["0.5"] > 0.25 * w
    for bad in ("0.1", "2", "nan"):
        run = eyeviz_main("snapshot", scene, "-o", tmp_path / "bad.png", "--aspect", bad)
        assert run.returncode == 2 and run.stderr.count("\n") == 1, run.stderr
        assert "aspect" in run.stderr
    assert not (tmp_path / "bad.png").exists()


@pytest.mark.slow
def test_snapshot_hostile_scenes_are_one_line(tmp_path, eyeviz_main):
    """Too many features, a feature at 1e308: a one-line refusal, no file (refused before
    any figure is made: tests/render/test_export.py counts them)."""
    many = tmp_path / "many.toml"
    rows = "".join(
        f'[[features]]\nname = "f{i}"\nx = {i}.0\ny = 1500.0\ng = 1.0\n\n' for i in range(10_001)
    )
    many.write_text(rows)
    far = tmp_path / "far.toml"
    far.write_text('[[features]]\nname = "far"\nx = 1e308\ny = 1500.0\ng = 50.0\n')
    for scene, words in ((many, "10000"), (far, "1e+308")):
        run = eyeviz_main("snapshot", scene, "-o", tmp_path / "o.png")
        assert run.returncode == 2, run.stderr
        lines = run.stderr.strip().splitlines()
        assert len(lines) == 1 and words in lines[0], run.stderr
    assert not (tmp_path / "o.png").exists()
