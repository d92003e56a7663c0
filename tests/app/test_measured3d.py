"""Measured eyes in the app (docs/measured.md, "In the app"): the shipped honeybee opens
in the 3D page; a real X pointer (xdotool) drags a ball and the lit facets drawn on the
eye follow -- the eye meshes' cell colours and the rendered pixels of the close-up --,
with the lit acceptance cones; one Ctrl+Z undoes the drag; an invalid eye file is refused
in one line with the open scene kept; Save writes the eye file back relative."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from PyQt5 import QtCore

from eyeviz.measured import shipped_eye
from eyeviz.model.scene import load
from eyeviz.render.vtk.primitives import read_rgb
from eyeviz.render.vtk.style import UNLIT, hex_rgb

SCENES = Path(__file__).resolve().parents[2] / "eyeviz" / "assets" / "scenes"
BEE = SCENES / "bee.toml"


def _xdo(qtbot, *args):
    subprocess.run(["xdotool", *map(str, args)], check=True)
    qtbot.wait(40)


def _pixel(win, i):
    """Global screen pixel of ball i's centre, through VTK's own camera (vtkCoordinate)."""
    import vtk

    host = win.host3d
    f = host.model.scene.features[i]
    c = vtk.vtkCoordinate()
    c.SetCoordinateSystemToWorld()
    c.SetValue(f.x, f.y, f.z)
    dx, dy = c.GetComputedDoubleDisplayValue(host.actors.scene_ren)
    h = host.view.ren_win.GetSize()[1]
    return host.view.mapToGlobal(QtCore.QPoint(round(dx), round(h - dy)))


def _mesh_rgb(host, e: int) -> np.ndarray:
    return read_rgb(host.actors.eyes.meshes[e]).copy()


def _close_up(host) -> np.ndarray:
    """The eyes' close-up as rendered (RGB rows top-down), read back from the window."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter

    host.view.ren_win.Render()
    f = vtkWindowToImageFilter()
    f.SetInput(host.view.ren_win)
    f.ReadFrontBufferOff()
    f.Update()
    img = f.GetOutput()
    w, h, _ = img.GetDimensions()
    arr = vtk_to_numpy(img.GetPointData().GetScalars()).reshape(h, w, -1)[::-1, :, :3]
    x0, _y0, x1, _y1 = host.actors.eyes_ren.GetViewport()
    return arr[:, int(x0 * w) : int(x1 * w)].astype(int)


def _count(img: np.ndarray, color: str) -> int:
    """Pixels of the ball's hue at any shade (the facets are lit by the view's lights:
    (0, 93, 146) for #0072B2): cosine > 0.998 with its RGB, and not black."""
    c = np.array(hex_rgb(color), dtype=float)
    v = img.astype(float)
    norm = np.linalg.norm(v, axis=-1)
    cos = (v @ c) / np.maximum(norm * np.linalg.norm(c), 1e-9)
    return int(((cos > 0.998) & (norm > 60)).sum())


def test_the_honeybee_opens_in_the_3d_page(make_window):
    win = make_window(load(BEE), BEE)
    host = win.host3d
    assert host.active and host.view.isVisible() and not win.plotter.isVisible()
    st = host.model.state
    assert st.facet_counts == (3187, 3187)
    meshes = host.actors.eyes.meshes
    assert [m.GetNumberOfCells() for m in meshes] == [3187, 3187]
    # every ball's lit facets are drawn in its colour (the last ball wins a shared facet)
    for e, eye in enumerate("AB"):
        rgb = _mesh_rgb(host, e)
        for i, f in enumerate(host.model.scene.features):
            later = [st.lit(j, eye) for j in range(i + 1, st.n)]
            mine = np.setdiff1d(st.lit(i, eye), np.concatenate(later) if later else [])
            assert mine.size and (rgb[mine] == hex_rgb(f.color)).all()
        unlit = np.setdiff1d(np.arange(3187), np.concatenate([st.lit(i, eye) for i in range(st.n)]))
        assert (rgb[unlit] == UNLIT).all()
    # the layer menu offers the acceptance cones, not the HEALPix predictions
    assert host.layer_actions["cones"].isVisible() and host.layer_actions["cones"].isChecked()
    assert not host.layer_actions["predictions"].isVisible()
    # the selected ball's lit cones: one per lit facet of each eye
    cones = host.actors.cones
    assert cones.cone_actor.GetVisibility()
    sel = host.model.selected
    assert np.array_equal(cones.drawn["A"], st.lit(sel, "A"))
    assert np.array_equal(cones.drawn["B"], st.lit(sel, "B"))


