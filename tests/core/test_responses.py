"""``responses`` of the eye models: the lit sets' structure, values in [0, 1], and the
values against an independent quadrature for random, tangent, enclosing and tiny balls."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.geometry import EyePair

from .responses_mp import ball_angles, cap_response

TOL = 1e-9


def _check_structure(resp, csr):
    for (indptr, indices, values), (lp, li) in zip(resp, csr, strict=True):
        np.testing.assert_array_equal(indptr, lp)
        np.testing.assert_array_equal(indices, li)
        assert values.dtype == np.float64 and values.shape == indices.shape
        assert ((values >= 0) & (values <= 1)).all()


def _check_measured(pair, x, y, z, g, kind, limit=40, always=()):
    resp = pair.responses(x, y, z, g, kind=kind)
    _check_structure(resp, pair.lit_csr(x, y, z, g))
    checked = 0
    for (indptr, indices, values), w in zip(resp, "AB", strict=True):
        e = pair.eye(w)
        for bi in range(indptr.size - 1):
            row = range(indptr[bi], indptr[bi + 1])
            for j in [j for j in row if j < indptr[bi] + 4 or indices[j] in always]:
                f = indices[j]
                c = (np.ravel(x)[bi], np.ravel(y)[bi], np.ravel(z)[bi])
                th, b = ball_angles(c, e.positions[f], e.axes[f], np.ravel(g)[bi])
                want = cap_response(e.acceptance[f] / 2, b, th, kind)
                assert abs(values[j] - want) <= TOL, (w, bi, f, values[j], want)
                checked += 1
                if checked >= limit:
                    return resp
    return resp


@pytest.mark.parametrize("kind", ["flat", "gaussian"])
def test_measured_random_balls(toy_pair, kind):
    rng = np.random.default_rng(3)
    x, y, z = rng.uniform(-6, 6, 8), rng.uniform(0.5, 8, 8), rng.uniform(-3, 3, 8)
    g = rng.uniform(0.05, 1.5, 8)
    _check_measured(toy_pair, x, y, z, g, kind)


@pytest.mark.parametrize("kind", ["flat", "gaussian"])
def test_measured_tangent_tiny_and_enclosing_balls(toy_pair, kind):
    e = toy_pair.eye_a
    p, a = e.positions[7], e.unit_axes[7]
    alpha = float(e.acceptance[7]) / 2
    # a direction at alpha + 0.01 from the axis, in the plane of the axis and x
    side = np.cross(a, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    ang = alpha + 0.01
    d = math.cos(ang) * a + math.sin(ang) * side
    c = p + 3.0 * d
    with mp.workdps(50):
        g_touch = float(3 * mp.sin(mp.mpf(0.01)))  # tangent to facet 7's cone, to rounding
    balls = [
        (c, g_touch),  # tangent
        (c, float(np.nextafter(g_touch, 1))),
        (p + 2.0 * a, 1e-12),  # tiny, on the axis
        (p + 2.0 * a + 1e-7 * side, 5e-300),  # tinier still
        (p + 0.01 * a, 0.02),  # holds the lens: every direction
        (p + 0.3 * a, 0.3),  # the lens on the ball's sphere
    ]
    x, y, z = (np.array([b[0][k] for b in balls]) for k in range(3))
    g = np.array([b[1] for b in balls])
    resp = _check_measured(toy_pair, x, y, z, g, kind, limit=200, always=(7,))
    (indptr, indices, values), _ = resp
    for bi in (0, 1, 2):  # the tangent balls and the tiny one light facet 7
        assert 7 in indices[indptr[bi] : indptr[bi + 1]]
    (indptr, indices, values), _ = resp
    row = dict(zip(indices[indptr[4] : indptr[5]], values[indptr[4] : indptr[5]], strict=True))
    assert row[7] == 1.0  # the ball holds facet 7's lens: every direction
    hit = indices[indptr[2] : indptr[3]]
    assert 7 in hit and values[indptr[2] + list(hit).index(7)] > 0


def test_measured_honeybee_matches_reference(honeybee):
    rng = np.random.default_rng(5)
    x, y, z = rng.uniform(-8, 8, 5), rng.uniform(0, 10, 5), rng.uniform(-4, 4, 5)
    g = rng.uniform(0.1, 2, 5)
    _check_measured(honeybee, x, y, z, g, "gaussian", limit=20)
    _check_measured(honeybee, x, y, z, g, "flat", limit=20)


def test_kinds_are_refused_where_they_do_not_apply(toy_pair):
    with pytest.raises(EyevizError, match="measured eyes answer responses of kind 'flat' or"):
        toy_pair.responses(0.0, 5.0, 0.0, 1.0, kind="cell")
    with pytest.raises(EyevizError, match="planar eyes answer responses of kind 'cell'"):
        EyePair().responses(0.0, 100.0, 5.0, kind="gaussian")
    with pytest.raises(ValueError, match="g"):
        toy_pair.responses(0.0, 5.0, 0.0, -1.0)


def _planar_reference(eyes, x, y, g, cx, k):
    """Sector k's covered share, from the disc's tangent directions in 50 digits."""
    with mp.workdps(50):
        dx, yy, gg = mp.mpf(float(x)) - mp.mpf(cx), mp.mpf(float(y)), mp.mpf(float(g))
        r = mp.sqrt(dx * dx + yy * yy)
        if r < gg:
            return 1.0
        phi = mp.atan2(yy, dx)
        beta = mp.asin(gg / r)
        gam = 2 * mp.pi / eyes.m
        total = mp.mpf(0)
        for s in (-1, 0, 1):
            lo = max(phi - beta + 2 * mp.pi * s, k * gam)
            hi = min(phi + beta + 2 * mp.pi * s, (k + 1) * gam)
            total += max(hi - lo, 0)
        return float(total / gam)


@pytest.mark.parametrize("m", [720, 36, 4096])
def test_planar_cells_match_reference(m):
    eyes = EyePair(40.0, 20.0, m)
    rng = np.random.default_rng(m)
    x = np.concatenate([rng.uniform(-200, 200, 6), [40.0, 30.0, 45.0, 0.0]])
    y = np.concatenate([rng.uniform(-200, 200, 6), [50.0, 0.0, 1.0, 1e-3]])
    g = np.concatenate([rng.uniform(0.5, 30, 6), [1e-9, 10.0, 6.0, 1e-12]])
    resp = eyes.responses(x, y, g)
    bitmaps = eyes.bitmaps(x, y, g)
    for (indptr, indices, values), cx, bm in zip(resp, (-40.0, 40.0), bitmaps, strict=True):
        for bi in range(x.size):
            lit = indices[indptr[bi] : indptr[bi + 1]]
            np.testing.assert_array_equal(lit, np.flatnonzero(bm[bi]))
            vals = values[indptr[bi] : indptr[bi + 1]]
            pairs = list(zip(lit, vals, strict=True))
            for k, v in pairs[:6] + pairs[-3:]:
                assert abs(v - _planar_reference(eyes, x[bi], y[bi], g[bi], cx, int(k))) <= TOL
    # the eye centre on the disc's circle: every sector lit, half of them at 0 (tangency)
    (ip, ix, vals), _ = EyePair(40.0, 20.0, 720).responses(-30.0, 0.0, 10.0)
    assert ix.size == 720 and (vals == 0).sum() >= 359 and abs(vals.sum() - 360) < 1e-9


def test_planar_sum_is_the_disc_angle():
    eyes = EyePair(40.0, 20.0, 720)
    rng = np.random.default_rng(9)
    x, y, g = rng.uniform(-300, 300, 50), rng.uniform(-300, 300, 50), rng.uniform(0.1, 20, 50)
    (ip, _, vals), _ = eyes.responses(x, y, g)
    sums = np.add.reduceat(vals, ip[:-1]) * eyes.gamma
    r = np.hypot(x + 40, y)
    want = np.where(r < g, 2 * math.pi, 2 * np.arcsin(np.minimum(g / r, 1)))
    np.testing.assert_allclose(sums, want, rtol=0, atol=1e-9)


def test_measured_gaussian_on_the_sphere(toy_pair):
    """support="sphere": the untruncated kernel, on the same lit facets; refused for flat."""
    x, y, z, g = 0.3, 4.0, 0.2, 0.4
    cone = toy_pair.responses(x, y, z, g, kind="gaussian")
    sphere = toy_pair.responses(x, y, z, g, kind="gaussian", support="sphere")
    (p, i, v), _ = sphere
    np.testing.assert_array_equal(i, cone[0][1])
    e = toy_pair.eye_a
    for j in range(min(5, i.size)):
        th, b = ball_angles((x, y, z), e.positions[i[j]], e.axes[i[j]], g)
        want = cap_response(e.acceptance[i[j]] / 2, b, th, "gaussian", "sphere")
        assert abs(v[j] - want) <= TOL
    with pytest.raises(EyevizError, match="support 'sphere'"):
        toy_pair.responses(x, y, z, g, kind="flat", support="sphere")
