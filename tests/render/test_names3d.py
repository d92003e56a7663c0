"""The 3D names' placement (issue 32 item 4): the pure placement, and the exported figure's
names read back from matplotlib (their drawn extents) against the balls and eyes as the
figure's camera projects them: no name over another name, a ball or an eye."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from eyeviz.model.labels3d import discs, place_boxes

SCENES = Path(__file__).resolve().parents[2] / "eyeviz" / "assets" / "scenes"


def _hit(box, disc) -> bool:
    cx, cy, r = disc
    qx, qy = min(max(cx, box[0]), box[2]), min(max(cy, box[1]), box[3])
    return float(np.hypot(cx - qx, cy - qy)) < r - 0.5


def _apart(a, b) -> bool:
    return min(a[2], b[2]) - max(a[0], b[0]) <= 0.5 or min(a[3], b[3]) - max(a[1], b[1]) <= 0.5


def test_two_balls_one_behind_the_other_get_names_apart():
    # "behind" and "ahead" on one line of sight: the same centre, one disc inside the other
    c = np.array([[200.0, 150.0], [200.0, 150.0]])
    r = np.array([40.0, 15.0])
    sizes = np.array([[60.0, 18.0], [50.0, 18.0]])
    boxes = place_boxes(c, r, sizes, np.zeros((0, 3)), (0, 0, 400, 300))
    assert _apart(boxes[0], boxes[1])
    for b in boxes:
        assert not _hit(b, (200.0, 150.0, 40.0))
        assert 0 <= b[0] and b[2] <= 400 and 0 <= b[1] and b[3] <= 300


def test_a_name_leaves_an_obstacle_and_the_edge():
    # right of the ball is the view's edge, left of it a ghost: the name goes above/below
    boxes = place_boxes(
        np.array([[380.0, 150.0]]), np.array([15.0]), np.array([[60.0, 18.0]]),
        np.array([[340.0, 150.0, 25.0]]), (0, 0, 400, 300),
    )  # fmt: skip
    b = boxes[0]
    assert not _hit(b, (380.0, 150.0, 15.0)) and not _hit(b, (340.0, 150.0, 25.0))
    assert 0 <= b[0] and b[2] <= 400


def test_a_name_with_no_place_apart_gives_way():
    # a view too small for both names (sphere_lecture's step 7 at 175 %): the first name
    # keeps its place, the second is not drawn rather than printed over it
    c = np.array([[200.0, 30.0], [120.0, 30.0]])
    r = np.array([5.0, 5.0])
    sizes = np.array([[170.0, 50.0], [170.0, 50.0]])
    args = (c, r, sizes, np.zeros((0, 3)), (0, 0, 400, 60))
    boxes = place_boxes(*args)
    assert np.isfinite(boxes[0]).all() and np.isnan(boxes[1]).all()
    crossed = place_boxes(*args, give_way=False)  # to frame: every name's least-bad place
    assert np.isfinite(crossed).all() and not _apart(crossed[0], crossed[1])


def test_behind_the_camera_is_nan():
    from eyeviz.model.camera3d import Camera3D

    cam = Camera3D((0.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), 30.0)
    c, r = discs(cam, [[0.0, 100.0, 0.0], [0.0, -100.0, 0.0]], [5.0, 5.0], 400, 300)
    assert np.allclose(c[0], (200.0, 150.0)) and np.isfinite(r[0])
    assert np.isnan(c[1]).all() and np.isnan(r[1])


@pytest.mark.parametrize(
    ("name", "view"),
    [("sphere_teaching", "top"), ("sphere_teaching", "front"), ("sphere_lecture", "side"),
     ("sphere_lecture", "top")],
)  # fmt: skip
def test_exported_names_cover_nothing(name, view):
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from eyeviz.model.camera3d import eyes_camera
    from eyeviz.model.scene import load
    from eyeviz.model.state3d import compute_state3d
    from eyeviz.render.mpl.figure3d import figure3d

    scene = load(SCENES / f"{name}.toml")
    st = compute_state3d(scene)
    fig = figure3d(scene, st, width=7.2, view=view, bitmaps=False, table=False)
    FigureCanvasAgg(fig).draw()
    rend = fig.canvas.get_renderer()
    scene_ax = next(a for a in fig.axes if a.get_gid() == "perspective-scene")
    eyes_ax = next(a for a in fig.axes if a.get_gid() == "perspective-eyes")
    bb = scene_ax.get_window_extent()
    from eyeviz.render.mpl.perspective3d import framed_camera

    to_pt = 72.0 / fig.dpi  # the figure's camera: its preset, framed for the names
    cam = framed_camera(st, scene, view, bb.width * to_pt, bb.height * to_pt)
    eb = eyes_ax.get_window_extent()
    h = abs(st.pair.h)
    ecam = eyes_camera(cam, h, st.pair.l, eb.width / eb.height)
    eyes = np.array([[-h, 0, 0, st.pair.l], [h, 0, 0, st.pair.l]])
    balls = np.array([(f.x, f.y, f.z, f.g) for f in scene.features])
    checked = 0
    for ax, c, spheres in ((scene_ax, cam, np.concatenate([balls, eyes])), (eyes_ax, ecam, eyes)):
        box = ax.get_window_extent()
        xy, rad = discs(c, spheres[:, :3], spheres[:, 3], box.width, box.height)
        dd = [
            (x + box.x0, y + box.y0, r) for (x, y), r in zip(xy, rad, strict=True) if np.isfinite(r)
        ]
        texts = [t for t in ax.texts if t.get_gid() == "name3d"]
        ext = [t.get_window_extent(rend) for t in texts]
        boxes = [(e.x0, e.y0, e.x1, e.y1) for e in ext]
        for k, b in enumerate(boxes):
            for d in dd:
                assert not _hit(b, d), (texts[k].get_text(), b, d)
            for j in range(k + 1, len(boxes)):
                assert _apart(b, boxes[j]), (texts[k].get_text(), texts[j].get_text())
        checked += len(boxes)
    assert checked == len(scene.features) + 2
