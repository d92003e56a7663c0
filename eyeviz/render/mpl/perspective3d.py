"""The 3D view drawn from the model, as matplotlib polygons: the vector twin of the VTK view
(:mod:`eyeviz.render.vtk.scene3d`; issue 22 item 6, docs/spherical.md).

The view has the VTK view's two parts side by side: the eyes close up on the left
(:func:`eyeviz.model.camera3d.eyes_camera`, from the camera's direction) and the scene on
the right, through the camera. Everything is projected by
:func:`eyeviz.model.camera3d.project` (VTK's perspective projection, so the polygons land
where the VTK render puts them) into normalised device coordinates, [-1, 1] across each
part. The geometry is :mod:`eyeviz.model.shapes3d`'s, the arrays the VTK painters draw:

- the eyes' facets (layer "eyes"): up to nside ``FULL_MAX_NSIDE`` every facet, else the
  unlit sphere at nside 16 (at nside 4 where an eye is drawn a few pixels wide) and the
  lit facets at the scene's nside over it; lit facets in their ball's colour (a later
  ball wins);
- the balls (layer "features"), spheres in their colours, named (layer "labels");
- the tangent cones from each eye centre to each ball (layer "tangents"), translucent,
  from the eye's surface on (the VTK cone starts at the centre, hidden by the eye), in
  the close-up only their first ``EYE_CONE`` eye radii;
- the plane z = 0 with a grid and each eye's equator (layer "plane");
- the boundary of the 3D binocular field of view (layer "bfv"), translucent.

Closed surfaces (eyes, balls) lose their back faces (culled: the face's outward normal
points away from the camera); open ones (cones, plane, field) keep both sides, as VTK draws
them. Every polygon is then painted far to near by the distance of its centroid from the
camera (painter's algorithm) in one collection; long surfaces are cut in bands so that
their pieces sort with what lies beside them. Polygons that reach behind the camera's
near plane or lie wholly outside the view are left out. Shading is a headlight: a face's
colour times ambient + diffuse cos(angle to the camera), with the VTK actors' ambient and
diffuse.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PolyCollection
from matplotlib.colors import to_rgba, to_rgba_array
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

from eyeviz.core import healpix
from eyeviz.model import shapes3d
from eyeviz.model.camera3d import Camera3D, eyes_camera, project
from eyeviz.model.facets3d import surface_of
from eyeviz.model.labels3d import Named3D, discs, fit_labels, leaders, place_named
from eyeviz.model.predictions3d import Predictions3D
from eyeviz.model.scene import Scene
from eyeviz.model.state3d import SceneState3D
from eyeviz.render.mpl.ghosts3d import draw_ghosts
from eyeviz.render.mpl.style import SMALL, pt, short
from eyeviz.render.style3d import (
    BALL_LIGHT,
    BFV_OPACITY,
    BFV_RGB,
    CONE_OPACITY,
    EDGE_RGB,
    EDGES_MAX_NSIDE,
    EYE_CONE,
    EYE_LIGHT,
    EYES_FRACTION,
    GRID_OPACITY,
    INK_RGB,
    INSET_RGB,
    PLANE_OPACITY,
    PLANE_RGB,
    UNLIT_RGB,
    field_reach,
    split_viewports,
)

__all__ = [
    "EYES_FRACTION",
    "VIEW_LAYERS",
    "Polygons",
    "default_camera",
    "framed_camera",
    "draw_panel",
    "draw_view",
    "scene_aspect",
    "scene_polygons",
    "split_viewports",
]

# The looks the VTK view shares (eyeviz/render/style3d.py: one place for both painters;
# this module must not import VTK, snapshot runs without it);
# tests/render/test_figure3d_vtk.py compares the two pictures.
UNLIT_RGBA = (*UNLIT_RGB, 1.0)
EDGE_RGBA = (*EDGE_RGB, 1.0)
BFV_RGBA = (*BFV_RGB, BFV_OPACITY)
PLANE_RGBA = (*PLANE_RGB, PLANE_OPACITY)
GRID_RGBA = (*PLANE_RGB, GRID_OPACITY)
CONE_ALPHA = CONE_OPACITY
INSET_RGBA = (*INSET_RGB, 1.0)
INK_RGBA = (*INK_RGB, 1.0)
SEAM = 0.3  # pt: facets outlined in their own colour, so no seam shows between them
LINE_PIECES = 24  # a grid line of the plane is cut in this many pieces to sort
#: The balls are HEALPix spheres of this nside (192 facets, the front ~96 drawn).
BALL_NSIDE = 4
CONE_RES = 32  # points around a tangent cone
CONE_BANDS = 8  # pieces along it
#: An eye whose radius is drawn below this fraction of the view's half height (a few
#: pixels) has its unlit sphere drawn at nside 4: the file stays small, the picture alike.
SMALL_EYE = 0.04
#: Layers the view draws (the others are drawn elsewhere or not at all).
VIEW_LAYERS = ("eyes", "features", "tangents", "plane", "bfv")


@dataclass
class Polygons:
    """Polygons in normalised device coordinates, in painting order (far first)."""

    verts: list[np.ndarray]
    face: np.ndarray  # (n, 4) rgba
    edge: np.ndarray  # (n, 4) rgba
    width: np.ndarray  # (n,) line widths, points
    depth: np.ndarray  # (n,) centroid distance from the camera
    kind: np.ndarray  # (n,) "eye", "lit", "ball", "cone", "plane", "bfv", "line"

    def __len__(self) -> int:
        return len(self.verts)


def default_camera(state: SceneState3D, view: str = "default", aspect: float = 1.0) -> Camera3D:
    """The view's camera for a preset ``view`` (:data:`eyeviz.model.camera3d.PRESETS`)
    framing the eyes and the balls in a scene part ``aspect`` (width / height) wide: the
    app's and the VTK PNG's (:func:`eyeviz.model.shapes3d.view_camera`)."""
    return shapes3d.view_camera(state, view, aspect)


def scene_aspect(w: float, h: float) -> float:
    """The scene part's width / height in a ``w`` x ``h`` view (:func:`split_viewports`)."""
    _, (x0, _y0, x1, _y1) = split_viewports(w, h)
    return (x1 - x0) * w / h


