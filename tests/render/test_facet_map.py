"""The one Mollweide map painter (eyeviz/render/mpl/facet_map.py) on a measured eye pair:
Voronoi patches written as vector paths, lit patches in their ball's colour, the seam and
the poles, and the HEALPix provider through the same painter."""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET

import matplotlib.image as mimage
import numpy as np
import pytest
from matplotlib.colors import to_hex, to_rgba
from matplotlib.figure import Figure

from eyeviz.measured import MeasuredEye, MeasuredEyePair, load_eyes, shipped_eye
from eyeviz.model.facet_patches import VoronoiPatches, facet_patches
from eyeviz.render.mpl.facet_map import (
    MapAxes,
    draw_eye_view,
    facet_at,
    mollweide,
    outline_lonlat,
    view_lonlat,
    view_polys,
)
from eyeviz.render.mpl.healpix_map import facet_lonlat

SVG = "{http://www.w3.org/2000/svg}"
RED, BLUE = "#d62728", "#1f77b4"


@pytest.fixture(scope="module")
def bee():
    return load_eyes(shipped_eye("AM_60185-real.eye"))


def _balls(bee):
    """Two balls ahead and below the bee (its binocular field), their lit sets on eye A."""
    lit = [bee.lit(0.0, 11.3, -16.4, 1.0)[0], bee.lit(-5.2, 29.5, -52.0, 3.0)[0]]
    assert all(len(x) >= 2 for x in lit)
    return lit


def _map_figure(patches, lit, colors):
    fig = Figure(figsize=(4.0, 2.2))
    ax = fig.add_axes((0.02, 0.02, 0.96, 0.96), axes_class=MapAxes)
    ax.set_gid("mapA")
    coll = draw_eye_view(ax, patches, lit, colors)
    coll.set_gid("facets")
    return fig, coll


def test_svg_holds_one_path_per_patch_lit_ones_in_the_balls_colours(bee, tmp_path):
    patches = facet_patches(bee, "A")
    lit = _balls(bee)
    fig, coll = _map_figure(patches, lit, [RED, BLUE])
    _, over, _ = view_polys(patches, np.arange(patches.n))
    out = tmp_path / "map.svg"
    fig.savefig(out, format="svg")
    root = ET.parse(out).getroot()
    group = next(g for g in root.iter(f"{SVG}g") if g.get("id") == "facets")
    paths = list(group.iter(f"{SVG}path"))
    assert len(paths) == patches.n + int(over.sum())  # a patch across the seam twice
    fills = [re.search(r"fill:\s*(#[0-9a-f]{6})", p.get("style", "")) for p in paths]
    fills = [f.group(1) if f else None for f in fills]
    # a later ball wins where both light a facet (as the app and the 3D view)
    blue = set(lit[1].tolist())
    red = set(lit[0].tolist()) - blue
    nblue = len(blue) + int(over[list(blue)].sum())
    nred = len(red) + int(over[list(red)].sum()) if red else 0
    assert fills.count(BLUE) == nblue and fills.count(RED) == nred
    assert fills.count(to_hex("#eeeeee")) == len(paths) - nblue - nred
    for i in list(blue)[:5]:  # the path of facet i (in order, the seam's copies last)
        assert fills[i] == BLUE


def test_pdf_is_vector_and_png_shows_the_lit_patch(bee, tmp_path):
    patches = facet_patches(bee, "A")
    lit = _balls(bee)
    fig, _ = _map_figure(patches, lit, [RED, BLUE])
    pdf = tmp_path / "map.pdf"
    fig.savefig(pdf, format="pdf")
    data = pdf.read_bytes()
    assert data.startswith(b"%PDF") and b"/Subtype /Image" not in data  # nothing rasterised
    png = tmp_path / "map.png"
    fig.savefig(png, format="png", dpi=300)
    img = mimage.imread(png)
    ax = fig.axes[0]
    # the middle of ball 1's patch is drawn in its colour
    c = patches.centers(lit[1]).mean(axis=0)
    i = int(lit[1][np.argmax(patches.centers(lit[1]) @ c)])
    x, y = _map_xy(patches, i)
    px, py = ax.transData.transform((x, y)) * 300 / fig.dpi
    rgb = img[img.shape[0] - 1 - int(round(py)), int(round(px)), :3]
    assert np.abs(rgb - np.array(to_rgba(BLUE)[:3])).max() < 0.05


