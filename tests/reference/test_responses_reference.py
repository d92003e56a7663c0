"""The responses reference against closed forms (eyeviz/reference/responses_reference.py)."""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from scipy.stats import ncx2

from eyeviz.reference.responses_reference import (
    FWHM_PER_SIGMA,
    cap_of_ball,
    cap_response,
    reference_response,
    two_caps_area,
)

D = math.radians


def _gauss_disc(beta: float, dr: float) -> float:
    """Concentric Gaussian response in closed form: the integral of
    exp(-t^2 / (2 s^2)) sin t over [0, b] is Im(s sqrt(pi/2) e^(-s^2/2)
    (erf((b - i s^2) / (s sqrt 2)) + erf(i s / sqrt 2)))."""
    with mpmath.workdps(40):
        s = mpmath.mpf(dr) / (2 * mpmath.sqrt(2 * mpmath.log(2)))

        def f(b):
            z = (mpmath.mpf(b) - 1j * s * s) / (s * mpmath.sqrt(2))
            return mpmath.im(mpmath.erf(z) + mpmath.erf(1j * s / mpmath.sqrt(2)))

        return float(f(beta) / f(mpmath.pi))


def test_fwhm_constant() -> None:
    assert FWHM_PER_SIGMA == pytest.approx(2.3548200450309493, abs=1e-15)


@pytest.mark.parametrize("kind", ["flat", "gaussian"])
def test_enclosing_and_missing(kind: str) -> None:
    # a cap of radius pi covers every direction; flat: a cap holding the cone gives 1
    assert cap_response(0.3, math.pi, D(2.6), kind) == 1.0
    assert cap_response(D(1), D(3), D(2.6), "flat") == 1.0
    # a cap past the kernel's support (flat) or far in the tail (gaussian)
    far = cap_response(D(20), D(1), D(2.6), kind)
    assert far == 0.0 if kind == "flat" else 0 < far < 1e-60


def test_flat_concentric_closed_form() -> None:
    for beta, dr in ((D(1), D(2.6)), (D(0.01), D(5)), (1.0, 2.5), (D(1e-4), D(1e-3))):
        with mpmath.workdps(40):
            exact = (1 - mpmath.cos(beta)) / (1 - mpmath.cos(mpmath.mpf(dr) / 2))
        assert cap_response(0, beta, dr, "flat") == pytest.approx(float(exact), rel=1e-14)


def test_flat_offset_is_two_caps_area() -> None:
    rng = np.random.default_rng(1)
    for _ in range(3):
        dr, beta = rng.uniform(0.01, 1.5, 2)
        delta = rng.uniform(abs(dr / 2 - beta) * 1.01, (dr / 2 + beta) * 0.99)
        area = two_caps_area(dr / 2, beta, delta) / (2 * math.pi * (1 - math.cos(dr / 2)))
        assert cap_response(delta, beta, dr, "flat") == pytest.approx(area, rel=1e-12)


def test_gaussian_concentric_closed_form() -> None:
    for beta, dr in ((D(1), D(2.6)), (2.0, 3.0), (D(0.3), D(1e-2))):
        got = cap_response(0, beta, dr, "gaussian")
        assert got == pytest.approx(_gauss_disc(beta, dr), rel=1e-13, abs=1e-300)


def test_gaussian_small_angle_limit_is_noncentral_chi2() -> None:
    # at tiny angles the sphere is flat: P = ncx2.cdf((beta/s)^2, 2, (delta/s)^2)
    dr = 1e-4
    s = dr / FWHM_PER_SIGMA
    for delta, beta in ((0.5e-4, 0.4e-4), (1.5e-4, 1e-4), (0.2e-4, 0.1e-4)):
        want = ncx2.cdf((beta / s) ** 2, 2, (delta / s) ** 2)
        assert cap_response(delta, beta, dr, "gaussian") == pytest.approx(want, rel=1e-7)


def test_issue_numbers() -> None:
    # issue 34: a 1-degree ball 1.5 degrees off the axis of a 2.6-degree facet gets 0.159
    assert round(cap_response(D(1.5), D(1), D(2.6), "gaussian"), 3) == 0.159


def test_tangent_cap_gives_zero() -> None:
    with mpmath.workdps(60):
        alpha, beta = mpmath.mpf(D(2.6)) / 2, mpmath.mpf(D(1))
        assert cap_response(alpha + beta, beta, 2 * alpha, "flat") == 0.0
        # just inside: a sliver
        inside = cap_response(alpha + beta - mpmath.mpf(1e-6), beta, 2 * alpha, "flat")
    assert 0 < inside < 1e-6


def test_ball_geometry() -> None:
    # the lens strictly inside: 1; on the surface: the hemisphere towards the centre
    assert reference_response((0, 0, 0), (0, 1, 0), D(5), (0, 0.5, 0), 1.0, "flat") == 1.0
    with mpmath.workdps(30):
        cap = cap_of_ball((0, 0, 0), (0, 1, 0), (1, 0, 0), 1.0)
    assert cap is not None and float(cap[1]) == pytest.approx(math.pi / 2)
    assert float(cap[0]) == pytest.approx(math.pi / 2)
    # same response whichever frame: ball at distance 10, radius 0.2, 1 degree off the axis
    t = D(1)
    want = cap_response(t, math.asin(0.02), D(4), "gaussian")
    rng = np.random.default_rng(3)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    p = rng.normal(size=3)
    axis = q @ np.array([0.0, 0.0, 3.0])  # not unit: only the direction counts
    c = p + q @ (10 * np.array([math.sin(t), 0.0, math.cos(t)]))
    got = reference_response(p, axis, D(4), c, 0.2, "gaussian")
    assert got == pytest.approx(want, rel=1e-9)


@pytest.mark.parametrize(
    ("args", "word"),
    [
        ((0.1, 0.1, 0.0), "acceptance"),
        ((0.1, 0.1, math.pi), "acceptance"),
        ((-0.1, 0.1, 0.5), "delta"),
        ((0.1, float("nan"), 0.5), "beta"),
    ],
)
def test_bad_parameters(args: tuple[float, float, float], word: str) -> None:
    with pytest.raises(ValueError, match=word):
        cap_response(*args, kind="flat")
    with pytest.raises(ValueError, match="kind"):
        cap_response(0.1, 0.1, 0.5, kind="box")
    with pytest.raises(ValueError, match="radius"):
        reference_response((0, 0, 0), (0, 0, 1), 0.5, (0, 0, 1), 0.0)


def test_gaussian_cut_at_the_cone() -> None:
    # support="cone": K cut at dr/2 and normalised there; concentric: F(beta) / F(dr/2)
    dr, beta = D(2.6), D(1)
    want = _gauss_disc(beta, dr) / _gauss_disc(dr / 2, dr)
    assert cap_response(0, beta, dr, "gaussian", support="cone") == pytest.approx(want, rel=1e-13)
    assert cap_response(0, dr, dr, "gaussian", support="cone") == 1.0
    # zero past the cone, where the sphere-wide kernel still has weight
    assert cap_response(dr / 2 + D(1.01), D(1), dr, "gaussian", support="cone") == 0.0
    assert cap_response(dr / 2 + D(1.01), D(1), dr, "gaussian") > 1e-3
    with pytest.raises(ValueError, match="support"):
        cap_response(0.1, 0.1, 0.5, "gaussian", support="disc")
