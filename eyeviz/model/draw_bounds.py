"""How large a spherical scene each drawing path draws, checked before anything is
allocated (issue 36 item 5, issue 35 item 6).

The geometry takes any nside up to :data:`eyeviz.core.bounds.MAX_NSIDE` (data sets and
estimators need no picture), but a picture costs per facet it draws: a ball lighting most
of an eye at nside 1024 drew 12.6 million facet polygons per eye (11.6 GB, then "out of
memory"); at nside 2048 the PNG did not finish in 150 s and the app ran out of memory
under 6 GB. Each path (``"vector"``: SVG/PDF, ``"png"``: the PNG snapshot, ``"app"``: the
3D view) states the largest nside it draws and the most lit facets (per eye, summed over
the balls) it draws; :func:`check_drawable_eyes` refuses a scene beyond either in one line
naming the bound, from the balls' sizes alone (:func:`lit_estimate`), before any lit set
is computed.

Pure arithmetic; no numpy arrays per facet.
"""

from __future__ import annotations

import math

from eyeviz import EyevizError
from eyeviz.model.scene import Scene

__all__ = ["MAX_DRAW_NSIDE", "MAX_DRAWN_LIT", "MAX_APP_BALLS", "PATHS", "check_drawable_eyes",
           "lit_estimate"]  # fmt: skip

PATHS = ("vector", "png", "app")
#: The largest nside each path draws (measured: a vector figure of nside 1024 with a
#: small ball took 36 s and 0.23 GB on a loaded 2-core machine; the eyes' close-up and the
#: maps are drawn from the lit facets and a coarse sphere, so nside itself costs little
#: until a per-eye array of 12 nside^2 entries is made: 200 MB at 4096).
MAX_DRAW_NSIDE = {"vector": 4096, "png": 4096, "app": 2048}
#: The most lit facets per eye (summed over balls) each path draws: each is a polygon of
#: the Mollweide maps (vector, PNG; a ball lighting 25,700 facets per eye at nside 128 took
#: 131 s and 0.30 GB under a load of 7-8, one lighting 101,500 at nside 256 did not end in
#: 300 s) and of the view's lit patches (app; coarsened past 200,000 a ball).
MAX_DRAWN_LIT = {"vector": 25_000, "png": 25_000, "app": 400_000}
#: The most balls a spherical scene may have in the app (the 3D view): 10^4 at nside 180
#: gave no first frame in 500 s (issue 36 item 4); at nside 180 under a load of 8-11, 100
#: balls took 110 s to a first frame and 300 balls 251 s (docs/spherical.md).
MAX_APP_BALLS = 100


def _cap_fraction(s: float) -> float:
    """The share of the sphere a ball of angular radius asin(s) covers, (1 - cos a) / 2,
    without cancellation for small s."""
    if s >= 1.0:
        return 1.0
    return s * s / (2.0 * (1.0 + math.sqrt(1.0 - s * s)))


def lit_estimate(scene: Scene) -> int:
    """About how many facets the scene's balls light on its busier eye (summed over the
    balls: overlapping caps count twice), from each ball's angular size seen from each eye
    centre, plus a rim of cells along each cap's edge."""
    e = scene.eyes
    if e.nside is None:
        return 0
    npix = 12 * int(e.nside) ** 2
    width = math.sqrt(4.0 * math.pi / npix)  # a cell's angular width
    most = 0.0
    for cx in (-float(e.h), float(e.h)):
        total = 0.0
        for f in scene.features:
            d = math.hypot(f.x - cx, f.y, f.z)
            s = 1.0 if d <= f.g else f.g / d
            rim = 8.0 * math.asin(min(1.0, s)) / width + 4.0
            total += min(float(npix), npix * _cap_fraction(s) + rim)
        most = max(most, total)
    return int(min(most, 1e18))


def check_drawable_eyes(scene: Scene, path: str) -> None:
    """EyevizError (one line) when ``path`` (:data:`PATHS`) does not draw ``scene``'s
    spherical eyes: nside above :data:`MAX_DRAW_NSIDE`, lit facets above
    :data:`MAX_DRAWN_LIT`, or (the app) more balls than :data:`MAX_APP_BALLS`."""
    if path not in PATHS:
        raise ValueError(f"path must be one of {PATHS}, got {path!r}")
    nside = scene.eyes.nside
    if nside is None:
        return
    what = {"vector": "an SVG/PDF figure", "png": "a PNG snapshot", "app": "the app's 3D view"}
    if nside > MAX_DRAW_NSIDE[path]:
        raise EyevizError(
            f"nside = {nside}: {what[path]} draws spherical eyes up to nside "
            f"{MAX_DRAW_NSIDE[path]} (a larger nside is for data sets and estimators)"
        )
    if path == "app" and len(scene.features) > MAX_APP_BALLS:
        raise EyevizError(
            f"{len(scene.features)} balls: the app's 3D view draws at most {MAX_APP_BALLS} "
            "(a larger scene exports as a figure, or splits)"
        )
    lit = lit_estimate(scene)
    if lit > MAX_DRAWN_LIT[path]:
        raise EyevizError(
            f"the balls light about {lit:,} facets of an eye at nside {nside}; {what[path]} "
            f"draws at most {MAX_DRAWN_LIT[path]:,} (smaller balls, or a smaller nside)"
        )
