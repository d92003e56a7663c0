"""The spherical side's ``responses`` layer: each lit facet's graded response
(docs/responses.md) for the app's 3D eyes and Facets dock, and the shade it is painted in.

Which kind each model shows (:data:`LAYER_KIND`): a measured eye's ``gaussian`` (the
acceptance function of Snyder and the renderers, restricted to the cone), a HEALPix eye's
``cell`` (the share of the cell's area the ball covers). A lit facet is painted in its
ball's colour blended towards the unlit grey by ``1 - value`` (:func:`shade`), quantised
to :data:`LEVELS` steps so that the Facets dock keeps a small palette.

Cost: every ball's responses are computed, each ball's once per position
(:class:`ResponseCache`: a drag recomputes the dragged ball's only, on every frame). A
measured eye's cost about 50 us per lit (ball, facet) pair; a HEALPix eye's cells the cap
surely holds are 1 from a vertex-and-edge test, and only the cells its edge crosses are
integrated (:func:`eyeviz.core.responses_cells.cell_fraction`, compiled), about 80 us a
boundary cell.
"""

from __future__ import annotations

import numpy as np

from eyeviz.core.geometry3d import EyePair3D
from eyeviz.core.measured import MeasuredEyePair
from eyeviz.core.responses import healpix_values, measured_values
from eyeviz.model.state3d import SceneState3D

__all__ = [
    "LAYER_KIND",
    "LEVELS",
    "ResponseCache",
    "lit_responses",
    "owner_values",
    "response_text",
    "shaded_owners",
    "shade",
    "shade_levels",
    "shaded_palette",
]

#: The kind the layer shows per eye model (``Pair3D.kind``).
LAYER_KIND = {"measured": "gaussian", "spherical": "cell"}
#: The shades between unlit (value 0) and the ball's colour (value 1).
LEVELS = 32


def shade_levels(values: np.ndarray) -> np.ndarray:
    """Each value's shade step in 0..LEVELS-1 (NaN, not computed: the full colour);
    a positive value never falls to step 0, so a lit facet never reads as unlit."""
    v = np.asarray(values, np.float64)
    out = np.full(v.shape, LEVELS - 1, np.int64)
    ok = np.isfinite(v)
    k = np.ceil(np.clip(v[ok], 0.0, 1.0) * (LEVELS - 1)).astype(np.int64)
    out[ok] = k
    return out


def shade(rgb: np.ndarray, unlit: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Colours ``rgb`` (..., C, floats or uint8) blended towards ``unlit`` (C) by
    ``1 - value``, the values quantised by :func:`shade_levels`; same dtype as ``rgb``."""
    t = shade_levels(values).astype(np.float64)[..., None] / (LEVELS - 1)
    c = np.asarray(rgb, np.float64)
    out = np.asarray(unlit, np.float64) * (1.0 - t) + c * t
    if np.issubdtype(np.asarray(rgb).dtype, np.integer):
        return np.round(out).astype(np.asarray(rgb).dtype)
    return out


def shaded_palette(rgb: np.ndarray, unlit: np.ndarray) -> np.ndarray:
    """(n * LEVELS, C): ball k's colour at shade step s in row k * LEVELS + s (step 0 the
    unlit colour, LEVELS - 1 the ball's own), as :func:`shade` paints them."""
    t = np.arange(LEVELS, dtype=np.float64)[None, :, None] / (LEVELS - 1)
    c = np.asarray(rgb, np.float64)[:, None, :]
    out = np.asarray(unlit, np.float64) * (1.0 - t) + c * t
    return out.reshape(-1, c.shape[-1])


def shaded_owners(
    owner: np.ndarray, values: np.ndarray, rgba: np.ndarray, unlit: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(index, palette): per lit facet the row of :func:`shaded_palette` ``(rgba, unlit)``
    (returned too) painting ball ``owner``'s colour at ``values``' shade."""
    return owner * LEVELS + shade_levels(values), shaded_palette(rgba, unlit)


def response_text(value: float, kind: str) -> str:
    """The hover's words for a lit facet's response (NaN: not computed)."""
    if np.isfinite(value):
        return f"response {value:.3g} ({kind})"
    return f"response not computed ({kind})"


class ResponseCache:
    """Each (eye, ball) row's responses, kept while the pair and the ball stay the same:
    a drag recomputes only the dragged ball's (each row holds its latest position only)."""

    def __init__(self) -> None:
        self.pair: object | None = None
        # (eye, ball index): (the ball's (x, y, z, g), its lit facets, their values)
        self.rows: dict[tuple[str, int], tuple[tuple[float, ...], np.ndarray, np.ndarray]] = {}

    def _check_pair(self, pair: object) -> None:
        """Forget everything for other eyes (HEALPix pairs are compared by their
        parameters: a state may build its pair anew)."""
        same = pair is self.pair or (
            isinstance(pair, EyePair3D)
            and isinstance(self.pair, EyePair3D)
            and (pair.h, pair.l, pair.nside) == (self.pair.h, self.pair.l, self.pair.nside)
        )
        if not same:
            self.pair, self.rows = pair, {}

    def row(self, state: SceneState3D, eye: str, i: int, idx: np.ndarray) -> np.ndarray:
        """Ball ``i``'s responses on its lit facets ``idx`` of ``eye`` (aligned)."""
        pair = state.pair
        self._check_pair(pair)
        ball = (float(state.x[i]), float(state.y[i]), float(state.z[i]), float(state.g[i]))
        got = self.rows.get((eye, i))
        if got is not None and got[0] == ball and np.array_equal(got[1], idx):
            return got[2]
        balls = tuple(np.array([v]) for v in ball)
        indptr = np.array([0, idx.size], np.int64)
        if isinstance(pair, MeasuredEyePair):
            e = pair.eye(eye)
            kind = LAYER_KIND["measured"]
            vals = measured_values(e.positions, e.unit_axes, e.acceptance, balls, indptr, idx, kind)
        elif isinstance(pair, EyePair3D):
            cx = -pair.h if eye == "A" else pair.h
            vals = healpix_values(pair.nside, cx, balls, indptr, idx)
        else:  # pragma: no cover - the spherical side has these two models
            vals = np.full(idx.size, np.nan)
        self.rows[(eye, i)] = (ball, idx.copy(), vals)
        return vals


CACHE = ResponseCache()


def lit_responses(
    state: SceneState3D, selected: int | None, cache: ResponseCache | None = None
) -> dict[str, np.ndarray]:
    """Per eye ("A", "B") the values aligned with the lit CSR's indices: each lit (ball,
    facet) pair's response (``selected`` is not needed: every ball's are computed)."""
    cache = CACHE if cache is None else cache
    out: dict[str, np.ndarray] = {}
    for eye, csr in (("A", state.lit_a), ("B", state.lit_b)):
        if csr is None:
            out[eye] = np.zeros(0)
            continue
        indptr, idx = csr
        vals = np.full(idx.size, np.nan)
        for i in range(state.n):
            lo, hi = int(indptr[i]), int(indptr[i + 1])
            if hi > lo:
                vals[lo:hi] = cache.row(state, eye, i, idx[lo:hi])
        out[eye] = vals
    return out


def owner_values(csr: tuple[np.ndarray, np.ndarray], values: np.ndarray) -> np.ndarray:
    """Per lit facet (sorted, as :func:`eyeviz.app.panels.bitmaps3d.lit_owners`) the value
    of the ball that colours it (the last ball lighting it)."""
    _, idx = csr
    _, first = np.unique(idx[::-1], return_index=True)
    return values[::-1][first]
