"""What the 3D view draws, as numpy arrays: facet polygons, tangent cones, the 3D BFV's
cones, the plane z = 0 and the colour of every facet (no VTK, no matplotlib).

The VTK painters (:mod:`eyeviz.render.vtk.scene3d`) and a vector figure draw these
arrays only; the geometry is here, beside the model (docs/architecture.md: renderers never
compute geometry). The eyes and the balls are those of docs/spherical.md: eye A at
(-h, 0, 0), eye B at (h, 0, 0), facets the HEALPix cells in RING order; a measured pair's
(docs/measured.md) are drawn through :mod:`eyeviz.model.facets3d`, and its h and l (half
its eyes' distance, its largest lens distance from an eye's centroid) frame the cameras.

Why it is not :mod:`eyeviz.model.frame_parts` (issue 37.2 keeps the two): the planar
Frame's parts are polygons in the plane (wedges clipped to the view, runs of equal colour
along an eye's m ommatidia, tangent segments), built per layer from Proposition 2's
intervals; these are meshes in space (cells or lenses lit from CSR lit sets, tangent and
acceptance cones, the plane z = 0) and the cameras that frame them. The same job, drawing
what the state holds without computing it in a renderer, is done by different geometry.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from eyeviz import EyevizError
from eyeviz.core import healpix
from eyeviz.model.camera3d import Camera3D, preset
from eyeviz.model.state3d import SceneState3D

__all__ = [
    "FULL_MAX_NSIDE",
    "MAX_DRAWN_FACETS",
    "check_drawn_facets",
    "lit_owner",
    "MAX_ACCEPTANCE_CONES",
    "acceptance_cones",
    "bfv_cones",
    "cone_faces",
    "edge_step",
    "facet_mesh",
    "facet_owner",
    "patch_facets",
    "plane_z0",
    "bounding_ball",
    "scene_extent",
    "view_camera",
    "shorten_cones",
    "tangent_cone",
    "tangent_cones",
    "view_nside",
]

#: Up to this nside every facet of an eye is a cell of the view's mesh (nside 32: 12,288
#: per eye). Beyond, the unlit sphere is one smooth mesh (the vector figure's: the facets
#: of :data:`COARSE_NSIDE`, :func:`view_nside`) and the lit facets are drawn at the scene's
#: nside over it (nside 180: 388,800 facets per eye, each under a pixel in the view; a
#: full mesh rendered in ~450 ms a frame here, scripts/bench_app3d.py measures the LOD).
FULL_MAX_NSIDE = 32
COARSE_NSIDE = 16


def view_nside(nside: int) -> int:
    """The nside of the mesh drawn for an eye's unlit sphere (see :data:`FULL_MAX_NSIDE`)."""
    return int(nside) if nside <= FULL_MAX_NSIDE else COARSE_NSIDE


