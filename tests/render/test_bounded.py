"""Extreme but valid scenes render in bounded time or are refused in one line (issue 13):
huge discs become their clipped polygon, far labels are dropped, what shows is the same."""

from __future__ import annotations

import math

import numpy as np
import pytest
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Polygon, Wedge
from PIL import Image

from eyeviz import EyevizError
from eyeviz.model import scene as S
from eyeviz.render.mpl import bounded, vector
from eyeviz.render.mpl.export import export


def _area(p: np.ndarray) -> float:
    x, y = p[:, 0], p[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def test_clip_polygon_square_by_box():
    sq = np.array([(-1, -1), (3, -1), (3, 3), (-1, 3)], float)
    out = bounded.clip_polygon(sq, (0, 1, 0, 2))
    assert _area(out) == pytest.approx(2.0)
    assert len(bounded.clip_polygon(sq, (5, 6, 5, 6))) == 0


@pytest.mark.parametrize(
    ("c", "r"),
    [((0.0, 0.0), 1.0), ((0.0, -1e12 + 0.5), 1e12), ((3.0, 0.5), 2.5), ((1e6, 1e6), 1e6 * 1.41)],
)
def test_disc_in_box_area_matches_monte_carlo(c, r):
    box = (0.0, 1.0, 0.0, 1.0)
    polys = bounded.disc_in_box(c, r, box)
    area = sum(_area(p) for p in polys)
    rng = np.random.default_rng(0)
    pts = rng.random((200_000, 2))
    inside = np.hypot(pts[:, 0] - c[0], pts[:, 1] - c[1]) <= r
    assert area == pytest.approx(inside.mean(), abs=0.005)
    for p in polys:  # nothing outside the box
        assert p[:, 0].min() >= -1e-12 and p[:, 0].max() <= 1 + 1e-12


def test_wedge_in_box_is_the_sector():
    # a quarter disc of radius 1e9 around (-1e9 + 0.5, 0.5): in the unit box its edge is
    # (nearly) the line x = 0.5, and angles in [0, 90] degrees keep y >= 0.5
    c = (-1e9 + 0.5, 0.5)
    polys = bounded.disc_in_box(c, 1e9, (0.0, 1.0, 0.0, 1.0), (0.0, math.pi / 2))
    assert sum(_area(p) for p in polys) == pytest.approx(0.25, abs=1e-6)


def _assert_rasterable(fig) -> None:
    """What keeps Agg and FreeType quick, checked on the figure instead of timing a draw:
    every patch lies within a few view sizes of the figure (a disc of radius 1e12 spans
    1e11 pixels and Agg subdivides its curves by the pixel), every text is anchored within
    :data:`bounded.TEXT_REACH_PX` of it, and no path has more than a few arcs' samples."""
    w, h = fig.bbox.width, fig.bbox.height
    reach = (bounded.HUGE + 2) * max(w, h)
    for ax in fig.axes:
        for p in ax.patches:
            v = p.get_transform().transform(p.get_path().vertices)
            assert np.isfinite(v).all() and np.abs(v).max() <= reach, p.get_gid()
            assert len(v) <= 4 * bounded.ARC_SAMPLES + 16, (p.get_gid(), len(v))
    far = bounded.TEXT_REACH_PX
    for t in [*fig.texts, *(t for ax in fig.axes for t in ax.texts)]:
        x, y = t.get_transform().transform(t.get_position())
        assert -far <= x <= w + far and -far <= y <= h + far, t.get_text()[:40]


def _fig_with(*patches, texts=()):
    fig = Figure(figsize=(3, 3), dpi=100)
    ax = fig.add_axes((0.1, 0.1, 0.8, 0.8))
    ax.set_xlim(0, 10)
    ax.set_ylim(0, 10)
    for p in patches:
        ax.add_patch(p)
    for x, y, s in texts:
        ax.text(x, y, s, clip_on=True)
    return fig, ax


def test_huge_disc_replaced_far_patch_removed_far_text_dropped():
    big = Circle((5, -1e12 + 5), 1e12, facecolor="r", gid="feature-big")
    far = Circle((1e9, 1e9), 1.0, gid="feature-far")
    small = Circle((5, 5), 1.0, gid="feature-small")
    fig, ax = _fig_with(big, far, small, texts=[(1e12, 0, "far"), (5, 5, "near")])
    bounded.bound_figure(fig)
    gids = sorted(p.get_gid() for p in ax.patches)
    assert gids == ["feature-big", "feature-small"]
    new = next(p for p in ax.patches if p.get_gid() == "feature-big")
    assert isinstance(new, Polygon)
    xy = new.get_xy()
    assert np.abs(xy).max() < 20  # within the expanded view
    # the expanded view [-0.5, 10.5]^2 below the disc's edge y = 5
    assert _area(xy) == pytest.approx(11 * 5.5, rel=1e-5)
    assert [t.get_text() for t in ax.texts] == ["near"]
    _assert_rasterable(fig)  # the draw's speed: scripts/bench_bounded.py
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig).draw()


def test_the_rasterable_check_sees_an_unbounded_figure():
    """The check above fails on the figure bound_figure was not run on."""
    big = Circle((5, -1e12 + 5), 1e12, gid="feature-big")
    fig, _ = _fig_with(big, texts=[(1e12, 0, "far")])
    with pytest.raises(AssertionError, match="feature-big"):
        _assert_rasterable(fig)
    fig, _ = _fig_with(texts=[(1e12, 0, "far")])
    with pytest.raises(AssertionError, match="far"):
        _assert_rasterable(fig)