def test_a_real_x_pointer_drag_relights_the_eye_and_ctrl_z_undoes_it(make_window, qtbot):
    if shutil.which("xdotool") is None:
        pytest.fail("xdotool is needed for this test: apt-get install xdotool")
    sc = load(BEE)
    sc.layers.remove("cones")  # the close-up's pixels: the facets' colours, no cones over them
    win = make_window(sc, BEE)
    win.activateWindow()
    win.raise_()
    host = win.host3d
    host.set_preset("front")
    qtbot.wait(50)
    i = 1  # "mid": in the binocular field, lighting facets of both eyes
    f0 = host.model.scene.features[i]
    x0, y0, z0 = f0.x, f0.y, f0.z
    color = f0.color
    lit0 = [host.model.state.lit(i, e).copy() for e in "AB"]
    rgb0 = [_mesh_rgb(host, e) for e in (0, 1)]
    img0 = _close_up(host)
    px0 = _count(img0, color)
    assert px0 > 0  # its lit facets are seen in the close-up
    p = _pixel(win, i)
    _xdo(qtbot, "mousemove", p.x(), p.y())
    _xdo(qtbot, "mousedown", 1)
    for k in range(1, 11):
        _xdo(qtbot, "mousemove", p.x() + 12 * k, p.y())  # to the right: out of eye A's view
    _xdo(qtbot, "mouseup", 1)
    qtbot.waitUntil(lambda: win.undo_stack.count() == 1, timeout=5000)
    f = host.model.scene.features[i]
    assert f.x < x0 - 1.0 and f.y == pytest.approx(y0)  # the front view faces the bee: -x
    st = host.model.state
    lit1 = [st.lit(i, e).copy() for e in "AB"]
    assert not all(np.array_equal(a, b) for a, b in zip(lit0, lit1, strict=True))
    rgb1 = [_mesh_rgb(host, e) for e in (0, 1)]
    img1 = _close_up(host)  # the close-up as drawn now: only the facets' colours changed
    changed = np.abs(img1 - img0).sum(axis=-1) > 0
    assert changed.any() and _count(img1, color) != px0
    assert not all(np.array_equal(a, b) for a, b in zip(rgb0, rgb1, strict=True))
    for e, eye in enumerate("AB"):  # the mesh shows the new lit set, in the ball's colour
        later = [st.lit(j, eye) for j in range(i + 1, st.n)]
        mine = np.setdiff1d(lit1[e], np.concatenate(later) if later else [])
        assert (rgb1[e][mine] == hex_rgb(color)).all()
        gone = np.setdiff1d(lit0[e], np.concatenate([st.lit(j, eye) for j in range(st.n)]))
        assert (rgb1[e][gone] == UNLIT).all()
    host.model.set_layer("cones", True)  # the selected ball's cones follow it
    assert np.array_equal(host.actors.cones.drawn["A"], lit1[0])
    assert np.array_equal(host.actors.cones.drawn["B"], lit1[1])
    win.undo_stack.undo()
    _xdo(qtbot, "key", "--window", int(win.winId()), "ctrl+z")
    qtbot.waitUntil(lambda: win.undo_stack.index() == 0, timeout=3000)
    assert "cones" not in host.model.scene.layers
    back = host.model.scene.features[i]
    assert (back.x, back.y, back.z) == (x0, y0, z0)
    for e in (0, 1):
        assert np.array_equal(_mesh_rgb(host, e), rgb0[e])
    assert _count(_close_up(host), color) == pytest.approx(px0, rel=0.05, abs=3)


def test_an_invalid_eye_file_is_refused_and_the_scene_kept(make_window, tmp_path):
    win = make_window(load(BEE), BEE)
    before = win.host3d.model.scene.copy()
    bad = tmp_path / "bad.toml"
    (tmp_path / "broken.eye").write_text("0 0 0 1 0 0\n", encoding="utf-8")
    bad.write_text('[eyes]\nfile = "broken.eye"\n', encoding="utf-8")
    assert not win.open_path(bad)
    assert "eyes.file" in win.last_error and "\n" not in win.last_error
    assert win.host3d.active and win.host3d.model.scene.eyes.kind == "measured"
    assert win.host3d.model.scene == before
    missing = tmp_path / "missing.toml"
    missing.write_text('[eyes]\nfile = "nowhere.eye"\n', encoding="utf-8")
    assert not win.open_path(missing)
    assert "no such eye file" in win.last_error and len(win.host3d.model.scene.features) == 3


def test_save_writes_the_eye_file_relative(make_window, tmp_path):
    win = make_window(load(BEE), BEE)
    win.host3d.model.move(0, (0.5, 5.0, -6.0), "Nudge")
    out = tmp_path / "bee2.toml"
    assert win.save_path(out)
    text = out.read_text(encoding="utf-8")
    assert "file = " in text and "nside" not in text
    back = load(out)
    assert back.eyes.file.samefile(shipped_eye("AM_60185-real.eye"))
    assert (back.features[0].x, back.features[0].y, back.features[0].z) == (0.5, 5.0, -6.0)


def test_the_bumblebees_open_and_switch(make_window):
    win = make_window(load(SCENES / "bumblebees.toml"), SCENES / "bumblebees.toml")
    assert [m.GetNumberOfCells() for m in win.host3d.actors.eyes.meshes] == [4827, 4827]
    assert win.open_path(SCENES / "bumblebee_small.toml")
    assert [m.GetNumberOfCells() for m in win.host3d.actors.eyes.meshes] == [1889, 1889]
    assert win.open_path(SCENES / "sphere_teaching.toml")  # and back to HEALPix eyes
    assert win.host3d.actors.eyes.meshes[0].GetNumberOfCells() == 768
    assert not win.host3d.layer_actions["cones"].isVisible()
