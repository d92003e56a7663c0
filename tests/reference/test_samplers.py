"""The renderers' samplers (eyeviz/reference/samplers.py): their biases and error law."""

from __future__ import annotations

import math

import numpy as np
import pytest

from eyeviz.reference import samplers as S
from eyeviz.reference.responses_reference import cap_response

D = math.radians
DR = D(2.6)


def _rotate(point: np.ndarray, angle: float, axis: np.ndarray) -> np.ndarray:
    """shaders.cu rotatePoint: Rodrigues' formula as the shader writes it."""
    return (
        math.cos(angle) * point
        + math.sin(angle) * np.cross(axis, point)
        + (1 - math.cos(angle)) * np.dot(axis, point) * axis
    )


def _shader_ray(splay: float, roll: float, axis: np.ndarray) -> np.ndarray:
    """shaders.cu generateOffsetRay, transcribed line by line."""
    perp = np.cross(np.array([0.0, 1.0, 0.0]), axis)
    perp = np.array([0.0, 0.0, 1.0]) if perp.sum() == 0 else perp / np.linalg.norm(perp)
    return _rotate(_rotate(axis, splay, perp), roll, axis)


def test_shader_transcription_gives_polar_angle_abs_splay() -> None:
    # the model's premise: CompoundRay's ray is |splay| from the axis, at a uniform roll
    rng = np.random.default_rng(0)
    for _ in range(20):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        splay, roll = rng.normal() * 0.3, rng.uniform() * math.pi
        ray = _shader_ray(splay, roll, axis)
        theta = math.acos(min(1.0, float(ray @ axis)))
        assert theta == pytest.approx(abs(splay), abs=1e-9)


def test_rays_within_half_fwhm() -> None:
    # CompoundRay: P(|Z| <= sqrt(2 ln 2)) = erf(sqrt(ln 2)) = 76.1 %; a 2-D Gaussian: 50 %
    cr = S.fraction_within("compoundray", DR / 2, DR)
    assert cr == pytest.approx(math.erf(math.sqrt(math.log(2))), abs=1e-9)
    assert round(cr, 3) == 0.761
    assert S.fraction_within("gauss2d", DR / 2, DR) == pytest.approx(0.5, abs=1e-4)
    assert S.fraction_within("uniform", DR / 2, DR) == pytest.approx(1.0, abs=1e-12)
    rng = np.random.default_rng(1)
    for sampler, want in (("compoundray", cr), ("gauss2d", 0.5)):
        d, _ = S.draw(sampler, DR, 40_000, rng)
        share = np.mean(np.arccos(np.clip(d[:, 2], -1, 1)) <= DR / 2)
        assert share == pytest.approx(want, abs=0.01)


def test_issue_example_compoundray_gets_0121_not_0159() -> None:
    delta, beta = D(1.5), D(1)
    assert round(cap_response(delta, beta, DR), 3) == 0.159
    q = float(S.expected_response("compoundray", delta, beta, DR))
    assert round(q, 3) == 0.121
    rng = np.random.default_rng(2)
    d, w = S.draw("compoundray", DR, 100_000, rng)
    assert S.sampled_response(d, w, delta, beta) == pytest.approx(q, abs=0.003)


@pytest.mark.parametrize(
    ("delta", "beta"), [(D(1.5), D(1)), (D(0.2), D(3)), (D(2.0), D(0.3)), (0.0, D(0.5))]
)
def test_unbiased_samplers_converge_to_the_exact_responses(delta: float, beta: float) -> None:
    g = S.expected_response("gauss2d", delta, beta, DR)
    assert g == pytest.approx(cap_response(delta, beta, DR, "gaussian"), abs=1e-9)
    u = S.expected_response("uniform", delta, beta, DR)
    assert u == pytest.approx(cap_response(delta, beta, DR, "flat"), abs=1e-9)


def test_invertpy_layout() -> None:
    d, w = S.draw("invertpy", DR, 1000, np.random.default_rng(3))
    assert d.shape == (7, 3)
    theta = np.arccos(np.clip(d[:, 2], -1, 1))
    assert theta[0] == 0 and np.allclose(theta[1:], DR / 2)
    assert w[0] == 1 and np.allclose(w[1:], math.exp(-0.5))
    roll = np.sort(np.mod(np.arctan2(d[1:, 1], d[1:, 0]), 2 * math.pi))
    assert np.allclose(np.diff(roll), math.pi / 3)


@pytest.mark.parametrize("sampler", ["gauss2d", "compoundray", "invertpy", "uniform"])
def test_error_law_against_monte_carlo(sampler: str) -> None:
    # E[(estimate - exact)^2] in closed form against repeated real draws
    delta, beta, n, reps = D(1.2), D(0.8), 16, 2000
    exact = cap_response(delta, beta, DR)
    rng = np.random.default_rng(4)
    e = np.array([math.sin(delta), 0.0, math.cos(delta)])
    if sampler == "invertpy":
        draws = [S.draw(sampler, DR, n, rng) for _ in range(reps)]
        d, w = np.stack([x[0] for x in draws]), np.stack([x[1] for x in draws])
    else:
        d, w = S.draw(sampler, DR, n * reps, rng)
        d, w = d.reshape(reps, n, 3), w.reshape(reps, n)
    est = (w * (d @ e >= math.cos(beta))).sum(1) / w.sum(1)
    # the batched hit test is sampled_response's
    assert est[0] == S.sampled_response(d[0], w[0], delta, beta)
    err = est - exact
    want = float(S.mean_square_error(sampler, exact, delta, beta, DR, n))
    assert np.mean(err**2) == pytest.approx(want, rel=0.15)


def test_unknown_sampler() -> None:
    with pytest.raises(ValueError, match="unknown sampler"):
        S.expected_response("mitsuba", 0.1, 0.1, DR)
