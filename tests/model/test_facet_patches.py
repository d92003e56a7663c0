"""The facets' outline providers (eyeviz/model/facet_patches.py): HEALPix cells and the
Voronoi patches of a measured eye's axes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import SphericalVoronoi

from eyeviz.core import healpix
from eyeviz.core.geometry3d import EyePair3D
from eyeviz.measured import load_eyes, shipped_eye
from eyeviz.model.facet_patches import (
    HealpixPatches,
    VoronoiPatches,
    facet_patches,
    patches_caption,
    patches_caption_forms,
)


@pytest.fixture(scope="module")
def bee():
    return load_eyes(shipped_eye("AM_60185-real.eye"))


def _lonlat(v):
    return np.arctan2(v[..., 1], v[..., 0]), np.arcsin(np.clip(v[..., 2], -1, 1))


def test_every_axis_and_every_point_inside_an_outline_is_its_facet(bee):
    p = facet_patches(bee, "A")
    assert p.n == bee.facet_counts[0]
    idx = np.arange(p.n)
    np.testing.assert_array_equal(p.at(*_lonlat(p.centers(idx))), idx)
    v, cnt = p.outlines(idx)
    assert v.shape == (p.n, p.width, 3) and cnt.max() <= p.width and cnt.min() >= 3
    # 2 % of the way from each outline point to the axis: inside the patch
    inner = 0.98 * v + 0.02 * p.centers(idx)[:, None, :]
    inner /= np.linalg.norm(inner, axis=-1, keepdims=True)
    np.testing.assert_array_equal(
        p.at(*_lonlat(inner)), np.broadcast_to(idx[:, None], inner.shape[:2])
    )


def test_interior_patches_are_the_voronoi_cells(bee):
    """A cell not cut by its cap is scipy's SphericalVoronoi region, its vertices in
    order (every step-th outline point is a vertex)."""
    _, axes, acc = bee.facets("B")
    p = VoronoiPatches(axes, acc, step=2)
    u = axes / np.linalg.norm(axes, axis=1, keepdims=True)
    sv = SphericalVoronoi(u, 1.0, np.zeros(3))
    sv.sort_vertices_of_regions()
    checked = 0
    for i in range(0, p.n, 97):
        verts = sv.vertices[sv.regions[i]]
        if np.arccos(np.clip(verts @ u[i], -1, 1)).max() > p.reach[i]:
            continue
        v, cnt = p.outlines(np.array([i]))
        assert cnt[0] == 2 * len(verts)
        np.testing.assert_allclose(v[0, : cnt[0] : 2], verts, atol=1e-12)
        checked += 1
    assert checked > 20


def test_cells_at_the_edge_of_the_field_are_cut_to_their_cap(bee):
    """The honeybee's edge cells reach 20-100 deg as Voronoi cells; every patch stays
    within its reach, and a direction the eye does not look at is on no patch."""
    p = facet_patches(bee, "A")
    idx = np.arange(p.n)
    v, cnt = p.outlines(idx)
    ang = np.arccos(np.clip(np.einsum("kwj,kj->kw", v, p.centers(idx)), -1, 1))
    assert np.all(ang <= p.reach[p.rep][:, None] + 1e-9)
    assert math.degrees(p.reach.max()) < 4.0  # 3 x the median spacing (1.14 deg)
    # eye A (left) looks left and down; straight up-right is on none of its patches
    assert p.at(np.array([0.3]), np.array([1.2]))[0] == -1
    assert (p._counts >= 24).sum() < 0.1 * p.n  # cut cells: a few per cent


def test_coinciding_axes_share_a_patch_and_the_later_facet_answers():
    rng = np.random.default_rng(3)
    ax = rng.normal(size=(60, 3))
    ax[7] = ax[3] * 2.0  # the same direction
    p = VoronoiPatches(ax, np.full(60, 0.1))
    v3, c3 = p.outlines(np.array([3]))
    v7, c7 = p.outlines(np.array([7]))
    np.testing.assert_array_equal(v3, v7)
    u = ax[3] / np.linalg.norm(ax[3])
    assert p.at(*_lonlat(u[None]))[0] == 7


def test_axes_on_one_great_circle_have_patches_too():
    """A planar ring written as a measured eye: no Voronoi diagram (Qhull refuses), each
    cell outlined from its neighbours' bisectors."""
    t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    ax = np.stack([np.cos(t), np.sin(t), 0 * t], 1)
    p = VoronoiPatches(ax, np.full(40, 0.1))
    lon = t + 0.3 * (2 * np.pi / 40)  # within each facet's sector
    np.testing.assert_array_equal(p.at(lon, np.zeros(40)), np.arange(40))
    v, _ = p.outlines(np.arange(40))
    half_width = np.abs(np.angle(np.exp(1j * (np.arctan2(v[..., 1], v[..., 0]) - t[:, None]))))
    assert half_width.max() <= math.pi / 40 + 1e-9  # the bisectors at +-half the spacing


def test_healpix_provider_is_the_cells():
    p = HealpixPatches(8, 2)
    idx = np.arange(p.n)
    v, cnt = p.outlines(idx)
    np.testing.assert_array_equal(v, healpix.boundaries(8, idx, 2))
    assert (cnt == 8).all() and not p.may_wind
    c = healpix.centers(8, idx)
    np.testing.assert_array_equal(p.at(*_lonlat(c)), idx)
    assert p.describe(5).startswith("facet 5: azimuth ")


def test_patches_are_kept_per_pair_and_eye(bee):
    assert facet_patches(bee, "A") is facet_patches(bee, "A")
    assert facet_patches(bee, "B") is not facet_patches(bee, "A")
    again = load_eyes(shipped_eye("AM_60185-real.eye"))  # same arrays: same patches
    assert facet_patches(again, "A") is facet_patches(bee, "A")
    pair = EyePair3D(40.0, 20.0, 4)
    assert facet_patches(pair, "A").n == 192
    assert patches_caption(pair) == "nside 4, 192 facets per eye"
    assert patches_caption(bee) == "3,187 (A) and 3,187 (B) measured facets"
    # shorter forms for a narrow panel, each shorter than the last, keeping the counts
    for p, counts in ((pair, ["192"]), (bee, ["3,187", "3,187"])):
        forms = patches_caption_forms(p)
        assert forms[0] == patches_caption(p) and len(forms) == 3
        assert all(len(a) > len(b) for a, b in zip(forms[:-1], forms[1:], strict=True))
        assert all(f.count(c) >= counts.count(c) for f in forms for c in counts)
    with pytest.raises(ValueError, match="eye must be"):
        facet_patches(bee, "C")
    d = facet_patches(bee, "A").describe(0)
    assert d.startswith("facet 0: axis azimuth ") and d.endswith("acceptance 2.60\N{DEGREE SIGN}")
