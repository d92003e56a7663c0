"""export(): format by suffix, PNG scale, transparent background, PDF that renders,
atomic writes (an interrupted export leaves no file and keeps an existing one)."""

import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure

from eyeviz import EyevizError
from eyeviz.model import scene as scene_mod
from eyeviz.render.mpl.export import export

SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"


@pytest.fixture(scope="module")
def default_scene():
    return scene_mod.load(SCENES / "default.toml")


def png_size(path) -> tuple[int, int]:
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


def read_png(path) -> np.ndarray:
    from matplotlib.image import imread

    return imread(path)


def test_png_scale_doubles_pixels(tmp_path, default_scene):
    a = export(default_scene, tmp_path / "a.png")
    b = export(default_scene, tmp_path / "b.png", scale=2)
    wa, ha = png_size(a)
    wb, hb = png_size(b)
    assert wa == 1050  # 3.5 in at 300 dpi
    assert (wb, hb) == (2 * wa, 2 * ha)


def test_png_shows_the_scene(tmp_path, default_scene):
    img = read_png(export(default_scene, tmp_path / "a.png"))
    rgb = (img[..., :3] * 255).round().astype(int)
    assert img.shape[2] in (3, 4) and (img[..., 3] == 1).all() if img.shape[2] == 4 else True
    for f in default_scene.features:  # every feature's colour is there (rim or lit cells)
        want = np.array([int(f.color[i : i + 2], 16) for i in (1, 3, 5)])
        assert (np.abs(rgb - want).sum(axis=2) < 30).sum() > 20, f.name
    assert rgb.std() > 20


def test_png_transparent(tmp_path, default_scene):
    img = read_png(export(default_scene, tmp_path / "t.png", transparent=True))
    assert img.shape[2] == 4
    assert img[0, 0, 3] == 0  # the corner: no white ground
    assert (img[..., 3] > 0.9).sum() > 1000  # the scene itself is opaque


def test_pdf_renders_and_is_not_blank(tmp_path, default_scene):
    pdf = export(default_scene, tmp_path / "f.pdf")
    data = pdf.read_bytes()
    assert data.startswith(b"%PDF")
    assert b"/Type3" not in data and b"FontFile2" in data  # TrueType (fonttype 42) text
    subprocess.run(
        ["pdftoppm", "-r", "60", "-png", "-singlefile", str(pdf), str(tmp_path / "render")],
        check=True,
        timeout=60,
    )
    img = read_png(tmp_path / "render.png")
    rgb = (img[..., :3] * 255).round().astype(int)
    assert rgb.std() > 20
    blue = np.array([0x00, 0x72, 0xB2])  # the "far" feature
    assert (np.abs(rgb - blue).sum(axis=2) < 40).sum() > 10


def test_svg_written(tmp_path, default_scene):
    import xml.etree.ElementTree as ET

    svg = export(default_scene, tmp_path / "f.SVG")
    root = ET.parse(svg).getroot()
    assert root.tag.endswith("svg")


def test_unknown_suffix_and_bad_scale(tmp_path, default_scene):
    with pytest.raises(EyevizError, match=r"\.gif.*use \.png, \.svg or \.pdf") as exc:
        export(default_scene, tmp_path / "f.gif")
    assert "\n" not in str(exc.value)
    with pytest.raises(EyevizError, match="no suffix"):
        export(default_scene, tmp_path / "figure")
    for bad in (0, -1, float("nan"), "big"):
        with pytest.raises(EyevizError, match="scale"):
            export(default_scene, tmp_path / "f.png", scale=bad)
    with pytest.raises(EyevizError, match="does not exist"):
        export(default_scene, tmp_path / "nodir" / "f.png")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("exc", [KeyboardInterrupt, RuntimeError])
@pytest.mark.parametrize("suffix", [".png", ".pdf"])
def test_interrupted_export_leaves_no_file(tmp_path, default_scene, monkeypatch, exc, suffix):
    real = Figure.savefig

    def half_then_fail(self, fname, *args, **kw):
        real(self, fname, *args, **kw)  # the whole file is there ...
        with open(fname, "r+b") as fh:  # ... then cut short, as by Ctrl-C mid-write
            fh.truncate(100)
        raise exc("interrupted mid-save")

    monkeypatch.setattr(Figure, "savefig", half_then_fail)
    target = tmp_path / f"fig{suffix}"
    with pytest.raises(exc):
        export(default_scene, target)
    assert list(tmp_path.iterdir()) == []
    # an existing figure is kept unchanged
    target.write_bytes(b"previous figure")
    with pytest.raises(exc):
        export(default_scene, target)
    assert target.read_bytes() == b"previous figure"
    assert [p.name for p in tmp_path.iterdir()] == [target.name]
