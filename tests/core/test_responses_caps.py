"""The cap-level graded responses (eyeviz.core.responses_caps) against an independent
mpmath quadrature, the small-angle chi-square limit and the stiff cases."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import chi2, ncx2

from eyeviz.core.responses_caps import (
    FWHM_TO_SIGMA,
    cap_area,
    flat_response,
    gaussian_response,
    kernel_G,
    lens_area,
)

from .responses_mp import cap_response

TOL = 1e-9

# (a, b, theta): random, tangent from outside and inside, one cap inside the other,
# tiny balls, hemispheres, caps beyond a hemisphere, the axis on the ball's edge
CASES = [
    (0.02, 0.01, 0.015),
    (0.0227, 0.0061, 0.0287 - 1e-12),  # tangent, just overlapping
    (0.0227, 0.0061, 0.0227 + 0.0061 + 1e-13),  # tangent, just apart
    (0.02, 0.005, 0.015),  # internally tangent: the ball's cap inside the acceptance
    (0.02, 0.03, 0.01),  # internally tangent: the acceptance inside the ball's cap
    (0.02, 1e-9, 0.01),  # tiny ball, inside
    (0.02, 1e-12, 0.02),  # tiny ball on the cone's edge
    (0.02, 0.5, 0.3),  # acceptance inside a big ball
    (0.3, math.pi / 2, 1.8),  # the lens on the ball's sphere: a hemisphere
    (0.3, 1.2, 1.0),
    (1.2, 1.0, 0.3),
    (1.2, 1.0, 1.0),  # the axis on the ball's edge
    (0.5, 2.5, 2.0),  # beyond a hemisphere (the core's general caps)
    (1.4, 2.8, 2.9),  # beyond a hemisphere, wrapping past -u
    (0.01, 0.004, 0.0),  # concentric
]


@pytest.mark.parametrize("a,b,theta", CASES)
def test_flat_matches_quadrature(a, b, theta):
    assert abs(float(flat_response(a, b, theta)) - cap_response(a, b, theta)) <= TOL


@pytest.mark.parametrize("support", ["cone", "sphere"])
@pytest.mark.parametrize("a,b,theta", CASES)
def test_gaussian_matches_quadrature(a, b, theta, support):
    got = float(gaussian_response(a, b, theta, support))
    assert abs(got - cap_response(a, b, theta, "gaussian", support)) <= TOL


def test_random_caps_match_quadrature():
    rng = np.random.default_rng(34)
    a = rng.uniform(0.005, 1.4, 12)
    b = rng.uniform(1e-4, math.pi / 2, 12)
    theta = rng.uniform(0, 1, 12) * (a + b + 0.1)
    flat = flat_response(a, b, theta)
    gauss = gaussian_response(a, b, theta)
    for i in range(12):
        assert abs(flat[i] - cap_response(a[i], b[i], theta[i])) <= TOL
        assert abs(gauss[i] - cap_response(a[i], b[i], theta[i], "gaussian")) <= TOL


def test_edges_of_the_range():
    # disjoint caps give 0, a ball holding the lens (b = pi) gives 1, both kinds
    assert flat_response(0.02, 0.01, 0.0301) == 0.0
    assert gaussian_response(0.02, 0.01, 0.0301) == 0.0
    assert flat_response(0.02, math.pi, 2.0) == 1.0
    assert gaussian_response(0.02, math.pi, 2.0) == 1.0
    assert gaussian_response(0.02, math.pi, 2.0, "sphere") == 1.0
    # a tiny ball inside the cap: its area share, positive, to relative accuracy
    tiny = float(flat_response(0.02, 1e-9, 0.01))
    assert tiny == pytest.approx(cap_area(1e-9) / cap_area(0.02), rel=1e-6)


def test_lens_area_is_symmetric_and_bounded():
    rng = np.random.default_rng(1)
    a, b = rng.uniform(0.01, 3.0, (2, 200))
    theta = rng.uniform(0, math.pi, 200)
    ab, ba = lens_area(a, b, theta), lens_area(b, a, theta)
    np.testing.assert_allclose(ab, ba, rtol=0, atol=1e-13)
    assert (ab <= np.minimum(cap_area(a), cap_area(b)) + 1e-13).all()
    assert (ab >= 0).all()


def test_gaussian_small_angle_limit_is_noncentral_chi_square():
    """On the plane, a 2-D Gaussian of width sigma puts P(|X - c| <= r) =
    ncx2(2, |c|^2 / sigma^2).cdf(r^2 / sigma^2) in a disc; the sphere's kernel tends to it
    as the angles shrink (relative differences of order angle^2)."""
    fwhm = 2e-3
    sigma = fwhm * FWHM_TO_SIGMA
    for off, r in ((1.5e-3, 1e-3), (0.0, 5e-4), (3e-3, 2e-3), (0.4e-3, 0.2e-3)):
        want = (
            ncx2(2, (off / sigma) ** 2).cdf((r / sigma) ** 2)
            if off
            else chi2(2).cdf((r / sigma) ** 2)
        )
        got = float(gaussian_response(fwhm / 2, r, off, "sphere"))
        assert got == pytest.approx(want, rel=1e-5, abs=1e-12)
    # the cone's kernel holds half the plane's mass (the edge is at half maximum): a
    # ball inside the cone gets twice the sphere's share
    got = float(gaussian_response(fwhm / 2, 2e-4, 5e-4))
    want = 2 * ncx2(2, (5e-4 / sigma) ** 2).cdf((2e-4 / sigma) ** 2)
    assert got == pytest.approx(want, rel=1e-5)


def test_issue_example_true_gaussian():
    """The issue's example, a 1-degree ball 1.5 degrees off the axis gets 0.159 from a
    true 2-D Gaussian (the small-angle chi-square value, acceptance 2.6 degrees)."""
    d = math.radians
    got = float(gaussian_response(d(2.6) / 2, d(1.0), d(1.5), "sphere"))
    sigma = d(2.6) * FWHM_TO_SIGMA
    want = ncx2(2, (d(1.5) / sigma) ** 2).cdf((d(1.0) / sigma) ** 2)
    assert got == pytest.approx(want, rel=1e-3)
    assert round(got, 2) == 0.16


def test_kernel_G_series_and_closed_form_agree():
    sigma = np.full(7, 0.3)
    psi = np.array([1e-8, 1e-3, 0.1, 0.47, 0.479, 0.481, 0.5])  # both sides of 1.6 sigma
    got = kernel_G(psi, sigma)
    import mpmath as mp

    for p, gv in zip(psi, got, strict=True):
        ref = mp.quad(lambda t: mp.exp(-(t**2) / (2 * mp.mpf(0.3) ** 2)) * mp.sin(t), [0, p])
        assert gv == pytest.approx(float(ref), rel=1e-12, abs=1e-300)


def test_bad_support_is_refused():
    with pytest.raises(ValueError, match="support"):
        gaussian_response(0.1, 0.1, 0.1, "plane")
