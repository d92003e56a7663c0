"""Settings for the whole suite.

Hypothesis' default deadline (200 ms per example) is a wall-clock assertion: on a loaded
machine, or beside another pytest-xdist worker, a correct example can take longer and
fail. No test here asserts on time (speed claims live in ``scripts/bench_*.py``); a hang
is caught by pytest-timeout (``timeout`` in pyproject's ``[tool.pytest.ini_options]``).
"""

from hypothesis import settings

settings.register_profile("eyeviz", deadline=None)
settings.load_profile("eyeviz")