class _Batch:
    """Polygons of one kind with the same number of vertices, in 3D."""

    def __init__(self, pts, face, kind: str, *, centre=None, edge=None, width=0.0, light=None):
        self.pts = np.asarray(pts, np.float64)  # (n, k, 3)
        n = self.pts.shape[0]
        self.face = np.broadcast_to(np.asarray(face, np.float64), (n, 4)).copy()
        self.edge = (
            self.face.copy()
            if edge is None
            else np.broadcast_to(np.asarray(edge, np.float64), (n, 4)).copy()
        )
        self.width = np.full(n, float(width))
        self.kind = kind
        self.centre = centre  # a closed surface's centre (3,): back faces culled
        self.light = light  # (ambient, diffuse) or None: drawn unshaded


def _reach(state: SceneState3D) -> float:
    return field_reach(shapes3d.scene_extent(state))  # as far as the VTK view


def _eye_batches(state: SceneState3D, scene: Scene, cam: Camera3D) -> list[_Batch]:
    """Each eye's facets (see the module docstring); an eye drawn smaller than
    :data:`SMALL_EYE` (its radius, a fraction of the view's half height) has its unlit
    sphere drawn at nside 4 under its lit facets, which keep the scene's nside. A
    measured pair's: :func:`_measured_eye_batches`."""
    if state.pair.kind == "measured":  # the mathematics differs: Voronoi patches about
        return _measured_eye_batches(state, scene)  # its axes, not a sphere of HEALPix rings
    pair = state.healpix
    n = pair.nside
    colors = to_rgba_array([f.color for f in scene.features]) if scene.features else None
    half = math.tan(math.radians(cam.view_angle) / 2.0)
    out = []
    for e, cx in enumerate((-pair.h, pair.h)):
        c = np.array([cx, 0.0, 0.0])
        dist = float(np.linalg.norm(np.asarray(cam.position) - c))
        small = pair.l < SMALL_EYE * dist * half
        if n <= shapes3d.FULL_MAX_NSIDE and not small:  # every facet, by its owner
            own = shapes3d.facet_owner(state, "AB"[e])
            pts = c + pair.l * healpix.boundaries(n, np.arange(pair.npix), shapes3d.edge_step(n))
            face = np.tile(np.asarray(UNLIT_RGBA), (pts.shape[0], 1))
            lit = own >= 0
            if colors is not None and lit.any():
                face[lit] = colors[own[lit]]
            edged = n <= EDGES_MAX_NSIDE
            out.append(
                _Batch(pts, face, "eye", centre=c, edge=EDGE_RGBA if edged else None,
                       width=0.25 if edged else SEAM, light=EYE_LIGHT)
            )  # fmt: skip
            continue
        vn = 4 if small else shapes3d.view_nside(n)
        pts = c + pair.l * healpix.boundaries(vn, np.arange(healpix.npix(vn)), 2)
        out.append(_Batch(pts, UNLIT_RGBA, "eye", centre=c, width=SEAM, light=EYE_LIGHT))
        pix, owner = shapes3d.lit_owner(state, "AB"[e])  # memory in the lit count only
        if pix.size and colors is not None:
            lp = c + pair.l * healpix.boundaries(n, pix, 1)
            out.append(
                _Batch(lp, colors[owner], "lit", centre=c, width=SEAM / 2, light=EYE_LIGHT)
            )  # a thinner seam: a patch of facets under a pixel wide would grow
    return out


