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


def test_every_entry_declares_its_contract():
    from eyeviz.estimators import registry

    for e in registry.entries():
        assert e.help and "\n" not in e.help and len(e.help) < 120, e.name
        assert e.any_design == (e.design is None), e.name
        if e.learns:
            assert e.weights_hint.startswith(f"eyeviz train {e.name}"), e.name
        for opt in (*e.load_options, *e.fit_options):
            assert opt.flags and opt.dest.isidentifier(), (e.name, opt.flags)


def test_bayes_help_says_median_not_mean():
    from eyeviz.estimators import registry

    assert "median" in registry.get("bayes").help
    assert "mean" not in registry.get("bayes").help


@pytest.mark.slow
def test_needs_torch_is_true_exactly_for_torch_estimators():
    code = (
        "import sys; from eyeviz.estimators import registry as r;"
        "import eyeviz.estimators as e;"
        "out = {};\n"
        "for n in ('analytic', 'bayes', 'compact'):\n"
        "    before = 'torch' in sys.modules; e.load(n); out[n] = 'torch' in sys.modules\n"
        "print(out['analytic'], out['bayes'], out['compact'],"
        " r.get('analytic').needs_torch, r.get('bayes').needs_torch, r.get('compact').needs_torch)"
    )
    assert _run(code) == "False False True False False True"


def test_register_a_plug_in_and_unregister():
    from eyeviz import EyevizError
    from eyeviz.estimators import registry
    from eyeviz.estimators.analytic import AnalyticEstimator

    entry = registry.Entry("mine", "a test plug-in", lambda **kw: AnalyticEstimator(**kw))
    registry.register(entry)
    try:
        assert "mine" in estimators.available()
        assert isinstance(estimators.load("mine"), AnalyticEstimator)
        with pytest.raises(EyevizError, match="already registered"):
            registry.register(entry)
        with pytest.raises(EyevizError, match="does not learn"):
            estimators.fit("mine")
    finally:
        registry.unregister("mine")
    assert "mine" not in estimators.available()


def test_limit_entry_listed_only_when_its_module_exists():
    import importlib.util

    from eyeviz.estimators import registry

    present = importlib.util.find_spec("eyeviz.estimators.limit") is not None
    assert ("limit" in estimators.available()) == present
    assert registry._REGISTRY["limit"].any_design


@pytest.mark.slow
def test_the_paper_entry_needs_torch():
    """Its weights are not shipped, so it cannot be loaded here: its module imports torch."""
    code = (
        "import sys; from eyeviz.estimators import registry as r;"
        "import eyeviz.estimators.paper;"
        "print('torch' in sys.modules, r.get('paper').needs_torch)"
    )
    assert _run(code) == "True True"
