"""`eyeviz snapshot --min-font` for spherical scenes (issue 32.12): the SVG's every text
at least that size (grey text included), the readout's cells apart at the raised size,
and the journal widths taken as for the planar figures."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

SCENES = Path(__file__).resolve().parents[2] / "eyeviz" / "assets" / "scenes"


@pytest.mark.parametrize("width", ["single", "double"])
def test_svg_has_no_text_below_the_minimum(tmp_path, width, eyeviz_main):
    out = tmp_path / "f.svg"
    scene = SCENES / "sphere_teaching.toml"  # in this process: the SVG is the point
    r = eyeviz_main("snapshot", scene, "-o", out, "--min-font", "8", "--width", width)
    assert r.returncode == 0, r.stderr
    svg = out.read_text()
    sizes = [float(v) for v in re.findall(r"font-size: ([0-9.]+)px", svg)]
    assert len(sizes) > 30  # the title, captions, names, maps, table
    assert min(sizes) >= 8.0
    w_in = float(re.search(r'<svg[^>]* width="([0-9.]+)pt"', svg).group(1)) / 72.0
    assert w_in == pytest.approx(3.5 if width == "single" else 7.2, abs=0.01)
    for grey in re.findall(r'font-size: ([0-9.]+)px[^"]*fill: #7a7a7a', svg):
        assert float(grey) >= 8.0


def test_raised_table_cells_stay_apart():
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from eyeviz.model.scene import load
    from eyeviz.render.mpl.figure3d import figure3d

    fig = figure3d(load(SCENES / "sphere_teaching.toml"), width=3.5, min_font=8)
    FigureCanvasAgg(fig).draw()
    rend = fig.canvas.get_renderer()
    ax = next(a for a in fig.axes if a.get_gid() == "readout")
    boxes = [t.get_window_extent(rend) for t in ax.texts]
    assert all(t.get_fontsize() >= 8 for t in ax.texts) and len(boxes) == 5 * 9
    for i, a in enumerate(boxes):
        assert a.x1 <= ax.get_window_extent().x1 + 1  # nothing cut at the right
        for b in boxes[i + 1 :]:
            apart = (
                min(a.x1, b.x1) - max(a.x0, b.x0) <= 0.5 or min(a.y1, b.y1) - max(a.y0, b.y0) <= 0.5
            )
            assert apart, (a, b)
