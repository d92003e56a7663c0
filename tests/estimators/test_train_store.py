"""Training output: the user directory by default, never the shipped assets unless asked,
staged then swapped in (an interruption leaves the previous model as it was)."""

from __future__ import annotations

import hashlib
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from eyeviz import EyevizError, estimators
from eyeviz.estimators import compact, store
from eyeviz.resources import models_dir

ROOT = Path(__file__).resolve().parents[2]
SMALL = {"n": 4096, "n_val": 500, "epochs": 1, "threads": 1}


def _hashes(d: Path) -> dict[str, str]:
    return {
        str(p.relative_to(d)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(d.rglob("*"))
        if p.is_file()
    }


def test_user_models_dir_follows_eyeviz_home(tmp_path, monkeypatch):
    monkeypatch.setenv("EYEVIZ_HOME", str(tmp_path))
    assert store.user_models_dir() == tmp_path / "models"
    monkeypatch.delenv("EYEVIZ_HOME")
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "xdg"))
    assert store.user_models_dir() == tmp_path / "xdg" / "eyeviz" / "models"
    assert store.resolve_out_dir(None, False) == tmp_path / "xdg" / "eyeviz" / "models"
    assert store.resolve_out_dir(None, True, "paper") == models_dir() / "paper"
    with pytest.raises(EyevizError, match="either -o DIR or --into-assets"):
        store.resolve_out_dir("x", True)


def test_staged_swaps_on_success_and_keeps_old_on_error(tmp_path):
    out = tmp_path / "m"
    with store.staged(out) as st:
        (st / "w.pt").write_text("new")
        (st / "w.json").write_text("{}")
    assert (out / "w.pt").read_text() == "new"
    with pytest.raises(RuntimeError), store.staged(out) as st:
        (st / "w.pt").write_text("half")
        raise RuntimeError("boom")
    assert (out / "w.pt").read_text() == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m"]  # no staging left behind


def test_interrupted_fit_leaves_previous_model_untouched(tmp_path):
    out = tmp_path / "models"
    path = estimators.fit("compact", None, out, **SMALL)
    assert path == out
    before = _hashes(out)
    assert set(before) == {"compact.json", "compact_dd.pt", "compact_ad.pt"}

    def interrupt(label, ep, total, val):
        if label == "AD":  # the DD checkpoint has been written (into the staging dir)
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        compact.fit(None, out, n=4096, n_val=500, epochs=2, seed=3, threads=1, progress=interrupt)
    assert _hashes(out) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["models"]
    estimators.load("compact", path=out).predict([0] * 360, [0] * 360)


