"""How the field's renderers sample a facet's acceptance, and what each sampler converges to.

A renderer estimates a facet's response to a ball by casting N rays from the lens and
averaging (weighted) whether each ray hits the ball. In the facet's frame (axis +z) a ray
u hits the ball whose cap has centre e = (sin delta, 0, cos delta) and angular radius
beta iff u . e >= cos(beta) (:mod:`eyeviz.reference.responses_reference` defines the
cap). Four samplers, for a facet of full acceptance angle dr (FWHM), sigma = dr / 2.3548:

- ``gauss2d``: i.i.d. rays of the 2-D Gaussian kernel on the sphere, density
  exp(-theta^2 / (2 sigma^2)) per solid angle (the exact ``gaussian`` response's kernel):
  theta from the planar Rayleigh law, kept with probability sin(theta) / theta (so the
  density carries sin(theta), not theta), roll uniform. Unbiased for ``gaussian``.
- ``compoundray``: CompoundRay's ommatidial ray generator (libEyeRenderer3/shaders.cu,
  ``__raygen__ommatidium`` and ``generateOffsetRay``): a splay angle
  ``curand_normal * acceptanceAngleRadians / FWHM_SD_RATIO`` (signed) about an axis
  perpendicular to the ommatidial axis, then a roll ``curand_uniform * M_PIf`` about the
  ommatidial axis; the facet's value is the mean over its samples. The polar angle is
  |splay| (folded into [0, pi]), so theta is half-normal, not Rayleigh: the density per
  solid angle is phi(theta) / sin(theta), which piles rays at the axis.
- ``invertpy``: InvertPy's ``CompoundEye`` (src/invertpy/sense/vision.py, ``reset`` and
  ``_sense``): the axis with weight 1 and 6 rays at theta = dr / 2 (the acceptance angle
  there is ``omm_rho``; the rays are the axis rotated by Euler 'XY' (k pi / 3, rho / 2)),
  each weight exp(-1/2), a weighted average. Deterministic: 7 rays, whatever N; its
  error over balls comes from the ring's roll relative to the ball.
- ``uniform``: i.i.d. rays uniform over the acceptance cone's solid angle (cos(theta)
  uniform in [cos(dr/2), 1]). Unbiased for ``flat``.

**What a sampler converges to.** For the i.i.d. samplers the hit count is binomial: with
q the probability that one ray hits, the N-ray estimate has mean q and variance
q (1 - q) / N, so its mean-square error against the exact response R is
(q - R)^2 + q (1 - q) / N. q is the integral of the sampler's polar-angle density p(theta)
against the cap's azimuthal share w(theta) / (2 pi) (:func:`expected_response`, numerical
quadrature with endpoint-clustered Gauss-Legendre nodes split at the kinks). For
``invertpy`` the 6 ring rays are equally spaced in roll, so for a random roll the number
inside the cap is floor(6 w / 2 pi) or one more, with the fractional part as probability.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable

import numpy as np

__all__ = [
    "SAMPLERS",
    "FWHM_PER_SIGMA",
    "INVERTPY_RING_WEIGHT",
    "cap_share",
    "draw",
    "expected_response",
    "sampled_response",
    "mean_square_error",
    "fraction_within",
]

SAMPLERS = ("gauss2d", "compoundray", "invertpy", "uniform")
FWHM_PER_SIGMA = 2.0 * math.sqrt(2.0 * math.log(2.0))
#: InvertPy's weight of each of its 6 ring rays (vision.py: ``self._w_gau = np.exp(-.5)``).
INVERTPY_RING_WEIGHT = math.exp(-0.5)
_GL_NODES = 48


def _check(sampler: str) -> None:
    if sampler not in SAMPLERS:
        raise ValueError(f"unknown sampler {sampler!r}; known: {', '.join(SAMPLERS)}")


def cap_share(theta, delta, beta) -> np.ndarray:
    """w(theta) / (2 pi): the share of the circle at polar angle theta about the axis that
    lies in the cap (delta, beta); broadcast."""
    theta, delta, beta = np.broadcast_arrays(*map(np.asarray, (theta, delta, beta)))
    s = np.sin(delta) * np.sin(theta)
    lhs = np.cos(beta) - np.cos(delta) * np.cos(theta)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(s > 0, lhs / np.where(s > 0, s, 1.0), np.where(lhs <= 0, -2.0, 2.0))
    return np.arccos(np.clip(c, -1.0, 1.0)) / np.pi


def _density(sampler: str, dr: float) -> tuple[Callable[[np.ndarray], np.ndarray], float]:
    """The polar-angle density p(theta) of an i.i.d. sampler, and the top of its support."""
    s = dr / FWHM_PER_SIGMA
    if sampler == "gauss2d":
        # composite Gauss-Legendre over [0, min(pi, 40 sigma)] (beyond: below e^-800)
        x, w = _leggauss(_GL_NODES)
        top = min(math.pi, 40 * s)
        h = top / 16
        t = (np.arange(16)[:, None] + (x + 1) / 2) * h
        norm = float((np.exp(-(t**2) / (2 * s * s)) * np.sin(t) * w * h / 2).sum())
        return lambda th: np.exp(-(th**2) / (2 * s * s)) * np.sin(th) / norm, math.pi
    if sampler == "compoundray":

        def folded(th: np.ndarray) -> np.ndarray:
            # |splay| folded into [0, pi]: the normal's mass at theta + 2 pi k and 2 pi k - theta
            th = np.asarray(th, float)
            ks = 2 * math.pi * np.arange(-3, 4).reshape((7,) + (1,) * th.ndim)
            z = np.exp(-((th + ks) ** 2) / (2 * s * s)) + np.exp(-((ks - th) ** 2) / (2 * s * s))
            return z.sum(axis=0) / (s * math.sqrt(2 * math.pi))

        return folded, math.pi
    if sampler == "uniform":
        a = dr / 2
        return lambda th: np.sin(th) / (1 - math.cos(a)), a
    raise ValueError(f"{sampler!r} is not an i.i.d. sampler")


@functools.lru_cache(maxsize=8)
def _leggauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(n)
    x.flags.writeable = w.flags.writeable = False
    return x, w


@functools.lru_cache(maxsize=8)
def _gl(n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = _leggauss(n)
    t = (x + 1) / 2
    # smoothstep t -> 3t^2 - 2t^3 clusters the nodes at both ends (sqrt kinks there)
    return 3 * t**2 - 2 * t**3, w / 2 * (6 * t - 6 * t**2)


def expected_response(sampler: str, delta, beta, dr: float) -> np.ndarray:
    """q: what the sampler converges to (its mean over draws) for caps (delta, beta);
    arrays broadcast; dr the full acceptance angle (FWHM), radians."""
    _check(sampler)
    delta, beta = np.broadcast_arrays(np.asarray(delta, float), np.asarray(beta, float))
    if sampler == "invertpy":
        w0 = 1.0 * (delta <= beta)
        ring = cap_share(np.full(delta.shape, dr / 2), delta, beta)
        k = INVERTPY_RING_WEIGHT
        return (w0 + 6 * k * ring) / (1 + 6 * k)
    p, top = _density(sampler, dr)
    u, wu = _gl(_GL_NODES)
    kinks = np.stack([np.abs(delta - beta), delta + beta, 2 * np.pi - delta - beta], -1)
    kinks = np.sort(np.clip(kinks, 0.0, top), axis=-1)
    ends = np.zeros(delta.shape + (1,))
    edges = np.concatenate([ends, kinks, ends + top], -1)
    out = np.zeros(delta.shape)
    for j in range(edges.shape[-1] - 1):
        a, b = edges[..., j, None], edges[..., j + 1, None]
        th = a + (b - a) * u
        f = p(th) * cap_share(th, delta[..., None], beta[..., None])
        out += ((b - a) * f * wu).sum(-1)
    return out


def draw(
    sampler: str, dr: float, n: int, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """(directions (n, 3), weights (n,)): n rays of the sampler in the facet's frame (axis
    +z); ``invertpy`` ignores n and gives its 7 rays at a random roll."""
    _check(sampler)
    s = dr / FWHM_PER_SIGMA
    if sampler == "invertpy":
        roll = rng.uniform(0, 2 * np.pi) + np.arange(6) * np.pi / 3
        th = np.concatenate([[0.0], np.full(6, dr / 2)])
        ph = np.concatenate([[0.0], roll])
        w = np.concatenate([[1.0], np.full(6, INVERTPY_RING_WEIGHT)])
    elif sampler == "compoundray":
        splay = rng.normal(size=n) * s  # signed, as the shader's curand_normal
        ph = rng.uniform(size=n) * np.pi  # curand_uniform * M_PIf
        th, w = splay, np.ones(n)
    elif sampler == "uniform":
        ct = rng.uniform(math.cos(dr / 2), 1.0, n)
        th, ph, w = np.arccos(ct), rng.uniform(0, 2 * np.pi, n), np.ones(n)
    else:
        th = np.empty(0)
        while th.size < n:
            t = s * np.sqrt(-2 * np.log1p(-rng.uniform(size=2 * n)))
            keep = (t < np.pi) & (rng.uniform(size=t.size) * t <= np.sin(t))
            th = np.concatenate([th, t[keep]])
        th, ph, w = th[:n], rng.uniform(0, 2 * np.pi, n), np.ones(n)
    d = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
    return d, w


def sampled_response(dirs: np.ndarray, weights: np.ndarray, delta: float, beta: float) -> float:
    """The weighted share of the rays that hit the cap (delta, beta)."""
    e = np.array([math.sin(delta), 0.0, math.cos(delta)])
    hit = dirs @ e >= math.cos(beta)
    return float((weights * hit).sum() / weights.sum())


def mean_square_error(
    sampler: str, exact, delta, beta, dr: float, n: int, q: np.ndarray | None = None
) -> np.ndarray:
    """E[(estimate - exact)^2] over the sampler's draws with n rays a facet (exact); q the
    sampler's :func:`expected_response` if known."""
    q = expected_response(sampler, delta, beta, dr) if q is None else np.asarray(q)
    exact = np.asarray(exact, float)
    if sampler != "invertpy":
        return (q - exact) ** 2 + q * (1 - q) / n
    k = INVERTPY_RING_WEIGHT
    share = cap_share(np.full(q.shape, dr / 2), *np.broadcast_arrays(delta, beta))
    m = 6 * share
    lo = np.floor(m + 1e-12)
    frac = np.clip(m - lo, 0.0, 1.0)
    w0 = 1.0 * (np.asarray(delta) <= np.asarray(beta))
    v_lo = (w0 + k * lo) / (1 + 6 * k)
    v_hi = (w0 + k * np.minimum(lo + 1, 6)) / (1 + 6 * k)
    return (1 - frac) * (v_lo - exact) ** 2 + frac * (v_hi - exact) ** 2


def fraction_within(sampler: str, theta: float, dr: float) -> float:
    """The share of the sampler's rays (by weight) within polar angle theta of the axis."""
    _check(sampler)
    if sampler == "invertpy":
        k = INVERTPY_RING_WEIGHT
        return (1.0 + (6 * k if theta >= dr / 2 else 0.0)) / (1 + 6 * k)
    p, top = _density(sampler, dr)
    u, wu = _gl(4 * _GL_NODES)
    b = min(theta, top)
    return float((b * p(b * u) * wu).sum())
