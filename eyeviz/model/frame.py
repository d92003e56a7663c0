"""One Frame: every derived drawing quantity of a scene, for every renderer (issue 9 item 2).

The Frame's parts (dataclasses) and the small pure helpers they use live in
:mod:`eyeviz.model.frame_parts` and are re-exported here; this module builds them.

``build_frame(scene, state=None, predictor=None, rect=...)`` runs the geometry once and
returns a :class:`Frame`; the matplotlib figure (and the VTK view) only *draw* a Frame.
It fills the readout every layer shares, then runs the frame builder of each layer the
scene shows, as the layer table (:mod:`eyeviz.model.layers`) names them: ``build_eyes``,
``build_bfv``, ... below; each reads a :class:`FrameInputs` and fills its part.
Qt-, VTK- and matplotlib-free; only what the scene's layers need is computed (a drag frame
with the default layers costs the intervals plus a few array operations).

Fields of :class:`Frame` (``None`` / empty when no layer needs them):

- ``pair`` (EyePair), ``layers`` (set of str), ``rect`` (x0, x1, y0, y1): the view rectangle
  the BFV wedge is clipped to; ``state`` (:class:`eyeviz.model.state.SceneState`).
- ``names``, ``colors`` (lists), ``x``, ``y``, ``g`` (arrays, one per feature).
- ``palette``: the distinct feature colours, in first-use order.
- ``eyes``: two :class:`EyeFrame` (A, B): ``center``, ``owner`` (feature index lighting
  each ommatidium, -1 unlit; the last feature wins), ``color_index`` (0 unlit, else
  1 + index into ``palette``), ``runs`` (starts, stops exclusive, color index: maximal runs
  of equal colour for merged drawing and the bitmap strips), ``l``, ``m`` and
  ``rim(k)``: the rim vertices at j*gamma (Figure 2, Eq. 6) of every k-th ommatidium and
  ``pooled_owner(k)``: the owner of each run of k ommatidia (the app's level of detail).
- ``intervals``: {"A": (L, R), "B": (L, R)} per feature (Prop. 2, ``EyePair.intervals``).
- ``bfv``: :class:`BFVFrame`: ``psi`` (Eq. 15), ``theta`` (Eq. 16), ``polygon`` the wedge
  clipped to ``rect`` (an (k, 2) array; empty when the wedge misses the rectangle) and the
  two edge segments ``edges`` ((x0, y0, x1, y1) from the origin to the rectangle's border).
- ``tangents``: list of :class:`TangentFrame` (feature i, eye, center, r_E, phi_E,
  ``alpha`` = asin(g / r_E) (Prop. 2, Fig. 3b), ``length`` = sqrt(r_E^2 - g^2) and
  ``ends`` the two tangent points (2, 2)); none for an eye inside a disc.
- ``sectors``: list of :class:`SectorFrame` (feature i, eye, center, L, R, ``reach``,
  ``rays`` the sector boundary indices k (angles k*gamma, Eq. 8, 11): L..R+1, or only L and
  R+1 when the run is 24 cells or longer) and ``ends`` their far points at ``reach``;
  whole-eye runs are omitted.
- readout arrays ``r, phi, rA, phiA, rB, phiB`` (polar about O, A, B; angles in rad),
  ``in_bfv``, ``vis_a``, ``vis_b``, ``in_domain`` (BFV and seen by both),
  ``out_of_domain`` (greyed features: the predictions layer is on and not in domain).
- ``predictions``: {estimator: :class:`PredictionFrame` (r_hat, phi_hat, x_hat, y_hat, dr,
  dr_pct, dphi_deg arrays, NaN outside the domain) or a one-line reason str}.
- ``ambiguity``: {feature index: dict(polygon, bounded, r_range, phi_range, g_range) or
  None (the disc covers an eye centre)}.
- ``posterior``: {feature index: :class:`eyeviz.model.posterior.Posterior` (the limit's
  posterior over centres, every g) or None (none: the prior cannot make the bitmaps)}.
  Both cost ~6-9 ms a feature, so a Frame holds them for the first :data:`MAX_REGIONS`
  features at most (the app asks for its selected feature only); ``regions_left_out``
  counts the rest, which an exported figure notes ("… and N more without ...", issue 25).
- ``trajectory``: :class:`TrajectoryPath` (points in the BFV and each estimator's accuracy)
  or None; ``trajectory_error``: why there is none.
- ``labels``: :class:`LabelFrame` anchors (text, x, y, kind, feature) of the ``labels``
  layer: the eyes A, B and the origin O under them, each feature's name up-right of its
  disc (the app's view places them at these points; the exported figure lays its own out).
- ``parts``: {layer name: part} of layers registered outside this module.

It is over 400 lines because this docstring lists every field of the Frame (the renderers'
contract) and it holds one builder per shipped layer; the parts and helpers are already in
:mod:`eyeviz.model.frame_parts`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from eyeviz.core.geometry import EyePair, intervals_to_bitmap
from eyeviz.model.frame_parts import (
    EYE_LABEL_DROP,
    FEATURE_LABEL_OFFSET,
    WIDE_SECTOR,
    BFVFrame,
    EyeFrame,
    Frame,
    LabelFrame,
    PredictionFrame,
    SectorFrame,
    TangentFrame,
    TrajectoryPath,
    clip_wedge,
    errors,
    rim_points,
    runs,
    view_rect,
)
from eyeviz.model.layers import needs_of, ordered, resolve
from eyeviz.model.predictor import Predictor, scene_predictions
from eyeviz.model.scene import Scene, Trajectory
from eyeviz.model.state import SceneState, compute_state, owners

__all__ = [
    "BFVFrame",
    "EyeFrame",
    "Frame",
    "FrameInputs",
    "LabelFrame",
    "PredictionFrame",
    "SectorFrame",
    "TangentFrame",
    "TrajectoryPath",
    "ambiguity_of",
    "build_ambiguity",
    "build_bfv",
    "build_eyes",
    "build_frame",
    "build_labels",
    "build_posterior",
    "build_predictions",
    "build_sectors",
    "build_tangents",
    "build_trajectory",
    "clip_wedge",
    "rim_points",
    "errors",
    "runs",
    "state_for",
    "trajectory_path",
    "view_rect",
    "EYE_LABEL_DROP",
    "FEATURE_LABEL_OFFSET",
    "MAX_REGIONS",
    "WIDE_SECTOR",
]

#: The most features whose ambiguity region and posterior one Frame computes (scene order;
#: issue 25: a 10^4-feature scene would spend ~90 s on them; a figure draws 40 at most).
MAX_REGIONS = 40

# --- derived quantities (formerly eyeviz.model.derived) ----------------------------------


def ambiguity_of(
    pair: EyePair, x: float, y: float, g: float, box: tuple[float, float, float, float] | None
) -> dict | None:
    """The ambiguity region of one feature (eyeviz.core.ambiguity) with its ranges, or None
    when the feature covers an eye centre (no polygon then)."""
    from eyeviz.core.ambiguity import ambiguity_radius_range, ambiguity_region

    try:
        reg = ambiguity_region(pair, x, y, g, box=box)
        g_range = ambiguity_radius_range(pair, x, y, g, box=box)
    except (ValueError, ArithmeticError):
        return None
    return {
        "polygon": reg.polygon,
        "bounded": reg.bounded,
        "r_range": reg.distance_range(),
        "phi_range": reg.azimuth_range(),
        "g_range": g_range,
    }


def trajectory_path(
    pair: EyePair,
    traj: Trajectory,
    estimators: list[str],
    predictor: Predictor | None,
    n: int = 240,
    stop: float = 6000.0,
) -> TrajectoryPath:
    """Points along ``traj`` (eyeviz.model.trajectories) where the feature is in the BFV, with
    AD and DD accuracy (100 % - APE, Section 6, Figure 15) per estimator at each point.
    ValueError (one line) when the trajectory never enters the BFV."""
    from eyeviz.model import trajectories as tr

    if traj.kind == "horizontal":
        x, y = tr.horizontal(traj.distance, traj.g, n, h=pair.h, l=pair.l)
        axis, label = x, f"x along y = {traj.distance:g}"
    elif traj.kind == "circular":
        x, y = tr.circular(traj.distance, traj.g, n, h=pair.h, l=pair.l)
        axis, label = np.degrees(np.arctan2(y, x)), f"φ (°) on r = {traj.distance:g}"
    elif traj.kind == "vertical":
        x, y = tr.vertical(
            traj.g, n, start=traj.distance, stop=max(stop, 2 * traj.distance), h=pair.h, l=pair.l
        )
        axis, label = y, "y along x = 0"
    else:
        raise ValueError(
            f"trajectory kind must be horizontal, circular or vertical, got {traj.kind!r}"
        )
    acc: dict[str, tuple[np.ndarray, np.ndarray] | str] = {}
    if predictor is not None and estimators:
        m = pair.m
        LA, RA, LB, RB = pair.intervals(x, y, np.full_like(x, traj.g))
        oa = intervals_to_bitmap(LA, RA, m, m // 2)
        ob = intervals_to_bitmap(LB, RB, m, m // 2)
        r, phi = np.hypot(x, y), np.arctan2(y, x)
        for name in estimators:
            res = predictor.predict_bitmaps(name, oa, ob, pair)
            if isinstance(res, str):
                acc[name] = res
                continue
            r_hat, phi_hat = res
            ad = 100.0 - 100.0 * np.abs(phi_hat - phi) / phi
            dd = 100.0 - 100.0 * np.abs(r_hat - r) / r
            acc[name] = (ad, dd)
    return TrajectoryPath(traj.kind, x, y, float(traj.g), np.asarray(axis), label, acc)


# --- building ----------------------------------------------------------------------------


#: The state's field that holds each need of :data:`eyeviz.model.layers.NEEDS`.
_NEED_FIELD = {"intervals": "LA", "owners": "owner_a", "readout": "r"}


def state_for(scene: Scene, state: SceneState | None) -> SceneState:
    """``state`` when it holds what the scene's layers need (the layer table), else
    ``compute_state(scene)``."""
    if state is None:
        return compute_state(scene)
    for need in needs_of(scene.layers):
        if getattr(state, _NEED_FIELD[need]) is None:
            return compute_state(scene)
    return state


@dataclass
class FrameInputs:
    """What a layer's frame builder (:data:`eyeviz.model.layers.LayerSpec.frame`) reads.

    ``box`` is the view rectangle (x0, x1, y0, y1); ``teach`` the features the per-feature
    teaching layers draw (all, or the app's selection); ``predictor``, ``predictions``,
    ``ambiguity`` and ``trajectory`` are :func:`build_frame`'s arguments of those names.
    """

    scene: Scene
    state: SceneState
    pair: EyePair
    box: tuple[float, float, float, float]
    teach: list[int]
    predictor: Predictor | None = None
    predictions: dict | None = None
    ambiguity: dict[int, dict | None] | None = None
    trajectory: TrajectoryPath | None = None
    named: list[int] | None = None  # the features the labels layer names (None: all)


def _polar(st: SceneState) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(rA, phiA, rB, phiB); ValueError when the state has no readout (a state_for bug)."""
    rA, phiA, rB, phiB = st.rA, st.phiA, st.rB, st.phiB
    if rA is None or phiA is None or rB is None or phiB is None:
        raise ValueError("this state has no polar coordinates about the eyes")
    return rA, phiA, rB, phiB


# --- one builder per layer (named in eyeviz.model.layers.LAYERS) -------------------------


def build_eyes(fr: Frame, inp: FrameInputs) -> None:
    """``eyes`` and ``bitmaps``: each eye's :class:`EyeFrame` (owners, colour runs, rim)."""
    if fr.eyes:  # the other of the two layers made them already
        return
    pair, st = inp.pair, inp.state
    uniq = {c: i + 1 for i, c in enumerate(fr.palette)}
    lut = np.array([0] + [uniq[c] for c in fr.colors], dtype=np.int64)
    for name, center, owner, L, R in (
        ("A", pair.centers[0], st.owner_a, st.LA, st.RA),
        ("B", pair.centers[1], st.owner_b, st.LB, st.RB),
    ):
        if owner is None:
            if L is not None and R is not None:
                owner = owners(L, R, pair.m)
            else:
                owner = np.full(pair.m, -1, np.int64)
        fr.eyes.append(EyeFrame(name, center, owner, lut, pair.l, pair.m))


def build_bfv(fr: Frame, inp: FrameInputs) -> None:
    """``bfv``: psi (Eq. 15), theta (Eq. 16) and the wedge clipped to the view rectangle."""
    fr.bfv = BFVFrame(inp.pair.psi, inp.pair.theta, inp.box)


def build_tangents(fr: Frame, inp: FrameInputs) -> None:
    """``tangents``: from each eye centre to each taught feature's disc (Prop. 2, Fig. 3b)."""
    pair, st = inp.pair, inp.state
    rA, phiA, rB, phiB = _polar(st)
    for i in inp.teach:
        g = float(st.g[i])
        for name, center, rE, phE in (
            ("A", pair.centers[0], float(rA[i]), float(phiA[i])),
            ("B", pair.centers[1], float(rB[i]), float(phiB[i])),
        ):
            if not rE > g:
                continue
            alpha = math.asin(g / rE)
            t = math.sqrt(rE * rE - g * g)
            ang = np.array([phE - alpha, phE + alpha])
            ends = np.column_stack([center[0] + t * np.cos(ang), center[1] + t * np.sin(ang)])
            fr.tangents.append(TangentFrame(i, name, center, rE, phE, alpha, t, ends))


def build_sectors(fr: Frame, inp: FrameInputs) -> None:
    """``sectors``: the boundary rays k*gamma of each taught feature's lit run (Eq. 8, 11)."""
    pair, st = inp.pair, inp.state
    m = pair.m
    LA, RA, LB, RB = st.intervals()
    rA, _, rB, _ = _polar(st)
    for i in inp.teach:
        g = float(st.g[i])
        for name, center, Li, Ri, rE in (
            ("A", pair.centers[0], LA[i], RA[i], rA[i]),
            ("B", pair.centers[1], LB[i], RB[i], rB[i]),
        ):
            L, R = int(Li), int(Ri)
            if R - L >= m - 1 or R < L:
                continue
            rays = list(range(L, R + 2)) if R - L < WIDE_SECTOR else [L, R + 1]
            reach = float(rE) + 1.6 * g
            t = np.asarray(rays, dtype=np.float64) * pair.gamma
            ends = np.column_stack([center[0] + reach * np.cos(t), center[1] + reach * np.sin(t)])
            fr.sectors.append(SectorFrame(i, name, center, L, R, reach, rays, ends))


def build_labels(fr: Frame, inp: FrameInputs) -> None:
    """``labels``: A, B and O under the eyes; each feature's name up-right of its disc."""
    pair, st = inp.pair, inp.state
    y = -EYE_LABEL_DROP * pair.l
    fr.labels = [
        LabelFrame("A", -pair.h, y, "eye"),
        LabelFrame("B", pair.h, y, "eye"),
        LabelFrame("O", 0.0, y, "eye"),
    ]
    if "features" in fr.layers:
        fs = inp.scene.features
        rows = np.arange(len(fs))
        if inp.named is not None:
            rows = np.array([i for i in inp.named if 0 <= i < len(fs)], dtype=np.intp)
        d = FEATURE_LABEL_OFFSET * st.g[rows]
        xs, ys = (st.x[rows] + d).tolist(), (st.y[rows] + d).tolist()
        fr.labels += [
            LabelFrame(fs[i].name, x, y_, "feature", i)
            for i, x, y_ in zip(rows.tolist(), xs, ys, strict=True)
        ]


def build_predictions(fr: Frame, inp: FrameInputs) -> None:
    """``predictions``: each estimator's :class:`PredictionFrame` or its one-line reason,
    from :func:`eyeviz.model.predictor.scene_predictions` (the one place a scene's
    predictions are computed) unless :func:`build_frame` was given them; features outside
    the estimators' domain are marked ``out_of_domain`` (drawn grey)."""
    st, scene = inp.state, inp.scene
    if not fr.n:
        return
    if fr.in_domain is not None:
        fr.out_of_domain = ~fr.in_domain
    if st.r is None or st.phi is None:
        raise ValueError("this state has no polar coordinates")
    given = inp.predictions
    if given is None:
        given = scene_predictions(scene, st, inp.predictor)
    for name in scene.estimators:
        res = given.get(name, "no prediction")
        if isinstance(res, str):
            fr.predictions[name] = res
            continue
        r_hat, phi_hat = (np.asarray(v, dtype=np.float64) for v in res)
        with np.errstate(invalid="ignore", divide="ignore"):
            dr = r_hat - st.r
            dphi = np.degrees(np.remainder(phi_hat - st.phi + math.pi, 2 * math.pi) - math.pi)
            fr.predictions[name] = PredictionFrame(
                r_hat,
                phi_hat,
                r_hat * np.cos(phi_hat),
                r_hat * np.sin(phi_hat),
                dr,
                100.0 * dr / st.r,
                dphi,
            )


def build_ambiguity(fr: Frame, inp: FrameInputs) -> None:
    """``ambiguity``: each feature's region (the given ones if any), bounded by the view
    rectangle widened by its width on every side."""
    n = fr.n
    if inp.ambiguity is not None:
        fr.ambiguity = {i: a for i, a in inp.ambiguity.items() if 0 <= i < n}
        return
    x0, x1, y0, y1 = inp.box
    w = x1 - x0
    box = (x0 - w, x1 + w, y0 - w, y1 + w)
    fs = inp.scene.features
    fr.regions_left_out = max(fr.regions_left_out, len(fs) - MAX_REGIONS)
    for i, f in enumerate(fs[:MAX_REGIONS]):
        fr.ambiguity[i] = ambiguity_of(inp.pair, f.x, f.y, f.g, box)


def build_posterior(fr: Frame, inp: FrameInputs) -> None:
    """``posterior``: each taught feature's posterior over centres (eyeviz.model.posterior;
    cached per key), None where it has none (an empty key, or a feature the intervals
    cannot describe)."""
    from eyeviz.core.domain import Domain
    from eyeviz.model.posterior import posterior_for_key

    st = inp.state
    if st.LA is None or st.RA is None or st.LB is None or st.RB is None or not inp.teach:
        return
    dom = Domain.from_eyes(inp.pair)
    fr.regions_left_out = max(fr.regions_left_out, len(inp.teach) - MAX_REGIONS)
    for i in inp.teach[:MAX_REGIONS]:
        key = tuple(int(v[i]) for v in (st.LA, st.RA, st.LB, st.RB))
        try:
            p = posterior_for_key(key, dom)
        except (ValueError, ArithmeticError):
            p = None
        fr.posterior[i] = None if p is None or p.empty else p


def build_trajectory(fr: Frame, inp: FrameInputs) -> None:
    """``trajectory``: the given path, or the scene's (points only), or why there is none."""
    traj = inp.scene.trajectory
    if inp.trajectory is not None:
        fr.trajectory = inp.trajectory
    elif traj is not None:
        try:
            stop = max(traj.distance, inp.box[3])
            fr.trajectory = trajectory_path(inp.pair, traj, [], None, n=400, stop=stop)
        except ValueError as exc:
            fr.trajectory_error = str(exc).splitlines()[0]


# --- building ----------------------------------------------------------------------------


def build_frame(
    scene: Scene,
    state: SceneState | None = None,
    predictor: Predictor | None = None,
    *,
    rect: tuple[float, float, float, float] | None = None,
    predictions: dict | None = None,
    only: int | None = None,
    ambiguity: dict[int, dict | None] | None = None,
    trajectory: TrajectoryPath | None = None,
    named: list[int] | None = None,
) -> Frame:
    """The :class:`Frame` of ``scene`` for its layers: the readout every layer shares,
    then the frame builder of each layer shown (the layer table,
    :data:`eyeviz.model.layers.LAYERS`).

    ``rect`` is the view rectangle (x0, x1, y0, y1) the BFV wedge is clipped to and the
    ambiguity regions are bounded by (default: the scene's view at the export's aspect).
    ``predictions`` (estimator -> (r_hat, phi_hat) or a reason) skips the estimators;
    otherwise ``predictor`` (made when None) answers, only if the predictions layer is on.
    ``only`` limits the per-feature teaching layers (tangents, sectors, posterior) to one
    feature (the app's selection). ``ambiguity`` ({feature: region or None}, e.g. the app
    model's cached region) and ``trajectory`` (a :class:`TrajectoryPath` already made) are
    taken as given instead of being computed. ``named`` limits the features' name labels
    to those features (the app's view, which names only its selection among many: no
    10^4 label objects per drag frame).
    """
    st = state_for(scene, state)
    pair = st.pair
    lay = set(scene.layers)
    box: tuple[float, float, float, float] = (
        view_rect(scene)
        if rect is None
        else (float(rect[0]), float(rect[1]), float(rect[2]), float(rect[3]))
    )
    colors = [f.color for f in scene.features]
    fr = Frame(
        pair=pair,
        layers=lay,
        rect=box,
        state=st,
        names=[f.name for f in scene.features],
        colors=colors,
        x=st.x,
        y=st.y,
        g=st.g,
        palette=list(dict.fromkeys(colors)),
    )
    n = st.n
    if st.LA is not None:
        LA, RA, LB, RB = st.intervals()
        fr.intervals = {"A": (LA, RA), "B": (LB, RB)}
        fr.vis_a, fr.vis_b = st.vis_a, st.vis_b
    if st.r is not None:
        fr.r, fr.phi, fr.rA, fr.phiA, fr.rB, fr.phiB = (
            st.r,
            st.phi,
            st.rA,
            st.phiA,
            st.rB,
            st.phiB,
        )
        fr.in_bfv = st.in_bfv
    if fr.in_bfv is not None and fr.vis_a is not None:
        fr.in_domain = st.in_domain()
    fr.out_of_domain = np.zeros(n, bool)
    teach = list(range(n)) if only is None else [only] if 0 <= only < n else []
    inp = FrameInputs(
        scene, st, pair, box, teach, predictor, predictions, ambiguity, trajectory, named
    )
    for spec in ordered("frame", lay):
        resolve(spec.frame)(fr, inp)
    return fr