def _measured_eye_batches(state: SceneState3D, scene: Scene) -> list[_Batch]:
    """A measured pair's facets as the VTK view draws them
    (:class:`eyeviz.model.facets3d.MeasuredSurface`): each ommatidium a hexagon at its
    lens, lit ones in their ball's colour (a later ball wins), no edges (a facet is a few
    pixels across); back faces culled about the eye's lens centroid."""
    surf = surface_of(state.pair)
    colors = to_rgba_array([f.color for f in scene.features]) if scene.features else None
    out = []
    for e, eye in enumerate("AB"):
        pts, faces = surf.mesh(e)
        k = int(faces[0])  # every cell a hexagon: [6, i0 .. i5] per facet
        poly = pts[faces.reshape(-1, k + 1)[:, 1:]]
        face = np.tile(np.asarray(UNLIT_RGBA), (poly.shape[0], 1))
        own = shapes3d.facet_owner(state, eye)
        lit = own >= 0
        if colors is not None and lit.any():
            face[lit] = colors[own[lit]]
        out.append(
            _Batch(poly, face, "eye", centre=np.asarray(surf.centres[e], np.float64),
                   width=SEAM, light=EYE_LIGHT)
        )  # fmt: skip
    return out


def _centres(state: SceneState3D) -> list[np.ndarray]:
    """The eyes' centres (the tangent cones' apexes, the labels' places): (-+h, 0, 0),
    or a measured pair's lens centroids."""
    return [np.asarray(c, np.float64) for c in surface_of(state.pair).centres]


def _ball_batches(scene: Scene) -> list[_Batch]:
    unit = healpix.boundaries(BALL_NSIDE, np.arange(healpix.npix(BALL_NSIDE)), 2)
    out = []
    for f in scene.features:
        c = np.array([f.x, f.y, f.z], np.float64)
        out.append(
            _Batch(c + f.g * unit, to_rgba(f.color), "ball", centre=c, width=SEAM,
                   light=BALL_LIGHT)
        )  # fmt: skip
    return out


def _cone_batches(state: SceneState3D, scene: Scene, length: float | None) -> list[_Batch]:
    """Each eye's tangent cone to each ball (:func:`eyeviz.model.shapes3d.tangent_cone`)
    from the eye's surface to the circle where it touches the ball (to ``length`` from
    the apex when given), cut in bands along its length, shortest at the eye."""
    pair = state.pair
    out = []
    # band ends in geometric steps: the first pieces short, so they sort in front of the
    # eye's facets they start from
    s = (np.geomspace(1.0, 2.0**CONE_BANDS, CONE_BANDS + 1) - 1.0) / (2.0**CONE_BANDS - 1.0)
    nxt = np.roll(np.arange(CONE_RES), -1)
    for a in _centres(state):
        for f in scene.features:
            cone = shapes3d.tangent_cone(a, (f.x, f.y, f.z), f.g, CONE_RES)
            if length is not None:
                cone = shapes3d.shorten_cones(cone, CONE_RES, length)
            gen = cone[1:] - a  # generators, apex to circle
            size = np.linalg.norm(gen, axis=-1)
            if not np.all(size > pair.l):  # degenerate, or ending inside the eye
                continue
            t0 = pair.l / size  # the eye's surface along each generator
            t = t0[None, :] + s[:, None] * (1.0 - t0[None, :])  # (bands + 1, res)
            rings = a + t[..., None] * gen[None]
            quads = np.stack(
                [rings[:-1], rings[:-1][:, nxt], rings[1:][:, nxt], rings[1:]], axis=2
            ).reshape(-1, 4, 3)
            rgba = list(to_rgba(f.color))
            rgba[3] = CONE_ALPHA
            out.append(_Batch(quads, rgba, "cone", width=0.0))
    return out