def edge_step(nside: int) -> int:
    """Points per facet edge: curved edges for the large facets of a small nside."""
    return max(1, min(8, 16 // int(nside)))


@lru_cache(maxsize=8)
def _unit_mesh(nside: int, step: int) -> tuple[np.ndarray, np.ndarray]:
    pts = healpix.boundaries(nside, np.arange(healpix.npix(nside)), step)
    k = 4 * step
    n = pts.shape[0]
    faces = np.empty((n, k + 1), dtype=np.int64)
    faces[:, 0] = k
    faces[:, 1:] = np.arange(n * k, dtype=np.int64).reshape(n, k)
    pts.setflags(write=False)
    faces.setflags(write=False)
    return pts.reshape(-1, 3), faces.ravel()


def facet_mesh(
    nside: int, centre, radius: float, pix=None, step: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """(points (k, 3), VTK faces) of facets ``pix`` (all when None) of an eye: one polygon
    per facet, counter-clockwise seen from outside, in ``pix`` order (so cell i is facet
    ``pix[i]``; cell i is facet i for the whole eye)."""
    step = edge_step(nside) if step is None else int(step)
    c = np.asarray(centre, dtype=np.float64)
    if pix is None:
        unit, faces = _unit_mesh(int(nside), step)
        return unit * radius + c, faces
    pix = np.asarray(pix, dtype=np.int64)
    k = 4 * step
    pts = healpix.boundaries(nside, pix, step).reshape(-1, 3) * radius + c
    faces = np.empty((pix.size, k + 1), dtype=np.int64)
    faces[:, 0] = k
    faces[:, 1:] = np.arange(pix.size * k, dtype=np.int64).reshape(pix.size, k)
    return pts, faces.ravel()


#: A ball's lit facets are drawn one cell each up to this many per eye; beyond (a large
#: ball near the eye at a large nside) as the facets of nside PATCH_COARSE_NSIDE their
#: centres fall in (a sample of at most this many), so a frame stays bounded.
MAX_PATCH_FACETS = 200_000
PATCH_COARSE_NSIDE = 64


def patch_facets(nside: int, pix: np.ndarray) -> tuple[int, np.ndarray]:
    """(nside, facets) to draw for the lit facets ``pix`` of one eye at ``nside``: the
    facets themselves, or beyond :data:`MAX_PATCH_FACETS` the coarse facets holding a
    sample of their centres."""
    pix = np.asarray(pix, dtype=np.int64)
    if pix.size <= MAX_PATCH_FACETS or nside <= PATCH_COARSE_NSIDE:
        return int(nside), pix
    step = -(-pix.size // MAX_PATCH_FACETS)
    v = healpix.centers(nside, pix[::step])
    coarse = healpix.vec2pix_ring(PATCH_COARSE_NSIDE, v[:, 0], v[:, 1], v[:, 2])
    return PATCH_COARSE_NSIDE, np.unique(coarse)


#: The most lit facets per eye a figure draws, one polygon each (issue 35: a whole-eye
#: ball at nside 1024, 12.6 million facets, took a snapshot to 11.6 GB and "out of
#: memory"); a scene beyond is refused in one line by :func:`check_drawn_facets` before
#: anything is drawn.
MAX_DRAWN_FACETS = 1 << 20


def lit_owner(state: SceneState3D, eye: str) -> tuple[np.ndarray, np.ndarray]:
    """(facets, owners): the lit facets of ``eye`` (sorted RING indices) and the ball each
    is coloured for, the last one lighting it (as :func:`facet_owner`). Memory in the lit
    count, not in the eye's facets (facet_owner at nside 16384 made 12 GiB)."""
    csr = state.lit_a if eye == "A" else state.lit_b
    if csr is None or int(csr[0][-1]) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int32)
    ip, ix = csr
    ball = np.repeat(np.arange(state.n, dtype=np.int32), np.diff(ip))
    # the last ball per facet: unique over the reversed list keeps each facet's first hit
    rev = np.asarray(ix, np.int64)[::-1]
    pix, first = np.unique(rev, return_index=True)
    return pix, ball[::-1][first]


def check_drawn_facets(state: SceneState3D, bound: int | None = None) -> None:
    """EyevizError (one line, the bound named) when an eye has more lit facets than a
    figure draws (:data:`MAX_DRAWN_FACETS`); counted from the lit lists, before drawing."""
    bound = MAX_DRAWN_FACETS if bound is None else bound
    for eye, csr in (("A", state.lit_a), ("B", state.lit_b)):
        if csr is None or int(csr[0][-1]) <= bound:
            continue
        count = lit_owner(state, eye)[0].size
        if count > bound:
            raise EyevizError(
                f"eye {eye} has {count:,} lit facets; a figure draws at most {bound:,} per "
                "eye (MAX_DRAWN_FACETS): a smaller nside or smaller balls"
            )


def facet_owner(state: SceneState3D, eye: str, out: np.ndarray | None = None) -> np.ndarray:
    """Per facet of ``eye`` the index of the ball it is coloured for, -1 if unlit.

    A facet lit by several balls takes the last one's (the scene's drawing order, as the
    planar owner of an ommatidium and the 3D figure). ``out`` (int32, npix) is filled in
    place when given.
    """
    npix = state.facet_counts[0 if eye == "A" else 1]
    own = np.full(npix, -1, dtype=np.int32) if out is None else out
    if out is not None:
        own.fill(-1)
    csr = state.lit_a if eye == "A" else state.lit_b
    if csr is None:
        return own
    ip, ix = csr
    for i in range(state.n):
        own[ix[ip[i] : ip[i + 1]]] = i
    return own


def tangent_cone(apex, centre, g: float, res: int = 48) -> np.ndarray:
    """Points (res + 1, 3): the apex, then the circle where the cone from ``apex`` touches
    the ball (``centre``, ``g``): the closed tangent cone of the 3D Proposition 2.

    The circle has centre apex + d (1 - g^2 / |d|^2) and radius g sqrt(|d|^2 - g^2) / |d|;
    when the apex lies in the closed ball (the whole eye lit) the cone is degenerate: every
    point is the apex.
    """
    a = np.asarray(apex, dtype=np.float64)
    d = np.asarray(centre, dtype=np.float64) - a
    dd = float(d @ d)
    out = np.empty((res + 1, 3))
    out[:] = a
    if dd <= g * g:
        return out
    dn = math.sqrt(dd)
    u = d / dn
    # two unit vectors normal to u
    ref = np.array([0.0, 0.0, 1.0]) if abs(u[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    e1 = np.cross(u, ref)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(u, e1)
    c = a + d * (1.0 - g * g / dd)
    rad = g * math.sqrt(dd - g * g) / dn
    t = np.linspace(0.0, 2.0 * math.pi, res, endpoint=False)
    out[1:] = c + rad * (np.cos(t)[:, None] * e1 + np.sin(t)[:, None] * e2)
    return out


def tangent_cones(apices, centres, g, res: int = 48) -> np.ndarray:
    """:func:`tangent_cone` for many cones at once: apices (k, 3), centres (k, 3), radii
    (k,) -> points (k * (res + 1), 3), cone after cone (vectorised: a drag frame)."""
    a = np.asarray(apices, dtype=np.float64).reshape(-1, 3)
    d = np.asarray(centres, dtype=np.float64).reshape(-1, 3) - a
    g = np.asarray(g, dtype=np.float64).reshape(-1)
    dd = (d * d).sum(axis=1)
    ok = dd > g * g
    dn = np.sqrt(np.where(ok, dd, 1.0))
    # a ball holding its apex (at an eye centre: d = 0) has no cone; any unit u keeps the
    # frame below free of 0/0 (a RuntimeWarning on stderr, issue 36)
    u = np.where(ok[:, None], d / dn[:, None], [0.0, 1.0, 0.0])
    ref = np.where((np.abs(u[:, 2]) < 0.9)[:, None], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0])
    e1 = np.cross(u, ref)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(u, e1)
    c = a + d * np.where(ok, 1.0 - g * g / np.where(ok, dd, 1.0), 0.0)[:, None]
    rad = np.where(ok, g * np.sqrt(np.maximum(dd - g * g, 0.0)) / dn, 0.0)
    t = np.linspace(0.0, 2.0 * math.pi, res, endpoint=False)
    ring = c[:, None, :] + rad[:, None, None] * (
        np.cos(t)[None, :, None] * e1[:, None, :] + np.sin(t)[None, :, None] * e2[:, None, :]
    )
    out = np.empty((a.shape[0], res + 1, 3))
    out[:, 0] = a
    out[:, 1:] = np.where(ok[:, None, None], ring, a[:, None, :])
    return out.reshape(-1, 3)


def cone_faces(res: int = 48) -> np.ndarray:
    """VTK faces of :func:`tangent_cone`'s points: ``res`` triangles apex, i, i + 1."""
    i = np.arange(res)
    return np.column_stack([np.full(res, 3), np.zeros(res, int), 1 + i, 1 + (i + 1) % res]).ravel()


#: The cones layer draws at most this many acceptance cones per eye (a sample beyond).
MAX_ACCEPTANCE_CONES = 1000


def acceptance_cones(
    positions, axes, acceptance, centre, res: int = 12
) -> tuple[np.ndarray, np.ndarray]:
    """Measured facets' acceptance cones (docs/measured.md): per facet the apex at its lens
    ``positions[i]``, along its unit axis ``axes[i]``, of half-angle ``acceptance[i] / 2``,
    truncated at the ball ``centre``'s distance from the lens (points: the apex, then
    ``res`` points of the rim, facet after facet; at most :data:`MAX_ACCEPTANCE_CONES`,
    an even sample beyond). Returns (points (k (res + 1), 3), the facets drawn)."""
    pos = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    k = pos.shape[0]
    take = np.arange(k)
    if k > MAX_ACCEPTANCE_CONES:
        take = take[:: -(-k // MAX_ACCEPTANCE_CONES)]
    pos = pos[take]
    u = np.asarray(axes, dtype=np.float64).reshape(-1, 3)[take]
    u = u / np.linalg.norm(u, axis=1, keepdims=True)
    half = np.asarray(acceptance, dtype=np.float64).reshape(-1)[take] / 2.0
    length = np.linalg.norm(np.asarray(centre, dtype=np.float64) - pos, axis=1)
    ref = np.where((np.abs(u[:, 2]) < 0.9)[:, None], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0])
    e1 = np.cross(u, ref)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(u, e1)
    t = np.linspace(0.0, 2.0 * math.pi, res, endpoint=False)
    rad = length * np.tan(half)
    rim = (pos + u * length[:, None])[:, None, :] + rad[:, None, None] * (
        np.cos(t)[None, :, None] * e1[:, None, :] + np.sin(t)[None, :, None] * e2[:, None, :]
    )
    out = np.empty((pos.shape[0], res + 1, 3))
    out[:, 0] = pos
    out[:, 1:] = rim
    return out.reshape(-1, 3), take


def shorten_cones(pts: np.ndarray, res: int, length: float) -> np.ndarray:
    """Cones of :func:`tangent_cone` (blocks of res + 1 points) cut ``length`` from their
    apex (a cone shorter than that is kept whole)."""
    p = np.asarray(pts, dtype=np.float64).reshape(-1, res + 1, 3)
    apex = p[:, :1, :]
    axis = p[:, 1:, :].mean(axis=1, keepdims=True) - apex
    d = np.linalg.norm(axis, axis=-1, keepdims=True)
    s = np.where(d > length, length / np.maximum(d, 1e-300), 1.0)
    return (apex + (p - apex) * s).reshape(-1, 3)


def bfv_cones(h: float, l: float, reach: float, res: int = 48) -> tuple[np.ndarray, np.ndarray]:
    """(points, VTK faces): the boundary of the 3D binocular field of view out to
    ``reach`` from the origin (docs/spherical.md): the halves y >= 0 of the two tangent
    cones from the origin, about +x and -x, of half-angle psi = asin(l / h). The field is
    the region in front of the eyes outside both cones.
    """
    psi = math.asin(l / h)
    t = np.linspace(-0.5 * math.pi, 0.5 * math.pi, res + 1)
    pts = [np.zeros((1, 3))]
    faces = []
    for k, sx in enumerate((1.0, -1.0)):
        ring = reach * np.column_stack(
            [
                np.full(t.size, sx * math.cos(psi)),
                math.sin(psi) * np.cos(t),
                math.sin(psi) * np.sin(t),
            ]
        )
        base = 1 + k * t.size
        pts.append(ring)
        j = np.arange(res)
        faces.append(np.column_stack([np.full(res, 3), np.zeros(res, int), base + j, base + j + 1]))
    return np.concatenate(pts), np.concatenate(faces).ravel()


def plane_z0(
    x0: float, x1: float, y0: float, y1: float, lines: int = 8
) -> tuple[np.ndarray, np.ndarray]:
    """(corners (4, 3), grid segments (2 * (lines + 1), 2, 3)) of the rectangle
    [x0, x1] x [y0, y1] of the plane z = 0 (the planar model's plane)."""
    corners = np.array([[x0, y0, 0.0], [x1, y0, 0.0], [x1, y1, 0.0], [x0, y1, 0.0]])
    xs = np.linspace(x0, x1, lines + 1)
    ys = np.linspace(y0, y1, lines + 1)
    seg = [((x, y0, 0.0), (x, y1, 0.0)) for x in xs] + [((x0, y, 0.0), (x1, y, 0.0)) for y in ys]
    return corners, np.asarray(seg, dtype=np.float64)


def bounding_ball(state: SceneState3D) -> tuple[tuple[float, float, float], float]:
    """(centre, radius) of a ball holding the eyes and every ball of the scene: the centre
    of their bounding box and the largest distance from it (what the presets frame)."""
    pair = state.pair
    r = pair.h + pair.l
    lo = np.array([-r, -pair.l, -pair.l])
    hi = -lo
    if state.n:
        c = np.column_stack([state.x, state.y, state.z])
        lo = np.minimum(lo, (c - state.g[:, None]).min(axis=0))
        hi = np.maximum(hi, (c + state.g[:, None]).max(axis=0))
    mid = (lo + hi) / 2.0
    # the eyes' box's farthest corner from mid
    rad = float(np.linalg.norm(np.abs(mid) + np.array([r, pair.l, pair.l])))
    if state.n:
        d = np.linalg.norm(c - mid, axis=1) + state.g
        rad = max(rad, float(d.max()))
    return (float(mid[0]), float(mid[1]), float(mid[2])), rad


def scene_extent(state: SceneState3D) -> float:
    """How far ahead the views reach: the farthest ball's |centre| + g (at least 8 (h + l))
    -- the ``extent`` of :func:`eyeviz.model.camera3d.preset`."""
    pair = state.pair
    lo = 8.0 * (pair.h + pair.l)
    if state.n == 0:
        return lo
    reach = np.sqrt(state.x**2 + state.y**2 + state.z**2) + state.g
    return float(max(lo, reach.max()))


def view_camera(state: SceneState3D, name: str = "default", aspect: float = 1.0) -> Camera3D:
    """The preset ``name`` (:func:`eyeviz.model.camera3d.preset`) framing the eyes and the
    balls (:func:`bounding_ball`) in a viewport ``aspect`` (width / height) wide: the 3D
    view's camera when a scene opens, its PNG's and its vector figure's by default. The
    default 3/4 view looks from above, or from below when the balls' mean height is
    negative."""
    pair = state.pair
    if name in ("eye_a", "eye_b"):
        return _along_eye(state, name, aspect)
    centre, radius = bounding_ball(state)
    cam = preset(name, pair.h, pair.l, scene_extent(state), aspect, centre=centre, radius=radius)
    if name == "default" and state.n and float(np.mean(state.z)) < 0.0:
        # the 3/4 view from the balls' side: from below when they are mostly below the
        # eyes' plane (a bee's binocular field), so the facets they light face the camera
        x, y, z = cam.position
        cam = Camera3D((x, y, 2.0 * cam.focal_point[2] - z), cam.focal_point, cam.view_up,
                       cam.view_angle)  # fmt: skip
    return cam


def _along_eye(state: SceneState3D, name: str, aspect: float) -> Camera3D:
    """Along the eye's forward axis, from ahead of every ball, far enough back that the
    balls and the other eye are in view (each point's offset from the axis within the
    view's half-angles at its distance from the camera, with a 10 % margin)."""
    pair = state.pair
    ex = -pair.h if name == "eye_a" else pair.h
    base = preset(name, pair.h, pair.l, scene_extent(state), aspect)
    half_v = math.radians(base.view_angle) / 2.0
    tv = math.tan(half_v)
    th = tv * aspect
    pts = [(abs(-ex - ex) + pair.l, 0.0, pair.l)]  # the other eye
    pts += [
        (abs(x - ex) + g, y, abs(z) + g)
        for x, y, z, g in zip(state.x, state.y, state.z, state.g, strict=True)
    ]
    need = max(y + 1.2 * max(dx / th, dz / tv) for dx, y, dz in pts)
    need = max(need, base.position[1])
    return Camera3D((ex, float(need), 0.0), (ex, 0.0, 0.0), base.view_up, base.view_angle)
