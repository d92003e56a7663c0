"""Joint statistics of the 3D generator's draws: r, g and elevation come from independent
uniforms (Algorithm 1, steps 7, 10 and the elevation draw). Marginal checks alone do not
see two draws sharing one uniform; the within-slot ranks below do."""

from __future__ import annotations

import math

import numpy as np
import pytest

from eyeviz.core.domain import Domain3D
from eyeviz.dataset import algorithm1_3d as A

DOM = Domain3D(h=30, l=10, nside=64, r_min=100, r_max=400, g_max=60, el_max=0.4)
N = 1500


def _uniforms(mode: str, seed: int) -> dict[str, np.ndarray]:
    """Each row's draws mapped back to [0, 1]: r within its slot's range, g within
    [g_min(r), g_max], elevation within the band (by the mode's own law)."""
    ds = A.generate3d(N, DOM, mode=mode, seed=seed)
    r = ds.r
    if mode == "multi":
        edges, _ = A.segment_plan3d(N, A.make_params3d(DOM, mode, seed, None))
        k = np.clip(np.searchsorted(edges, r, side="right") - 1, 0, edges.size - 2)
        lo, hi = edges[k], edges[k + 1]
        u_r = (r**3 - lo**3) / (hi**3 - lo**3)
        u_el = (np.sin(ds.elevation) / math.sin(DOM.el_max) + 1) / 2
    else:
        u_r = (r - DOM.r_min) / (DOM.r_max - DOM.r_min)
        u_el = (ds.elevation / DOM.el_max + 1) / 2
    g_min = r * math.sin(DOM.gamma / 2)
    u_g = (ds.g - g_min) / (DOM.g_max - g_min)
    return {"r": u_r, "g": u_g, "el": u_el}


@pytest.mark.parametrize("mode", ["single", "multi"])
def test_r_g_and_elevation_draws_are_uncorrelated(mode):
    u = _uniforms(mode, seed=11)
    for a, b in (("r", "g"), ("r", "el"), ("g", "el")):
        c = float(np.corrcoef(u[a], u[b])[0, 1])
        # 1500 rows: a standard error of about 0.026; a shared uniform gives ~1
        assert abs(c) < 0.12, f"{mode}: corr({a}, {b}) = {c:.3f}"


@pytest.mark.parametrize("mode", ["single", "multi"])
def test_each_draw_fills_its_range(mode):
    u = _uniforms(mode, seed=12)
    for name, v in u.items():
        assert v.min() >= -1e-9 and v.max() <= 1 + 1e-9, name
        # the quartiles of a uniform, within a few standard errors at 1500 rows
        q = np.quantile(v, [0.25, 0.5, 0.75])
        assert np.all(np.abs(q - [0.25, 0.5, 0.75]) < 0.08), (name, q)
