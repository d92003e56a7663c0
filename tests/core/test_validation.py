"""The one argument checker and the one Domain: scikit-learn style one-line messages."""

from __future__ import annotations

import math

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.domain import DEFAULTS, PAPER_DOMAIN, Domain
from eyeviz.core.validation import check_choice, check_int, check_positive, check_real


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: check_int("m", 7, ge=4, even=True), "m must be an even integer >= 4, got 7"),
        (lambda: check_int("m", 2, ge=4, even=True), "m must be an even integer >= 4, got 2"),
        (lambda: check_int("n", True, ge=1), "n must be an integer >= 1, got True"),
        (lambda: check_int("n", 3.5, ge=1), "n must be an integer >= 1, got 3.5"),
        (lambda: check_int("n", math.nan), "n must be an integer, got nan"),
        (lambda: check_int("n", math.inf, ge=1), "n must be an integer >= 1, got inf"),
        (lambda: check_int("n", "5", ge=1), "n must be an integer >= 1, got '5'"),
        (lambda: check_int("n", None), "n must be an integer, got None"),
        (lambda: check_int("n", np.bool_(True)), "n must be an integer, got "),
        (lambda: check_int("n", 11, ge=1, le=10), "n must be an integer >= 1 and <= 10, got 11"),
        (lambda: check_int("n", 1e23, le=10), "n must be an integer <= 10, got 1e+23"),
        (
            lambda: check_int("m", 10**5000, le=10),
            "m must be an integer <= 10, got an integer of about 5001 digits",
        ),
        (
            lambda: check_int("m", 10**60, le=9),
            "m must be an integer <= 9, got 10000000000000000000...(61",
        ),
        (lambda: check_real("g_max", math.nan, gt=0), "g_max must be a finite number > 0, got nan"),
        (lambda: check_real("r", math.inf), "r must be a finite number, got inf"),
        (lambda: check_real("x", "abc"), "x must be a finite number, got 'abc'"),
        (lambda: check_real("x", None), "x must be a finite number, got None"),
        (lambda: check_real("p", 1.0, ge=0, lt=1), "p must be a finite number >= 0 and < 1"),
        (lambda: check_positive("h", 0), "h must be a finite number > 0, got 0"),
        (lambda: check_choice("mode", "x", ("a", "b")), "mode must be one of 'a', 'b', got 'x'"),
    ],
)
def test_refusals_are_one_line_naming_the_parameter(call, message):
    with pytest.raises(EyevizError) as info:
        call()
    assert str(info.value).startswith(message) and "\n" not in str(info.value)


def test_accepted_values_are_converted_not_clamped():
    assert check_int("m", np.int64(720), ge=4, even=True) == 720
    assert type(check_int("m", np.int64(720))) is int


@pytest.mark.parametrize("value", [720, 720.0, np.int32(720), np.float64(720.0), np.float32(720)])
def test_the_integer_rule_takes_whole_number_floats(value):
    """One rule for every integer (API, CLI, scene and data files): an integer, or a float
    holding a whole number (JSON, TOML and numpy hand numbers over as floats)."""
    got = check_int("m", value, ge=4, le=720, even=True)
    assert got == 720 and type(got) is int


@pytest.mark.parametrize("value", [720.5, 721.0, 722.0, True, "720", None, [720], math.nan])
def test_the_integer_rule_refuses_the_rest(value):
    with pytest.raises(EyevizError, match="^m must be an even integer >= 4 and <= 720, got "):
        check_int("m", value, ge=4, le=720, even=True)
    assert check_real("r", "2.5", gt=0) == 2.5
    assert check_real("r", np.float32(0.5), le=0.5) == 0.5
    assert check_real("r", math.inf, finite=False) == math.inf


def test_domain_defaults_and_refusals():
    assert PAPER_DOMAIN == Domain(**DEFAULTS)
    assert Domain().design == (40.0, 20.0, 720) and Domain().width == 360
    assert Domain.from_dict({**PAPER_DOMAIN.to_dict(), "extra": 1}) == PAPER_DOMAIN
    with pytest.raises(EyevizError, match="r_min must be < r_max"):
        Domain(r_min=5000, r_max=1000)
    with pytest.raises(EyevizError, match="g_max must be a finite number > 0, got nan"):
        Domain(g_max=math.nan)
    with pytest.raises(ValueError, match="m"):
        Domain(m=7)


def test_public_paths_of_domain_still_work():
    from eyeviz.estimators import PAPER_DOMAIN as P2
    from eyeviz.estimators import Domain as D2
    from eyeviz.estimators.base import Domain as D3

    assert D2 is Domain and D3 is Domain and P2 is PAPER_DOMAIN
