"""The Mollweide map of an eye's facets (eyeviz.render.mpl.healpix_map) and the README's
figure of the spherical eyes (scripts/figure_spherical.py)."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import matplotlib.colors as mcolors
import matplotlib.image as mimage
import numpy as np
from matplotlib.figure import Figure

from eyeviz.core import healpix
from eyeviz.render.mpl.healpix_map import UNLIT, draw_eye_map, facet_lonlat

ROOT = Path(__file__).resolve().parents[2]


def test_facet_outlines_are_continuous_and_start_in_range():
    poly = facet_lonlat(4, np.arange(healpix.npix(4)), step=3)
    assert poly.shape == (192, 12, 2)
    lon, lat = poly[..., 0], poly[..., 1]
    assert np.all((lon[:, 0] >= -math.pi) & (lon[:, 0] < math.pi))
    assert np.abs(np.diff(lon, axis=-1)).max() < math.pi / 2  # no jump across the wrap
    assert np.all(np.abs(lat) <= math.pi / 2 + 1e-12)


def test_lit_facets_take_their_feature_colour_and_the_wrap_is_drawn_twice():
    fig = Figure()
    ax = fig.add_subplot(projection="mollweide")
    lit = [np.array([0, 5, 100]), np.array([5, 7])]
    coll = draw_eye_map(ax, 4, lit, ["#ff0000", "#0000ff"])
    fc = coll.get_facecolors()
    n = healpix.npix(4)
    assert len(fc) > n  # facets across lon = +-pi are drawn on both sides
    red, blue, grey = (mcolors.to_rgba(c) for c in ("#ff0000", "#0000ff", UNLIT))
    assert tuple(fc[0]) == red and tuple(fc[100]) == red
    assert tuple(fc[5]) == blue and tuple(fc[7]) == blue  # the later feature wins
    assert tuple(fc[1]) == grey


def test_the_readme_figure_draws_the_equatorial_reduction(tmp_path):
    spec = importlib.util.spec_from_file_location("fig3d", ROOT / "scripts/figure_spherical.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    out = tmp_path / "sph.png"
    mod.draw(out)  # asserts that the equator ring equals the planar bitmap it draws
    img = mimage.imread(out)
    assert img.shape[0] > 400 and img.shape[1] > 1000
