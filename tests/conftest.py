"""Settings for the whole suite.

Hypothesis' default deadline (200 ms per example) is a wall-clock assertion: on a loaded
machine, or beside another pytest-xdist worker, a correct example can take longer and
fail. No test here asserts on time (speed claims live in ``scripts/bench_*.py``); a hang
is caught by pytest-timeout (``timeout`` in pyproject's ``[tool.pytest.ini_options]``).
"""

import pytest
from hypothesis import settings

settings.register_profile("eyeviz", deadline=None)
settings.load_profile("eyeviz")


@pytest.fixture(scope="session")
def toy_pair():
    """A small measured pair: :func:`toy_measured_pair`."""
    return toy_measured_pair()


@pytest.fixture(scope="session")
def honeybee():
    """The shipped honeybee (AM_60185, 2 x 3187 facets), loaded once."""
    from eyeviz.measured import load_eyes, shipped_eye

    return load_eyes(shipped_eye("AM_60185-real.eye"))


def toy_measured_pair(n_dirs: int = 600, acceptance: float = 0.2):
    """A small measured pair (docs/measured.md) with a wide frontal binocular field: per
    eye, lenses on a sphere of radius 0.5 about (-/+2, 0, 0) looking outwards, the front
    directions (y > 0.2) of a Fibonacci sphere. Fast enough for data sets of a few rows."""
    import numpy as np

    from eyeviz.core.measured import MeasuredEye, MeasuredEyePair

    k = np.arange(n_dirs) + 0.5
    z = 1 - 2 * k / n_dirs
    phi = np.pi * (1 + 5**0.5) * k
    d = np.stack([np.sqrt(1 - z * z) * np.cos(phi), np.sqrt(1 - z * z) * np.sin(phi), z], 1)
    d = d[d[:, 1] > 0.2]
    eyes = [
        MeasuredEye(np.array([sx, 0.0, 0.0]) + 0.5 * d, d, np.full(len(d), acceptance), name=nm)
        for sx, nm in ((-2.0, "A"), (2.0, "B"))
    ]
    return MeasuredEyePair(eyes[0], eyes[1], name="toy", source="tests/conftest.py")
