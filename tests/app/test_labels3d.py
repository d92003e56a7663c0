"""The 3D view's names in a real window (issue 32 item 4): each ball's and each eye's name
lies beside what it names, over no other name, ball, eye or ghost, at every preset the
issue found overprinting (top: the name under its ball; side: "eye A" over "eye B"; front
and along each eye: "behind" over "ahead"; sphere_predictions: "target" under a ghost).

Where a name is drawn is read back from VTK (its anchor through VTK's own camera, plus
the text actor's display offset, plus VTK's text size), not from the placement's answer;
the discs are the balls and eyes as VTK projects them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from eyeviz.model.scene import load

SCENES = Path(__file__).resolve().parents[2] / "eyeviz" / "assets" / "scenes"


@pytest.fixture(scope="module")
def win(qapp, tmp_path_factory):
    from eyeviz.app.window import MainWindow, make_app, make_settings

    make_app()
    w = MainWindow(
        load(SCENES / "sphere_teaching.toml"),
        None,
        settings=make_settings(tmp_path_factory.mktemp("s") / "settings.json"),
    )
    w._force_close = True
    w.resize(1280, 720)
    w.show()
    qapp.processEvents()
    w.jobs.wait()
    yield w
    w.force_close()


def _display(ren, p) -> np.ndarray:
    import vtk

    c = vtk.vtkCoordinate()
    c.SetCoordinateSystemToWorld()
    c.SetValue(*p)
    return np.array(c.GetComputedDoubleDisplayValue(ren))


def _disc(ren, centre, radius) -> tuple[float, float, float]:
    """A sphere's disc in display pixels: centre, and the radius as VTK projects a point
    on the sphere's rim across the line of sight."""
    cam = ren.GetActiveCamera()
    pos, c = np.array(cam.GetPosition()), np.asarray(centre, float)
    sight = (c - pos) / np.linalg.norm(c - pos)
    side = np.cross(sight, np.array(cam.GetViewUp()))
    side /= np.linalg.norm(side)
    d = np.linalg.norm(c - pos)
    rim = c + side * radius * d / np.sqrt(max(d * d - radius * radius, 1e-9))
    a, b = _display(ren, c), _display(ren, rim)
    return float(a[0]), float(a[1]), float(np.hypot(*(b - a)))


def _boxes(ren, labels, dpi) -> list[tuple[str, tuple[float, float, float, float]]]:
    from eyeviz.render.vtk.primitives import text_size

    out = []
    cam = ren.GetActiveCamera()
    sight = np.subtract(cam.GetFocalPoint(), cam.GetPosition())
    for lab in labels:
        if not lab.GetVisibility() or not lab.GetInput() or lab.GetTextProperty().GetOpacity() == 0:
            continue  # hidden, or its sphere is out of the view
        if np.dot(np.subtract(lab.GetPosition(), cam.GetPosition()), sight) <= 0:
            continue  # behind the camera: VTK draws nothing
        x, y = _display(ren, lab.GetPosition())
        dx, dy = lab.GetDisplayOffset()
        w, h = text_size(lab.GetTextProperty(), lab.GetInput(), dpi)
        out.append((lab.GetInput(), (x + dx, y + dy, x + dx + w, y + dy + h)))
    return out


def _hits(box, disc, slack=1.5) -> bool:
    cx, cy, r = disc
    qx, qy = min(max(cx, box[0]), box[2]), min(max(cy, box[1]), box[3])
    return float(np.hypot(cx - qx, cy - qy)) < r - slack


def _apart(a, b, slack=1.0) -> bool:
    return min(a[2], b[2]) - max(a[0], b[0]) <= slack or min(a[3], b[3]) - max(a[1], b[1]) <= slack


def _check(host, ghosts=()) -> int:
    """Assert no name overlaps another name, ball, eye or ghost; returns the names checked."""
    act = host.actors
    act.scene_ren.GetRenderWindow().Render()
    dpi = act.scene_ren.GetRenderWindow().GetDPI()
    st, surf = host.model.state, act.surface
    n = 0
    for ren, labels in ((act.scene_ren, act.balls.ball_labels), (act.eyes_ren, act.eyes.labels)):
        discs = [_disc(ren, c, surf.radius) for c in surf.centres]
        if ren is act.scene_ren:  # the close-up draws the eyes alone (and the cones' feet)
            discs += [_disc(ren, (st.x[i], st.y[i], st.z[i]), st.g[i]) for i in range(st.n)]
            discs += [_disc(ren, c, g) for c, g in ghosts]
        boxes = _boxes(ren, labels, dpi)
        w, h = ren.GetSize()
        x0, y0 = ren.GetOrigin()
        for k, (name, b) in enumerate(boxes):
            for d in discs:
                assert not _hits(b, d), (name, b, d)
            for other, b2 in boxes[k + 1 :]:
                assert _apart(b, b2), (name, other, b, b2)
            inside = x0 - 1 <= b[0] and b[2] <= x0 + w + 1 and y0 - 1 <= b[1] and b[3] <= y0 + h + 1
            assert inside, (name, b, (x0, y0, w, h))
            n += 1
    return n


@pytest.mark.parametrize("preset", ["top", "side", "front", "eye_a", "eye_b", "default"])
def test_names_cover_nothing_at_each_preset(win, qapp, preset):
    host = win.host3d
    host.set_preset(preset)
    qapp.processEvents()
    # the four balls' names and both eyes' (along an eye's axis, some are out of view)
    assert _check(host) >= (6 if preset in ("top", "side", "front", "default") else 3)


def test_target_is_not_under_a_ghost_after_a_drag(win, qapp, tmp_path):
    from eyeviz.model.predictions3d import Answer3D

    assert win.open_path(SCENES / "sphere_predictions.toml")
    host = win.host3d
    host.set_preset("default")
    win.jobs.wait()
    qapp.processEvents()
    st = host.model.state
    # the drag: the selected ball moved in the screen plane, the ghosts follow it
    host.model.select(0)
    host.model.move(0, (st.x[0] + 0.3 * st.g[0], st.y[0], st.z[0] + 0.2 * st.g[0]), "Move")
    win.jobs.wait()
    qapp.processEvents()
    preds = host.preds
    assert preds is not None
    ghosts = [((a.x, a.y, a.z), preds.g) for a in preds.ghosts()]
    assert any(isinstance(a, Answer3D) for a in preds.answers.values()) and ghosts
    # zoomed on the ball, so the ghosts are wide and over the name's default place
    cam = host.camera()
    c = np.array([st.x[0], st.y[0], st.z[0]])
    pos = np.asarray(cam.position)
    host.set_camera(type(cam)(tuple(c + (pos - c) * 12 * st.g[0] / np.linalg.norm(pos - c)),
                              tuple(c), cam.view_up, cam.view_angle))  # fmt: skip
    qapp.processEvents()
    assert _check(host, ghosts) >= 3