def _bfv_batches(state: SceneState3D) -> list[_Batch]:
    """The field's boundary (:func:`eyeviz.model.shapes3d.bfv_cones`), its triangles from
    the origin cut in bands (finer near the eyes)."""
    pair = state.pair
    pts, faces = shapes3d.bfv_cones(pair.h, pair.l, _reach(state))
    tri = faces.reshape(-1, 4)[:, 1:]
    apex, p1, p2 = pts[tri[:, 0]], pts[tri[:, 1]], pts[tri[:, 2]]
    s = np.concatenate([[0.0], np.geomspace(2.0 * pair.h / _reach(state), 1.0, 10)])
    s = s[:, None, None]
    r1, r2 = apex + s * (p1 - apex), apex + s * (p2 - apex)
    quads = np.stack([r1[:-1], r2[:-1], r2[1:], r1[1:]], axis=2).reshape(-1, 4, 3)
    return [_Batch(quads, BFV_RGBA, "bfv", width=0.0)]


#: At most this many fine tile lines across the eyes (h / l = 1e300 made np.arange ask
#: for 1e301 of them: "Maximum allowed size exceeded", issue 36); beyond it, 13 about
#: each eye only.
MAX_FINE_LINES = 256


def _fine_lines(h: float, l: float) -> tuple[np.ndarray, np.ndarray]:  # noqa: E741
    """x and y of the fine tile lines, a quarter of an eye radius apart, about the eyes."""
    if (2 * h + 3 * l) / (l / 4) <= MAX_FINE_LINES:
        return np.arange(-h - 1.5 * l, h + 1.5 * l, l / 4), np.arange(-1.5 * l, 1.5 * l, l / 4)
    about = np.linspace(-1.5 * l, 1.5 * l, 13)
    return np.concatenate([-h + about, h + about]), about


def _plane(state: SceneState3D) -> tuple[list[_Batch], np.ndarray]:
    """The plane z = 0 as the VTK view draws it (:func:`eyeviz.model.shapes3d.plane_z0`
    over [-0.8, 0.8] x [-0.2, 1] times the reach) in tiles (12 across, a quarter of an eye
    radius about the eyes, so that the tiles inside an eye sort behind its face), and its
    grid segments (k, 2, 3)."""
    pair = state.pair
    r = _reach(state)
    x0, x1, y0, y1 = -0.8 * r, 0.8 * r, -0.2 * r, r
    corners, segs = shapes3d.plane_z0(x0, x1, y0, y1)
    fine_x, fine_y = _fine_lines(pair.h, pair.l)
    xs = np.unique(np.clip(np.concatenate([np.linspace(x0, x1, 13), fine_x]), x0, x1))
    ys = np.unique(np.clip(np.concatenate([np.linspace(y0, y1, 13), fine_y]), y0, y1))
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    q = np.stack([gx, gy, np.zeros_like(gx)], axis=-1)
    quads = np.stack([q[:-1, :-1], q[1:, :-1], q[1:, 1:], q[:-1, 1:]], axis=2).reshape(-1, 4, 3)
    return [_Batch(quads, PLANE_RGBA, "plane", width=0.0)], segs


def _equators(state: SceneState3D) -> np.ndarray:
    """Each eye's equator just outside the eye (k, 2, 3 segments): the planar eye."""
    pair = state.pair
    t = np.linspace(0.0, 2.0 * math.pi, 121)
    r = pair.l * 1.012
    out = []
    for cx in (-pair.h, pair.h):
        ring = np.column_stack([cx + r * np.cos(t), r * np.sin(t), 0 * t])
        out.append(np.stack([ring[:-1], ring[1:]], axis=1))
    return np.concatenate(out)


def _lines(segs: np.ndarray, rgba, lw: float, pieces: int = 1) -> _Batch:
    """Segments (k, 2, 3) as painted items (each cut in ``pieces``): an outline only, so a
    line passes behind what is nearer, as in the VTK view."""
    t = np.linspace(0.0, 1.0, pieces + 1)[None, :, None]
    pts = segs[:, :1] + t * (segs[:, 1:] - segs[:, :1])  # (k, pieces + 1, 3)
    cut = np.stack([pts[:, :-1], pts[:, 1:]], axis=2).reshape(-1, 2, 3)
    return _Batch(cut, (0.0, 0.0, 0.0, 0.0), "line", edge=rgba, width=lw)


