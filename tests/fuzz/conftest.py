"""Fuzz suite (issue 13): hypothesis over scene TOML, CSV/NPZ data sets and model
directories. Property: a correct result, or an EyevizError (API) / one line and exit 2
(CLI); never a traceback, a hang, or a changed input file.

Examples are derandomised (the same inputs every run) and budgeted so the whole suite
runs in well under a minute; ``EYEVIZ_FUZZ_SCALE=10`` multiplies every budget. Each test
counts what it tried and what held; the tally is printed at the end of the run (the
figures of the README).
"""

from __future__ import annotations

import collections
import hashlib
import os

from hypothesis import HealthCheck, settings

SCALE = float(os.environ.get("EYEVIZ_FUZZ_SCALE", "1"))
TALLY: dict[str, collections.Counter] = collections.defaultdict(collections.Counter)


def fuzz_settings(examples: int):
    """No per-example deadline: a wall-clock limit fails on a loaded machine. A hang is
    caught by pytest-timeout (pyproject), and a subprocess by its own timeout."""
    return settings(
        max_examples=max(1, int(examples * SCALE)),
        deadline=None,
        derandomize=True,
        database=None,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
    )


def count(category: str, outcome: str) -> None:
    TALLY[category]["tried"] += 1
    TALLY[category][outcome] += 1


def digest(path) -> str:
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


def assert_one_line(msg: str) -> None:
    assert msg and "\n" not in msg.strip() and len(msg) < 1000, repr(msg[:2000])
    assert "Traceback" not in msg and "unexpected " not in msg, msg


def pytest_terminal_summary(terminalreporter):
    if not TALLY:
        return
    terminalreporter.write_sep("-", "fuzz tally (tried / correct result / refused in one line)")
    for cat in sorted(TALLY):
        c = TALLY[cat]
        bugs = {k: v for k, v in c.items() if k.startswith("bug")}
        terminalreporter.write_line(
            f"{cat:32s} tried {c['tried']:5d}  ok {c['ok']:5d}  refused {c['refused']:5d}"
            + (f"  {bugs}" if bugs else "")
        )
