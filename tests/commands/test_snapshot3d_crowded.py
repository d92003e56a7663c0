"""`eyeviz snapshot` of a crowded spherical scene (issue 32 item 4): nine balls packed
round a target, names of several lengths, at each view preset. The figure the command
saved (PNG and SVG) is read back: each ball's name, drawn where the placement the app
shares (:func:`eyeviz.model.labels3d.place_named`) put it, overlaps no other name, no
ball and no eye, keeps a gap from every ball and eye, and lies near its own ball or has a
leader line to it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from eyeviz.cli import main
from eyeviz.model.labels3d import discs
from eyeviz.model.scene import load
from eyeviz.model.state3d import compute_state3d

NAMES = ["target", "a", "left wing", "b2", "right", "up high", "low", "far one", "x"]
COLOURS = ["#D55E00", "#0072B2", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000",
           "#F0E442", "#999999"]  # fmt: skip


def _crowded(path) -> None:
    lines = ['title = "crowded"\n\n[eyes]\nh = 40.0\nl = 20.0\nnside = 8\n']
    for k, (name, col) in enumerate(zip(NAMES, COLOURS, strict=True)):
        if k == 0:
            x, y, z = 0.0, 300.0, 0.0
        else:  # a ring round the target, in and out of the plane
            a = 2 * math.pi * (k - 1) / (len(NAMES) - 1)
            x, y, z = 110 * math.cos(a), 300.0 + 60 * math.sin(2 * a), 90 * math.sin(a)
        g = 40.0 if k == 0 else 22.0 + 3 * (k % 3)
        lines.append(
            f'[[features]]\nname = "{name}"\nx = {x:.3f}\ny = {y:.3f}\nz = {z:.3f}\n'
            f'g = {g}\ncolor = "{col}"\n'
        )
    lines.append('[layers]\nshow = ["eyes", "features", "labels", "plane"]\n')
    path.write_text("\n".join(lines))


def _hit(box, disc, gap=0.0) -> float:
    cx, cy, r = disc
    qx, qy = min(max(cx, box[0]), box[2]), min(max(cy, box[1]), box[3])
    return float(np.hypot(cx - qx, cy - qy)) - r


def _apart(a, b) -> bool:
    return min(a[2], b[2]) - max(a[0], b[0]) <= 0.5 or min(a[3], b[3]) - max(a[1], b[1]) <= 0.5


@pytest.mark.parametrize("view", ["default", "top", "front", "side"])
@pytest.mark.parametrize("fmt", ["png", "svg"])
def test_crowded_snapshot_names_cover_nothing(view, fmt, tmp_path, monkeypatch, capsys):
    scene_file = tmp_path / "crowded.toml"
    _crowded(scene_file)
    saved: list[Figure] = []
    real = Figure.savefig

    def keep(fig, *args, **kwargs):  # the figure the command writes, kept to read back
        saved.append(fig)
        return real(fig, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", keep)
    out = tmp_path / f"crowded.{fmt}"
    assert main(["snapshot", str(scene_file), "-o", str(out), "--view", view]) == 0
    assert out.exists() and out.stat().st_size > 1000
    assert len(saved) == 1
    fig = saved[0]
    FigureCanvasAgg(fig).draw()  # its texts' extents as drawn
    rend = fig.canvas.get_renderer()
    scene = load(scene_file)
    st = compute_state3d(scene)
    ax = next(a for a in fig.axes if a.get_gid() == "perspective-scene")
    from eyeviz.render.mpl.perspective3d import framed_camera

    bb = ax.get_window_extent()
    to_pt = 72.0 / fig.dpi  # the figure's camera: its preset, framed for the names
    cam = framed_camera(st, scene, view, bb.width * to_pt, bb.height * to_pt)
    spheres = np.array(
        [(f.x, f.y, f.z, f.g) for f in scene.features]
        + [(-st.pair.h, 0.0, 0.0, st.pair.l), (st.pair.h, 0.0, 0.0, st.pair.l)]
    )
    xy, rad = discs(cam, spheres[:, :3], spheres[:, 3], bb.width, bb.height)
    dd = [(x + bb.x0, y + bb.y0, r) for (x, y), r in zip(xy, rad, strict=True)]
    texts = [t for t in ax.texts if t.get_gid() == "name3d"]
    names = [t.get_text() for t in texts]
    boxes = [tuple(t.get_window_extent(rend).extents) for t in texts]
    leaders = [ln for ln in ax.lines if ln.get_gid() == "leader3d"]
    in_view = [
        k for k, d in enumerate(dd[: len(NAMES)])
        if np.isfinite(d).all() and bb.x0 <= d[0] <= bb.x1 and bb.y0 <= d[1] <= bb.y1
    ]  # fmt: skip
    assert len(in_view) >= 6, (view, in_view)
    # every ball in the view named (a name gives way only where no place is left)
    assert len(texts) >= len(in_view) - 1, (view, names)
    px_per_pt = fig.dpi / 72.0
    for k, (name, b) in enumerate(zip(names, boxes, strict=True)):
        for j, d in enumerate(dd):
            if np.isfinite(d).all():
                # no ball or eye under a name, and a point of gap at least
                assert _hit(b, d) >= 1.0 * px_per_pt, (view, name, j, _hit(b, d))
        for other, b2 in zip(names[k + 1 :], boxes[k + 1 :], strict=True):
            assert _apart(b, b2), (view, name, other, b, b2)
        # near its own ball (within three of its heights), or a leader line to it
        own = dd[NAMES.index(name)]
        if _hit(b, own) > 3.0 * (b[3] - b[1]):
            assert leaders, (view, name, _hit(b, own))
    capsys.readouterr()