def scene_polygons(
    state: SceneState3D,
    scene: Scene,
    cam: Camera3D,
    aspect: float,
    part: str = "scene",
    layers=None,
) -> Polygons:
    """The polygons of one part of the view (``"scene"`` or the ``"eyes"`` close-up)
    through ``cam`` for a viewport of ``aspect`` = width / height, culled, clipped to the
    view and sorted far to near (see the module docstring). ``layers`` (default: the
    scene's) picks the parts among :data:`VIEW_LAYERS`."""
    shown = set(scene.layers if layers is None else layers)
    batches: list[_Batch] = []
    # mathematics: only HEALPix eyes are spheres with tangent cones (its BFV) and equators
    healpix_eyes = state.pair.kind == "spherical"
    if "bfv" in shown and part == "scene" and healpix_eyes:  # as VTK: not in the close-up
        batches += _bfv_batches(state)
    if "plane" in shown and part == "scene":
        tiles, grid = _plane(state)
        batches += [*tiles, _lines(grid, GRID_RGBA, 0.4, LINE_PIECES)]
    if "plane" in shown and "eyes" in shown and healpix_eyes:
        batches.append(_lines(_equators(state), INK_RGBA, 0.8))
    if "eyes" in shown and state.lit_a is not None:
        batches += _eye_batches(state, scene, cam)
    if "features" in shown and part == "scene":
        batches += _ball_batches(scene)
    if "tangents" in shown:
        batches += _cone_batches(state, scene, None if part == "scene" else EYE_CONE * state.pair.l)
    return _project(batches, cam, aspect, state.pair.l)


def _project(batches: list[_Batch], cam: Camera3D, aspect: float, l: float) -> Polygons:
    cam_pos = np.asarray(cam.position, np.float64)
    dist = float(np.linalg.norm(cam_pos - np.asarray(cam.focal_point, np.float64)))
    near = 1e-3 * dist
    verts: list[np.ndarray] = []
    faces, edges, widths, depths, kinds = [], [], [], [], []
    for b in batches:
        if b.pts.shape[0] == 0:
            continue
        mid = b.pts.mean(axis=1)
        to_cam = cam_pos - mid
        to_cam /= np.linalg.norm(to_cam, axis=-1, keepdims=True)
        if b.centre is not None:  # a closed surface: back faces culled
            normal = mid - b.centre
            with np.errstate(divide="ignore", invalid="ignore"):  # an eye of l = 1e-300:
                normal /= np.linalg.norm(normal, axis=-1, keepdims=True)  # NaN, culled
            keep = (to_cam * normal).sum(axis=-1) > 0
        else:
            normal = None
            keep = np.ones(mid.shape[0], bool)
        xy, depth = project(cam, b.pts, aspect)
        keep &= depth.min(axis=1) > near
        lo, hi = xy.min(axis=1), xy.max(axis=1)
        keep &= np.all(hi > -1.0, axis=1) & np.all(lo < 1.0, axis=1)
        idx = np.flatnonzero(keep)
        if idx.size == 0:
            continue
        face, edge = b.face[idx], b.edge[idx]
        if b.light is not None and normal is not None:  # headlight shading
            cos = np.abs((normal[idx] * to_cam[idx]).sum(axis=-1))
            k = np.minimum(b.light[0] + b.light[1] * cos, 1.0)[:, None]
            same = np.all(edge == face, axis=-1)
            face = face.copy()
            face[:, :3] *= k
            edge = edge.copy()
            edge[same, :3] = face[same, :3]
        d = np.linalg.norm(mid[idx] - cam_pos, axis=-1)
        if b.kind in ("lit", "line"):  # over the sphere they lie on (lit facets, equators)
            d = d - 0.15 * l
        verts.extend(xy[idx])
        faces.append(face)
        edges.append(edge)
        widths.append(b.width[idx])
        depths.append(d)
        kinds.append(np.full(idx.size, b.kind))
    if not verts:
        z4 = np.zeros((0, 4))
        return Polygons([], z4, z4, np.zeros(0), np.zeros(0), np.zeros(0, "<U5"))
    depth = np.concatenate(depths)
    order = np.argsort(-depth, kind="stable")  # far first
    return Polygons(
        [verts[i] for i in order],
        np.concatenate(faces)[order],
        np.concatenate(edges)[order],
        np.concatenate(widths)[order],
        depth[order],
        np.concatenate(kinds)[order],
    )