def test_unresolvable_edge_is_refused_in_one_line():
    # the edge (y = 5e-7) crosses a view 1e-6 wide; float64 resolves 1e-4 at 1e12
    fig, ax = _fig_with(Circle((5e-7, -1e12), 1e12 + 5e-7, gid="feature-x"))
    ax.set_xlim(0, 1e-6)
    ax.set_ylim(0, 1e-6)
    with pytest.raises(EyevizError, match="cannot draw feature-x") as info:
        bounded.bound_figure(fig)
    assert "\n" not in str(info.value)


def _scene(features: str, view: str, layers: str) -> S.Scene:
    return S.loads(
        f"[eyes]\nm = 6\n{features}[layers]\nshow = [{layers}]\n[view]\n{view}\n", "t.toml"
    )


ALL = '"features", "tangents", "ambiguity", "bitmaps", "readout", "bfv", "eyes", "labels"'


def test_snapshot_of_a_huge_disc_beside_the_view_is_quick_and_drawn(tmp_path):
    """The fuzz case: a disc of radius 1e12 whose label landed 1e11 pixels away
    (FreeType: raster overflow). The PNG shows the disc's colour over the whole view."""
    sc = _scene(
        '[[features]]\nname = "cc"\nx = 0.0\ny = 0.0\ng = 1e12\n',
        "center = [6235.4, 0.0]\nwidth = 8000.0",
        ALL,
    )
    out = tmp_path / "o.png"
    # what export hands to Agg: bounded (unbounded, the disc spans 1e11 pixels)
    _assert_rasterable(vector.figure(sc, dpi=vector.BASE_DPI))
    export(sc, out)
    img = np.asarray(Image.open(out).convert("RGB"))
    assert img.shape[0] > 500
    # the centre of the main view is covered by the disc: not white
    h, w, _ = img.shape
    assert img[int(h * 0.2), int(w * 0.6)].tolist() != [255, 255, 255]


def test_view_below_float_resolution_is_refused(tmp_path):
    sc = _scene("", "center = [-1e12, 0.0]\nwidth = 1e-4", '"eyes"')
    with pytest.raises(EyevizError, match=r"view width = 0.0001 cannot be drawn") as info:
        export(sc, tmp_path / "o.png")
    assert "\n" not in str(info.value)
    assert not (tmp_path / "o.png").exists()


@pytest.mark.slow
def test_tiny_view_inside_an_eye_draws_only_the_cells_it_sees(tmp_path):
    sc = S.loads(
        '[eyes]\nm = 5000\n[layers]\nshow = ["eyes", "sectors", "labels"]\n'
        "[view]\ncenter = [57.5517, 9.5885]\nwidth = 1e-2\n",
        "t.toml",
    )
    out = tmp_path / "o.svg"
    _assert_rasterable(vector.figure(sc, dpi=vector.VECTOR_DPI))
    export(sc, out)
    svg = out.read_text()
    assert 0 < svg.count('id="ommatidium-') < 100


def test_wedge_patch_huge_is_clipped():
    w = Wedge((5, -1e10), 1e10 + 5, 80, 100, gid="w")
    fig, ax = _fig_with(w)
    bounded.bound_figure(fig)
    (p,) = ax.patches
    assert isinstance(p, Polygon) and np.abs(p.get_xy()).max() < 20


def test_readout_of_extreme_values_does_not_overlap_or_overflow():
    """Distances of 1e12 and a 200-character name: the table's cells in each row are
    apart and inside the figure, the long lines cut with an ellipsis (was: run together)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from eyeviz.render.mpl import vector

    feats = "".join(
        f'[[features]]\nname = "{n}"\nx = {x!r}\ny = {y!r}\ng = {g!r}\n'
        for n, x, y, g in (
            ("$\\\\undefined$", -5525.0, -1e12, 1e6),
            ("n" * 200, 1e12, 123456789.125, 1e-6),
            ("a", 1833.46, 0.0, 1e6),
            ("exact", 1728.97, 123456789.125, 1e12),
        )
    )
    sc = _scene(feats, "center = [-4172.86, 0.0]\nwidth = 8000.0", ALL)
    fig = vector.figure(sc, dpi=100)
    renderer = FigureCanvasAgg(fig).get_renderer()
    width = fig.bbox.width
    rows: dict[str, list] = {}
    for ax in fig.axes:
        for t in ax.texts:
            gid = t.get_gid() or ""
            if not t.get_text():
                continue
            bb = t.get_window_extent(renderer)
            if gid.startswith("readout-"):
                assert bb.x1 <= width + 1 and bb.x0 >= -1, (t.get_text(), bb)
            if gid.startswith("readout-") and gid.split("-")[1].isdigit():
                rows.setdefault(gid.split("-")[2], []).append(bb)
    assert len(rows) == 4
    for boxes in rows.values():
        boxes.sort(key=lambda b: b.x0)
        for a, b in zip(boxes, boxes[1:], strict=False):
            assert a.x1 <= b.x0 + 0.5, (a, b)


def test_tick_labels_of_a_tiny_view_far_from_the_origin_differ():
    from eyeviz.render.mpl.layout import tick_format

    assert tick_format(0.0, 8000.0) == "%.0f"
    assert tick_format(-0.5, 0.5) == "%g"
    fmt = tick_format(2056.8355445, 2056.8355455)
    ticks = [fmt % v for v in (2056.835545, 2056.8355452, 2056.8355454)]
    assert len(set(ticks)) == 3, ticks
