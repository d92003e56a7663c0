"""The 3D Mollweide bitmaps outline the selected ball's lit facets and follow the selection
(Tab in the 3D view), repainting by blitting over the kept background, not redrawing."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
from mouse import x_focus

from eyeviz.app.panels.bitmaps3d import Bitmaps3DPanel
from eyeviz.model.scene import load
from eyeviz.model.state3d import compute_state3d

SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"


def _panel(qtbot):
    p = Bitmaps3DPanel()
    qtbot.addWidget(p)
    p.resize(420, 560)
    p.show()
    qtbot.waitExposed(p)
    return p


def _dark_in_patch(panel, st, ball: int, eye: str = "A") -> int:
    """Ink-dark pixels of the canvas in the box around ball ``ball``'s lit patch."""
    ax = panel.axes[eye]
    ratio = panel.canvas.devicePixelRatioF()
    pts = []
    for pix in st.lit(ball, eye):
        x, y = panel.map_point(eye, int(pix))
        if abs(x) < 2.4:  # away from the map's edge (a patch across it is split)
            dx, dy = ax.transData.transform((x, y))
            pts.append((dx / ratio, panel.canvas.height() - dy / ratio))
    assert pts
    xy = np.array(pts)
    x0, y0 = np.floor(xy.min(axis=0) - 14).astype(int)
    x1, y1 = np.ceil(xy.max(axis=0) + 14).astype(int)
    img = panel.canvas.grab().toImage()
    n = 0
    for x in range(max(x0, 0), min(x1, img.width())):
        for y in range(max(y0, 0), min(y1, img.height())):
            c = img.pixel(x, y)
            if max((c >> 16) & 255, (c >> 8) & 255, c & 255) < 70:
                n += 1
    return n


def test_the_selected_balls_facets_are_outlined_and_follow_the_selection(qtbot):
    sc = load(SCENES / "sphere_teaching.toml")  # nside 8: facets many pixels wide
    st = compute_state3d(sc)
    panel = _panel(qtbot)
    panel.set_state(st, sc, 0)
    qtbot.waitUntil(lambda: panel._bg is not None, timeout=5000)
    draws: list[object] = []
    panel.canvas.mpl_connect("draw_event", draws.append)
    for eye in "AB":  # the outline holds ball 0's lit facets (all of them), no other
        assert panel.outlined(eye) >= st.lit(0, eye).size > 0
    assert "'ahead' outlined" in panel.counts.text()
    dark0 = (_dark_in_patch(panel, st, 0), _dark_in_patch(panel, st, 1))
    verts0 = panel._halo["A"].get_paths()[0].vertices.copy()
    # another ball selected: its patch is outlined instead, by a blit (no full redraw)
    panel.set_state(st, sc, 1)
    assert panel.selected == 1 and "'up right' outlined" in panel.counts.text()
    for eye in "AB":
        assert panel.outlined(eye) >= st.lit(1, eye).size > 0
    verts1 = panel._halo["A"].get_paths()[0].vertices
    assert verts1.shape != verts0.shape or not np.allclose(verts1, verts0)
    dark1 = (_dark_in_patch(panel, st, 0), _dark_in_patch(panel, st, 1))
    assert dark1[1] > dark0[1] + 20, (dark0, dark1)  # ball 1's border turned ink
    assert dark1[0] < dark0[0] - 20, (dark0, dark1)  # ball 0's went back to its colours
    assert draws == []
    # no selection (or one past the balls): no outline
    for sel in (None, len(sc.features)):
        panel.set_state(st, sc, sel)
        assert panel.selected is None and panel.outlined("A") == 0
        assert "outlined" not in panel.counts.text()
    assert _dark_in_patch(panel, st, 1) < dark1[1] - 20
    # the same state and selection again: nothing is repainted; a new selection is
    panel.set_state(st, sc, 1)
    repaints: list[int] = []
    real = panel._repaint
    panel._repaint = lambda: (repaints.append(1), real())[1]
    panel.set_state(st, sc, 1)
    assert repaints == []
    panel.set_state(st, sc, 2)
    assert repaints == [1] and panel.outlined("A") >= st.lit(2, "A").size


def test_the_outline_follows_the_ball_at_nside_180(qtbot):
    """Sub-pixel facets: the outline is a ring of ink pixels around the selected ball's lit
    pixels (painted, not stroked); it moves with the ball."""
    sc = load(SCENES / "sphere_paper.toml")
    st = compute_state3d(sc)
    panel = _panel(qtbot)
    panel.set_state(st, sc, 0)
    qtbot.waitUntil(lambda: panel._bg is not None, timeout=5000)
    assert panel.outlined("A") >= st.lit(0, "A").size > 0

    def ring(state, scene) -> np.ndarray:
        """Columns of the ink pixels the selection adds to map A."""
        ink = []
        for sel in (None, 0):
            panel.set_state(state, scene, sel)
            buf = np.asarray(panel.canvas.buffer_rgba())[..., :3].astype(int)
            r0, r1, c0, c1 = panel._raster["A"].box
            ink.append(buf[r0:r1, c0:c1].max(axis=-1) < 70)
        return np.nonzero(ink[1] & ~ink[0])[1]

    before = ring(st, sc)
    assert before.size > 0 and _dark_in_patch(panel, st, 0) > 0
    moved = sc.copy()  # the selected ball moves: its outline goes with it
    moved.features[0].x += 0.05 * moved.features[0].y
    st2 = compute_state3d(moved)
    assert not np.array_equal(st2.lit(0, "A"), st.lit(0, "A"))
    after = ring(st2, moved)
    assert panel.outlined("A") >= st2.lit(0, "A").size
    assert before.mean() < after.mean()  # to the eye's right on its map


def test_tab_in_the_3d_view_moves_the_outline_to_the_next_ball(make_window, qtbot):
    win = make_window(load(SCENES / "sphere_teaching.toml"))
    host = win.host3d
    assert host.active and host.model.selected == 0
    bm = host.bitmaps
    qtbot.waitUntil(lambda: bm._bg is not None, timeout=5000)
    assert bm.selected == 0
    before = bm._halo["A"].get_paths()[0].vertices.copy()
    x_focus(win, host.view)
    subprocess.run(["xdotool", "key", "--delay", "40", "Tab"], check=True)
    qtbot.waitUntil(lambda: host.model.selected == 1, timeout=5000)
    qtbot.waitUntil(lambda: bm.selected == 1, timeout=5000)
    st = host.model.state
    assert bm.outlined("A") >= st.lit(1, "A").size > 0
    after = bm._halo["A"].get_paths()[0].vertices
    assert after.shape != before.shape or not np.allclose(after, before)
    assert "'up right' outlined" in bm.counts.text()
    assert host.view.hasFocus()  # Tab stayed in the view (no focus change)