def _map_xy(patches, i):
    """The Mollweide-axes point (matplotlib's MapAxes take radians) of facet i's axis."""
    c = patches.centers(np.array([i]))[0]
    lon, lat = view_lonlat(math.atan2(c[1], c[0]), math.asin(c[2]))
    return float(lon), float(lat)


def _pole_eye(n=400):
    """A synthetic eye whose axes cover the sphere above 30 deg elevation, one of them
    straight up: the patches at the north pole and across the seam (straight behind)."""
    rng = np.random.default_rng(5)
    z = rng.uniform(0.3, math.cos(math.radians(30.0)), n)  # none within 30 deg of the pole
    t = rng.uniform(0, 2 * np.pi, n)
    ax = np.column_stack([np.sqrt(1 - z**2) * np.cos(t), np.sqrt(1 - z**2) * np.sin(t), z])
    ax[0] = (0.0, 0.0, 1.0)
    back = np.array([0.0, -1.0, 1.0]) / math.sqrt(2.0)  # straight behind, 45 deg up: the seam
    ax[(ax @ back) > math.cos(math.radians(20.0))] = (1.0, 0.0, 0.7)  # none within 20 deg
    ax[1] = back
    pos = 0.5 * ax + np.array([-1.0, 0.0, 0.0])
    acc = np.full(n, math.radians(6.0))
    acc[0] = math.radians(40.0)  # the pole's patch may reach 20 deg
    acc[1] = math.radians(30.0)
    return MeasuredEye(pos, ax, acc, name="A")


def test_a_patch_round_the_pole_and_one_across_the_seam_fill_both_sides(tmp_path):
    eye = _pole_eye()
    # the pole lies inside patch 0 (its axis is the pole); move the axis off it a little so
    # the pole is strictly inside and its outline winds round it
    ax = eye.axes.copy()
    ax[0] = (0.01, 0.02, 1.0)
    patches = VoronoiPatches(ax, eye.acceptance)
    poly, cnt = outline_lonlat(*patches.outlines(np.array([0])), wind=True)
    assert cnt[0] > patches.outlines(np.array([0]))[1][0]  # closed along two meridians
    verts, over, _ = view_polys(patches, np.array([0, 1]))
    assert over.all()  # both cross the seam: drawn twice
    fig, _ = _map_figure(patches, [np.array([0]), np.array([1])], [RED, BLUE])
    png = tmp_path / "pole.png"
    fig.savefig(png, format="png", dpi=200)
    img = mimage.imread(png)
    mapax = fig.axes[0]

    def color_at(lon, lat):
        px, py = mapax.transData.transform((lon, lat)) * 200 / fig.dpi
        return img[img.shape[0] - 1 - int(round(py)), int(round(px)), :3]

    red, blue = np.array(to_rgba(RED)[:3]), np.array(to_rgba(BLUE)[:3])
    for lon in (-2.5, -1.0, 0.0, 1.0, 2.5):  # all round the pole
        assert np.abs(color_at(lon, math.radians(80.0)) - red).max() < 0.05
    # facet 1 (behind, 45 deg up) split by the seam: its colour at both edges of the map
    for lon in (-math.pi + 0.1, math.pi - 0.1):
        assert np.abs(color_at(lon, math.pi / 4) - blue).max() < 0.05


def test_hover_inverse_finds_every_measured_facet(bee):
    patches = facet_patches(bee, "B")
    idx = np.arange(0, patches.n, 7)
    c = patches.centers(idx)
    mx, my = view_lonlat(np.arctan2(c[:, 1], c[:, 0]), np.arcsin(c[:, 2]))
    x, y = mollweide(mx, my)
    np.testing.assert_array_equal(facet_at(patches, x, y), idx)
    assert facet_at(patches, 2.9, 0.0) == -1  # off the map


def test_healpix_outlines_through_the_generic_path_are_the_old_ones():
    """The generic lon/lat of HEALPix outlines is facet_lonlat's (the snapshots of the
    shipped spherical scenes were byte-identical before and after the painter became one)."""
    from eyeviz.core import healpix

    pix = np.arange(healpix.npix(8))
    a = facet_lonlat(8, pix, 2)
    b, cnt = outline_lonlat(healpix.boundaries(8, pix, 2))
    np.testing.assert_array_equal(a, b)
    assert (cnt == 8).all()
    pair = MeasuredEyePair(_pole_eye(), _pole_eye(), name="pole")
    assert facet_patches(pair, "A").may_wind