@pytest.mark.slow
def test_sigint_during_train_leaves_previous_output(tmp_path):
    home = tmp_path / "home"
    out = home / "models"
    # the previous output, trained in this process (the signal is the point, not this fit)
    estimators.fit("compact", None, out, **SMALL)
    before = _hashes(out)
    env = {**os.environ, "PYTHONPATH": str(ROOT), "EYEVIZ_HOME": str(home)}
    args = ["train", "compact", "-n", "8192", "--n-val", "500", "--epochs", "400"]
    args += ["--patience", "400", "--seed", "5", "--threads", "1"]
    proc = subprocess.Popen(
        [sys.executable, "-m", "eyeviz", *args],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 120
        while not list(home.glob(".models.staging-*/compact_dd.pt")):
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline, "no checkpoint in the staging dir"
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode != 0
    assert _hashes(out) == before
    assert not list(home.glob(".models.staging-*"))


@pytest.mark.slow
def test_train_leaves_shipped_assets_unchanged(tmp_path, monkeypatch, eyeviz_main):
    # the commands in this process: their output directories, not their processes, are
    # the point (three Python starts, two of them importing torch: about 4 CPU-seconds)
    assets = models_dir()
    before = _hashes(assets)
    home = tmp_path / "home"
    monkeypatch.setenv("EYEVIZ_HOME", str(home))
    res = eyeviz_main("train", "compact", "-n", "4096", "--n-val", "500", "--epochs", "1")
    assert res.returncode == 0, res.stderr
    assert str(home / "models") in res.stderr + res.stdout  # the output dir is printed
    assert _hashes(assets) == before
    assert (home / "models" / "compact.json").is_file()
    data = tmp_path / "d.npz"
    assert eyeviz_main("generate", "-n", "100", "-o", data).returncode == 0
    res = eyeviz_main(
        "predict", "-e", "compact", "--weights", home / "models", data, "-o", tmp_path / "p.csv"
    )
    assert res.returncode == 0, res.stderr
    assert len((tmp_path / "p.csv").read_text().splitlines()) == 101


def test_train_bayes_npz_name_into_user_dir(tmp_path, monkeypatch, eyeviz_main):
    monkeypatch.setenv("EYEVIZ_HOME", str(tmp_path / "home"))
    out = tmp_path / "t" / "b.npz"
    res = eyeviz_main("train", "bayes", "-n", "20000", "-o", out)
    assert res.returncode == 0, res.stderr
    est = estimators.load("bayes", path=out)
    assert est.metadata["sample_size"] == 20000


#: eyeviz train options refused in one line (before the fit, and torch, is imported)
BAD_TRAINING_OPTIONS = [
    (["paper", "--ad-lr", "nan"], "ad_lr must be a finite number > 0 and <= 10, got nan"),
    (["paper", "--ad-lr", "inf"], "ad_lr must be a finite number > 0 and <= 10, got inf"),
    (["paper", "--ad-lr", "0"], "ad_lr must be a finite number > 0 and <= 10, got 0.0"),
    (["paper", "--dd-momentum", "1", "-n", "20"], "dd_momentum must be"),
    (["paper", "-n", "5"], "n must be an integer >= 10, got 5"),
    (["paper", "--budget", "-3"], "budget must be a finite number > 0"),
    (["compact", "-n", "1000"], "-n must be >= 4096 (one batch"),
    (["compact", "--threads", "0"], "threads must be an integer >= 1 and <= 1024, got 0"),
    (["bayes", "-n", "0"], "n must be an integer >= 1 and <= 1000000000, got 0"),
]


@pytest.mark.parametrize("args, message", BAD_TRAINING_OPTIONS)
def test_bad_training_options_one_line(tmp_path, monkeypatch, eyeviz_main, args, message):
    monkeypatch.setenv("EYEVIZ_HOME", str(tmp_path))
    res = eyeviz_main("train", *args)  # in this process: the refusal, not the process, is the point
    assert res.returncode == 2
    last = res.stderr.strip().splitlines()[-1]
    assert last.startswith("eyeviz: error: ") and message in last, res.stderr
    assert "Traceback" not in res.stderr
    assert not (tmp_path / "models").exists() or not any((tmp_path / "models").rglob("*.pt"))


@pytest.mark.parametrize("args, message", BAD_TRAINING_OPTIONS)
def test_bad_training_options_are_refused_before_the_fit_is_imported(
    tmp_path, monkeypatch, args, message
):
    """`eyeviz train` checks the numbers before it imports the fit (torch, seconds): the
    same one-line refusal, the fit never reached (eyeviz.estimators.fit_checks)."""
    from eyeviz import cli
    from eyeviz.estimators import registry

    def no_fit(*_a, **_k):
        raise AssertionError("the fit was reached")

    monkeypatch.setattr(registry.Entry, "fit_estimator", no_fit)
    monkeypatch.setenv("EYEVIZ_HOME", str(tmp_path))
    parsed = cli.build_parser().parse_args(["train", *args, "--seed", "1"])
    with pytest.raises(EyevizError, match=re.escape(message)):
        parsed._run(parsed)


def test_into_assets_and_out_together_refused(tmp_path, monkeypatch, eyeviz_main):
    monkeypatch.setenv("EYEVIZ_HOME", str(tmp_path))
    res = eyeviz_main("train", "compact", "-o", tmp_path, "--into-assets")
    assert res.returncode == 2
    assert "not allowed with" in res.stderr


def test_staged_moves_the_json_metadata_last(tmp_path, monkeypatch):
    """A reader that finds the metadata finds the weights it describes: *.json is moved
    into place after every other file."""
    moved = []
    real = os.replace
    monkeypatch.setattr(store.os, "replace", lambda a, b: moved.append(Path(b).name) or real(a, b))
    with store.staged(tmp_path / "out") as tmp:
        for name in ("z_meta.json", "a_weights.pt", "m.npz", "b_meta.json"):
            (tmp / name).write_text(name)
    assert moved[-2:] == ["b_meta.json", "z_meta.json"]
    assert sorted(moved[:-2]) == ["a_weights.pt", "m.npz"]
    assert (tmp_path / "out" / "m.npz").read_text() == "m.npz"


def test_compact_help_states_the_batch_the_check_enforces():
    """The help of `train compact -n` names the one-batch floor fit_checks refuses below."""
    from eyeviz.estimators import registry
    from eyeviz.estimators.fit_checks import COMPACT_BATCH

    (n_option,) = [o for o in registry.get("compact").fit_options if "--n-train" in o.flags]
    assert f"at least one batch, {COMPACT_BATCH})" in n_option.kwargs["help"]