def draw_view(
    ax: Axes,
    state: SceneState3D,
    scene: Scene,
    cam: Camera3D,
    aspect: float,
    part: str = "scene",
    layers=None,
    *,
    geometry: bool = True,
    predictions: Predictions3D | None = None,
) -> PolyCollection | None:
    """One part of the view through ``cam`` on ``ax``, whose box must have width /
    height = ``aspect``: one collection of polygons and lines (the plane's grid and the
    equators, layer "plane") in painting order, the names (layer "labels") over them;
    limits [-1, 1] x [-1, 1], no axis. ``geometry`` False draws the names only (over the
    VTK render of the same view, :func:`draw_panel` ``image``)."""
    shown = set(scene.layers if layers is None else layers)
    coll = None
    if geometry:
        polys = scene_polygons(state, scene, cam, aspect, part, layers)
        coll = PolyCollection(
            polys.verts, facecolors=polys.face, edgecolors=polys.edge, linewidths=polys.width
        )
        coll.set_gid(f"view-{part}")
        ax.add_collection(coll, autolim=False)
    if "labels" in shown:
        _labels(ax, state, scene, cam, aspect, part, shown, predictions)
    ax.set_xlim(-1.0, 1.0)
    ax.set_ylim(-1.0, 1.0)
    ax.set_axis_off()
    return coll


def _named(state, scene, part, shown, predictions=None):
    """The names of view part ``part`` ("eyes": the eyes', "scene": the balls') as
    (texts, colours, :class:`Named3D`), their boxes' sizes in points at the figure's name
    size; None where the part names nothing."""
    size = pt(SMALL + 1)  # raised by --min-font: the boxes placed are the drawn ones
    eyes = np.array([(*c, state.pair.l) for c in _centres(state)], float)
    feats = scene.features if "features" in shown else []
    balls = np.array([(f.x, f.y, f.z, f.g) for f in feats], float).reshape(-1, 4)
    if part == "eyes" and "eyes" in shown:
        texts, cols = ["eye A", "eye B"], [INK_RGBA, INK_RGBA]
        named = Named3D(eyes[:, :3], eyes[:, 3], _text_sizes(texts, size), eyes[:0], below=True)
    elif part == "scene" and feats:
        texts = [short(f.name, 16) for f in feats]
        cols = [f.color for f in feats]
        others = [eyes]
        if predictions is not None and "predictions" in shown:
            gh = [(a.x, a.y, a.z, predictions.g) for a in predictions.ghosts()]
            others.append(np.array(gh, float).reshape(-1, 4))
        named = Named3D(balls[:, :3], balls[:, 3], _text_sizes(texts, size), np.concatenate(others))
    else:
        return None
    return texts, cols, named


def framed_camera(
    state: SceneState3D,
    scene: Scene,
    view: str,
    w_pt: float,
    h_pt: float,
    predictions: Predictions3D | None = None,
) -> Camera3D:
    """The preset ``view`` (:func:`default_camera`) for a scene part ``w_pt`` x ``h_pt``
    points, moved back until the balls' names are clear of each other and of every ball
    and eye (:func:`eyeviz.model.labels3d.fit_labels`, the app's framing): a crowded
    scene's names covered balls in the export, which framed the balls alone."""
    cam = default_camera(state, view, w_pt / max(h_pt, 1e-9))
    shown = set(scene.layers)
    got = _named(state, scene, "scene", shown, predictions) if "labels" in shown else None
    if got is None:
        return cam
    return fit_labels(cam, got[2], (w_pt, h_pt))


