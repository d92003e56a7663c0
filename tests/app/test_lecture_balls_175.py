"""The spherical lecture at 175 % in a 1280 x 720 window in presentation mode (issue 32,
the labels' items left open): read back from VTK in every step (the discs as VTK's camera
projects the balls and eyes, the names where their text actors are drawn, the view's own
texts' boxes),

- no ball or eye crosses the view's side note or title (the note crossed a ball's disc in
  steps 2-6: the framing kept names clear of it, not balls);
- every ball in the view is named, near its own ball: within its gap and a name's height
  of its rim, else with a leader line from the ball to it; nor nearer another ball than
  its own without one (a name that found no place gave way, leaving its ball unnamed in
  steps 7-8, and step 6 drew "below" far from its ball);
- every name keeps at least 4 px x the text scale from every ball, eye and selection ring
  (names touched their ball or ring with 0-2 px to spare in several steps).

Checked in every step of test_lecture_whole_175's walk (real keys, xdotool, into the real
window), with the other checks of the lecture at 175 %: one window and one walk for all."""

from collections import Counter

import numpy as np
from test_labels3d import _boxes, _disc
from test_lecture_names_175 import _box

from eyeviz.render.vtk.balls3d import RING


def _clearance(box, disc) -> float:
    """Pixels between a box (x0, y0, x1, y1) and a disc (cx, cy, r); < 0: they overlap."""
    cx, cy, r = disc
    qx, qy = min(max(cx, box[0]), box[2]), min(max(cy, box[1]), box[3])
    return float(np.hypot(cx - qx, cy - qy)) - r


def _box_gap(a, b) -> float:
    """Pixels between two boxes (0 where they touch or overlap)."""
    dx = max(a[0] - b[2], b[0] - a[2], 0.0)
    dy = max(a[1] - b[3], b[1] - a[3], 0.0)
    return float(np.hypot(dx, dy))


def _leader_to(segments, disc, box, origin) -> bool:
    """Whether a leader line runs from ``disc``'s rim to ``box`` (display pixels; the
    segments are in the viewport's, offset by ``origin``)."""
    for x0, y0, x1, y1 in segments:
        a = (x0 + origin[0], y0 + origin[1])
        e = (x1 + origin[0], y1 + origin[1])
        near_ball = abs(float(np.hypot(a[0] - disc[0], a[1] - disc[1])) - disc[2]) <= 12.0
        near_box = _box_gap((e[0], e[1], e[0], e[1]), box) <= 12.0
        if near_ball and near_box:
            return True
    return False


def check_balls(win, step: int, tally: Counter) -> None:
    """One step of the walk at 175 % (test_lecture_whole_175): balls and eyes clear of the
    view's texts, every ball named near its ball (or led to its name), 4 px x scale apart."""
    scale = win.presenter.scale
    host = win.host3d
    act = host.actors
    ren = act.scene_ren
    dpi = ren.GetRenderWindow().GetDPI()
    ren.GetRenderWindow().Render()
    st, surf = host.model.state, act.surface
    ox, oy = ren.GetOrigin()
    w, h = ren.GetSize()
    balls = [_disc(ren, (st.x[i], st.y[i], st.z[i]), st.g[i]) for i in range(st.n)]
    eyes = [_disc(ren, c, surf.radius) for c in surf.centres]
    # the view's own texts, in display pixels
    texts = []
    for actor in (host.side.actor, act.title):
        if actor.GetVisibility() and actor.GetInput():
            x0, y0, x1, y1 = _box(actor, ren)
            texts.append((actor.GetInput(), (x0 + ox, y0 + oy, x1 + ox, y1 + oy)))
    assert texts, step + 1  # the side note at least
    shows = host.model.scene.shows("features")
    for k, d in enumerate(balls + eyes):
        for text, tb in texts:
            # a ball's disc (or an eye's) over the note or the title
            assert _clearance(tb, d) > 0.0, (step + 1, k, text, d, tb)
    if not shows:
        return
    labels = act.balls.ball_labels[: st.n]
    drawn = dict(_boxes(ren, labels, dpi))
    segments = act.leaders.segments
    sel = host.model.selected
    for i, lab in enumerate(labels):
        cx, cy, r = balls[i]
        if not (ox <= cx <= ox + w and oy <= cy <= oy + h) or not lab.GetVisibility():
            continue
        name = lab.GetInput()
        # every ball in the view named: none gives way
        assert name in drawn, (step + 1, name, sorted(drawn))
        box = drawn[name]
        bh = box[3] - box[1]
        own = (cx, cy, r * RING + 1.0) if i == sel else (cx, cy, r)  # the ring's line
        # a margin of 4 px at 100 %, scaled with the text
        for k, d in enumerate(balls + eyes):
            dd = own if k == i else ((d[0], d[1], d[2] * RING + 1.0) if k == sel else d)
            gap = _clearance(box, dd)
            assert gap >= 4.0 * scale, (step + 1, name, k, round(gap, 2))
        # near its own ball, or a leader line to it
        rim = _clearance(box, (cx, cy, r))
        others = [_clearance(box, d) for k, d in enumerate(balls) if k != i]
        nearer = bool(others) and min(others) < rim - 1.0
        led = _leader_to(segments, (cx, cy, r), box, (ox, oy))
        if rim > 4.0 * scale + 2.0 + bh or nearer:
            assert led, (step + 1, name, round(rim, 1), nearer)
        else:
            tally["balls_near"] += 1
        tally["balls_named"] += 1


def balls_checked(tally: Counter) -> None:
    named, near = tally["balls_named"], tally["balls_near"]
    assert named >= 13 and near >= 8, (named, near)  # names were shown and checked
