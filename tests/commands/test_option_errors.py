"""Degenerate numeric options (0, tiny, huge, too many threads) are refused at the command
line's boundary with an EyevizError naming the option and the value, before any work:
never a raw Python text ("cannot write empty image", "Overflow when unpacking long",
"out of memory", "float division by zero") and never a run that allocates terabytes.

Each case runs the sub-command in-process (``args._run``) so the exception's *type* is
checked, not only the line the CLI prints; the ones that used to start unbounded work run
in a subprocess with a time limit instead.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import subprocess
import sys
from pathlib import Path

import pytest

from eyeviz import EyevizError, cli
from eyeviz.core.domain import Domain
from eyeviz.resources import scenes_dir

ROOT = Path(__file__).resolve().parents[2]
BIG = "1000000000000"  # 10^12


def _refusal(argv: list[str]) -> EyevizError:
    """The EyevizError the sub-command raises for ``argv`` (fails on any other outcome)."""
    args = cli.build_parser().parse_args(argv)
    out = io.StringIO()
    with (
        pytest.raises(Exception) as info,
        contextlib.redirect_stdout(out),
        contextlib.redirect_stderr(out),
    ):
        args._run(args)
    exc = info.value
    assert isinstance(exc, EyevizError), f"{type(exc).__name__}: {exc}"
    return exc


def _data_csv(tmp_path: Path) -> Path:
    p = tmp_path / "d.csv"
    rc = cli.main(["generate", "-n", "50", "-o", str(p), "--quiet"])
    assert rc == 0
    return p


SCENE = str(scenes_dir() / "default.toml")

# (argv after the output arguments are filled in, words the message must contain)
CASES = [
    # PIL "cannot write empty image" / FreeType "invalid ppem value" before
    (["snapshot", SCENE, "-o", "{out}.png", "--scale", "1e-308"], ["scale", "1e-308"]),
    (["snapshot", SCENE, "-o", "{out}.png", "--scale", "0.01"], ["scale", "0.01"]),
    # MemoryError "out of memory" before
    (["report", "stability", "-o", "{out}", "-n", BIG], ["-n", BIG]),
    (["report", "stability", "-o", "{out}", "-n", "0"], ["-n", "got 0"]),
    # "n (rows) must be in ..." (named the generator's n, not the option) before
    (
        ["report", "estimators", "-o", "{out}", "--estimators", "analytic", "--n-test", BIG],
        ["--n-test", BIG],
    ),
    (
        ["report", "trajectories", "-o", "{out}", "--estimators", "analytic"]
        + ["--min-count", BIG, "--max-count", BIG],
        ["--min-count", BIG],
    ),
    (
        ["report", "trajectories", "-o", "{out}", "--estimators", "analytic"]
        + ["--min-count", "50", "--max-count", "40"],
        ["--max-count", "40"],
    ),
    # torch "Overflow when unpacking long" / "value cannot be converted to type float"
    (["train", "paper", "-o", "{out}", "-n", "100", "--threads", BIG], ["threads", BIG]),
    (["train", "paper", "-o", "{out}", "-n", "100", "--ad-lr", "1e308"], ["ad_lr", "1e+308"]),
    (["train", "compact", "-o", "{out}", "-n", "5000", "--threads", BIG], ["threads", BIG]),
    (["train", "compact", "-o", "{out}", "-n", "5000", "--hidden", BIG], ["hidden", BIG]),
    # a plain ValueError of the geometry before (same text, not the boundary's error)
    (["predict", "{data}", "-o", "{out}.csv", "-e", "analytic", "--h", "0"], ["h", "0.0"]),
    (["predict", "{data}", "-o", "{out}.csv", "-e", "limit", "--m", "3"], ["m", "got 3"]),
    (["train", "bayes", "-o", "{out}", "-n", "100", "--l", "nan"], ["l", "nan"]),
]


IDS = [" ".join([a[0], "" if a[0] == "snapshot" else a[1], *w]) for a, w in CASES]


@pytest.mark.parametrize("argv,words", CASES, ids=IDS)
def test_degenerate_option_named(tmp_path, argv, words):
    data = _data_csv(tmp_path) if "{data}" in argv else None
    out = tmp_path / "out"
    argv = [a.format(out=out, data=data) for a in argv]
    exc = _refusal(argv)
    msg = str(exc)
    assert "\n" not in msg
    for w in words:
        assert w in msg, (w, msg)
    assert not list(tmp_path.glob("out*")), "a refused command wrote output"


@pytest.mark.slow
@pytest.mark.parametrize(
    "argv,words",
    [
        (["train", "bayes", "-o", "{out}", "-n", BIG], ["n", BIG]),
        (["train", "compact", "-o", "{out}", "-n", BIG], ["n_train", BIG]),
        (
            ["snapshot", SCENE, "-o", "{out}.png", "--width", "10", "--scale", "20"],
            ["scale 20", "width 10", "60,000 px"],
        ),
    ],
    ids=["bayes -n", "compact -n", "snapshot 60000 px"],
)
def test_refused_before_unbounded_work(tmp_path, argv, words):
    """These used to start generating 10^12 rows (hours, then out of memory), or drawing
    a 60000 px wide PNG (gigabytes of pixels); now one line before any work."""
    argv = [a.format(out=tmp_path / "out") for a in argv]
    proc = subprocess.run(
        [sys.executable, "-m", "eyeviz", *argv],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=ROOT,
    )
    assert proc.returncode == 2, proc.stderr
    errors = [ln for ln in proc.stderr.splitlines() if ln.startswith("eyeviz: error:")]
    assert len(errors) == 1, proc.stderr  # after the "training into ..." line
    line = errors[0]
    for w in words:
        assert w in line, (w, line)
    assert not list(tmp_path.glob("out*")), "a refused command wrote output"


def test_domain_refuses_a_bad_design_with_eyeviz_error():
    for kw in ({"h": 0.0}, {"l": float("nan")}, {"m": 3}, {"h": 10.0, "l": 20.0}):
        with pytest.raises(EyevizError):
            Domain(**kw)


def _run_cli(fn) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = cli._run(argparse.Namespace(_run=fn))
    return code, err.getvalue()


def test_division_by_zero_is_reported_as_a_bug(monkeypatch):
    """A raw "float division by zero" names no input: it is a bug's line, not a refusal."""
    monkeypatch.delenv("EYEVIZ_DEBUG", raising=False)
    code, err = _run_cli(lambda _a: 1.0 / 0.0)
    assert code == 2
    assert err.startswith("eyeviz: error: unexpected ZeroDivisionError: float division by zero")
    assert "EYEVIZ_DEBUG=1" in err


def test_debug_reraises_division_by_zero(monkeypatch):
    monkeypatch.setenv("EYEVIZ_DEBUG", "1")
    with pytest.raises(ZeroDivisionError):
        _run_cli(lambda _a: 1.0 / 0.0)


def test_a_named_value_error_stays_a_refusal(monkeypatch):
    monkeypatch.delenv("EYEVIZ_DEBUG", raising=False)

    def bad(_a):
        raise EyevizError("scale must be >= 0.25, got 0")

    code, err = _run_cli(bad)
    assert (code, err) == (2, "eyeviz: error: scale must be >= 0.25, got 0\n")
