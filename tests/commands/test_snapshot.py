"""`eyeviz snapshot`: headless, light (no torch/Qt/VTK), one-line errors."""

import json
import struct
import subprocess
import sys
from pathlib import Path

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


def test_snapshot_svg_and_pdf(tmp_path):
    for suffix in (".svg", ".pdf"):
        out = tmp_path / f"s{suffix}"
        res, _ = run_probe("snapshot", SCENES / "figure3b.toml", "-o", out)
        assert res == {"rc": 0, "heavy": []}
        assert out.stat().st_size > 1000


def test_snapshot_bad_input_is_one_line(tmp_path):
    exe = [sys.executable, "-m", "eyeviz", "snapshot"]
    cases = [
        [SCENES / "default.toml", "-o", tmp_path / "x.gif"],
        [tmp_path / "missing.toml", "-o", tmp_path / "x.png"],
        [SCENES / "default.toml", "-o", tmp_path / "x.png", "--scale", "-2"],
    ]
    bad = tmp_path / "bad.toml"
    bad.write_text("[eyes]\nm = 7\n")
    cases.append([bad, "-o", tmp_path / "x.png"])
    for args in cases:
        out = subprocess.run(
            [*exe, *map(str, args)], capture_output=True, text=True, timeout=120, cwd=ROOT
        )
        assert out.returncode == 2, out
        lines = out.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("eyeviz: error:"), out.stderr
        assert "Traceback" not in out.stderr
    assert [p.name for p in tmp_path.iterdir()] == ["bad.toml"]
