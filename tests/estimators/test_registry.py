"""The registry: names, loading, and that torch stays out until a torch estimator loads."""

import subprocess
import sys

import pytest

from eyeviz import estimators


def test_available_names():
    names = estimators.available()
    assert {"compact", "analytic", "bayes", "paper"} <= set(names)


def test_unknown_name_is_a_value_error():
    with pytest.raises(ValueError, match="unknown estimator 'nope'"):
        estimators.load("nope")


def test_load_analytic_is_an_estimator():
    est = estimators.load("analytic")
    assert isinstance(est, estimators.Estimator)
    assert est.name == "analytic"


def _run(code: str) -> str:
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return out.stdout.strip()


def test_import_and_available_do_not_import_torch():
    code = (
        "import sys, eyeviz.estimators as e; e.available(); e.load('analytic');"
        "print('torch' in sys.modules)"
    )
    assert _run(code) == "False"