def _labels(ax, state, scene, cam, aspect, part, shown, predictions=None) -> None:
    """The eyes' names (close-up) and the balls' names (scene), each beside what it names
    and over nothing else: :func:`eyeviz.model.labels3d.place_named`, as the app places
    them (text boxes estimated from the text's length: the same in the PNG and the SVG)."""
    pos = ax.get_position()
    fig_w, fig_h = ax.figure.get_size_inches()
    w_pt, h_pt = max(pos.width * fig_w * 72.0, 1e-6), max(pos.height * fig_h * 72.0, 1e-6)
    if (got := _named(state, scene, part, shown, predictions)) is None:
        return
    texts, cols, named = got
    # the balls' names give way to each other as in the app; both eyes are always named
    boxes = place_named(named, cam, w_pt, h_pt, give_way=not named.below)
    at, rad = discs(cam, named.centres, named.radii, w_pt, h_pt)
    oc, orad = discs(cam, named.others[:, :3], named.others[:, 3], w_pt, h_pt)
    lines = leaders(at, rad, boxes, np.column_stack([oc, orad]))
    for seg, col in zip(lines, cols, strict=True):
        if np.isfinite(seg).all():  # a name placed farther out: a line to its ball
            xs, ys = 2.0 * seg[0::2] / w_pt - 1.0, 2.0 * seg[1::2] / h_pt - 1.0
            ax.plot(xs, ys, color=col, lw=0.8, solid_capstyle="round", gid="leader3d")
    for box, t, col in zip(boxes, texts, cols, strict=True):
        if not np.isfinite(box).all():
            continue
        x, y = 2.0 * box[0] / w_pt - 1.0, 2.0 * box[1] / h_pt - 1.0
        if abs(x) < 1 and abs(y) < 1:
            ax.text(x, y, t, fontsize=pt(SMALL + 1), color=col, ha="left", va="bottom",
                    parse_math=False, gid="name3d")  # fmt: skip


def _text_sizes(texts: list[str], size: float) -> np.ndarray:
    """Each text's width and height in points at ``size`` (estimated from its length)."""
    return np.array([(len(t) * 0.6 * size, 1.2 * size) for t in texts], float).reshape(-1, 2)


def draw_panel(
    fig: Figure,
    box: tuple[float, float, float, float],
    state: SceneState3D,
    scene: Scene,
    cam: Camera3D,
    layers=None,
    *,
    image: np.ndarray | None = None,
    predictions: Predictions3D | None = None,
) -> tuple[Axes, Axes]:
    """The whole 3D view in ``box`` (figure fractions: left, bottom, width, height) as the
    VTK view lays it out (:func:`split_viewports`): the eyes close up on the left, the
    scene through ``cam`` on the right. Returns the (eyes, scene) axes.

    ``image`` (rows x columns x 3 or 4, the VTK render of this view through ``cam``, as
    many pixels as ``box`` holds at the figure's dpi) is shown in place of the polygons,
    filling the box pixel for pixel (no resampling); the names are drawn over it as over
    the polygons. ``predictions`` (the predictions layer, drawn when the scene shows it)
    are drawn over the polygons (:func:`draw_ghosts`); over an ``image`` they are in the
    picture already (the VTK layer)."""
    w_in, h_in = box[2] * fig.get_figwidth(), box[3] * fig.get_figheight()
    if image is not None:
        img_ax = fig.add_axes(box)
        img_ax.set_gid("perspective-image")
        rows, cols = image.shape[:2]
        img_ax.imshow(
            image, extent=(0.0, cols, 0.0, rows), origin="upper", interpolation="none",
            aspect="auto", resample=False,
        )  # fmt: skip
        img_ax.set_xlim(0.0, cols)
        img_ax.set_ylim(0.0, rows)
        img_ax.set_axis_off()
    axes = []
    for part, (x0, y0, x1, y1) in zip(("eyes", "scene"), split_viewports(w_in, h_in), strict=True):
        ax = fig.add_axes(
            (box[0] + x0 * box[2], box[1] + y0 * box[3], (x1 - x0) * box[2], (y1 - y0) * box[3])
        )
        ax.set_gid(f"perspective-{part}")
        aspect = (x1 - x0) * w_in / ((y1 - y0) * h_in)
        if part == "eyes":
            if image is None:
                ax.add_patch(Rectangle((-1, -1), 2, 2, facecolor=INSET_RGBA, lw=0, zorder=-1))
            ca, cb = _centres(state)  # as the VTK close-up: half the eyes' x distance
            pcam = eyes_camera(cam, abs(cb[0] - ca[0]) / 2.0, state.pair.l, aspect)
        else:
            pcam = cam
        draw_view(ax, state, scene, pcam, aspect, part, layers, geometry=image is None,
                  predictions=predictions)  # fmt: skip
        shown = scene.layers if layers is None else layers
        if part == "scene" and image is None and "predictions" in shown:
            draw_ghosts(ax, predictions, pcam, aspect)
            ax.set_xlim(-1.0, 1.0)
            ax.set_ylim(-1.0, 1.0)
        axes.append(ax)
    return axes[0], axes[1]
