"""Seeds: `eyeviz generate` draws a fresh one unless told, prints it and keeps it in an NPZ;
never a shipped model's; a given shipped seed is warned about (issue 25, item 2)."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from eyeviz import cli
from eyeviz.commands import _seeds
from eyeviz.dataset import io as dataset_io

SMALL = ["-n", "40", "--quiet"]


def _npz_seed(path) -> int:
    with np.load(path, allow_pickle=False) as z:
        return json.loads(str(z["meta"]))["params"]["seed"]


def test_the_shipped_metadata_records_its_seeds():
    found = _seeds.shipped_seeds()
    whats = {s.what: s for s in found}
    compact = [s for s in found if "compact" in s.what]
    assert {s.seed for s in compact} == {0, 1}  # training 0, validation 1 (compact.json)
    assert all(s.domain == (40.0, 20.0, 720.0, 1000.0, 5000.0, 500.0) for s in compact)
    bayes = [s for w, s in whats.items() if "bayes" in w]
    assert [s.seed for s in bayes] == [12345]
    assert any("paper" in w for w in whats)


def test_two_runs_without_a_seed_differ_and_print_their_seeds(tmp_path, capsys):
    seeds, data = [], []
    for name in ("train.npz", "test.npz"):
        out = tmp_path / name
        assert cli.main(["generate", *SMALL, "-o", str(out)]) == 0
        out_text = capsys.readouterr().out
        m = re.search(r"seed (\d+) \(drawn afresh; --seed \1 repeats this run\)", out_text)
        assert m, out_text
        assert _npz_seed(out) == int(m.group(1))  # kept where the format allows
        seeds.append(int(m.group(1)))
        data.append(dataset_io.load(out))
    assert seeds[0] != seeds[1]
    assert not np.array_equal(data[0].r, data[1].r)
    shipped = {s.seed for s in _seeds.shipped_seeds()}
    assert not shipped & set(seeds)


def test_the_printed_seed_repeats_the_run(tmp_path, capsys):
    a, b = tmp_path / "a.npz", tmp_path / "b.npz"
    assert cli.main(["generate", *SMALL, "-o", str(a)]) == 0
    seed = re.search(r"seed (\d+)", capsys.readouterr().out).group(1)
    assert cli.main(["generate", *SMALL, "--seed", seed, "-o", str(b)]) == 0
    assert a.read_bytes() == b.read_bytes()


def test_a_fresh_seed_is_never_a_shipped_one(monkeypatch):
    draws = iter([0, 12345, 1, 77])
    monkeypatch.setattr(_seeds.secrets, "randbits", lambda bits: next(draws))
    assert _seeds.fresh_seed() == 77


def test_a_shipped_seed_with_its_parameters_is_warned_about(tmp_path, capsys):
    out = tmp_path / "t.csv"
    assert cli.main(["generate", *SMALL, "--seed", "0", "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "warning: seed 0" in err and "compact weights' training set" in err
    assert "not a held-out test set" in err
    # other parameters draw another set: no warning
    assert cli.main(["generate", *SMALL, "--seed", "0", "--r-max", "4000", "-o", str(out)]) == 0
    assert "warning" not in capsys.readouterr().err
    # a seed no shipped model used: silent
    assert cli.main(["generate", *SMALL, "--seed", "424242", "-o", str(out)]) == 0
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize("bad", ["-1"])
def test_a_negative_seed_is_refused_in_one_line(tmp_path, capsys, bad):
    assert cli.main(["generate", *SMALL, "--seed", bad, "-o", str(tmp_path / "x.csv")]) == 2
    err = capsys.readouterr().err
    assert "seed" in err and err.count("\n") == 1
    assert not (tmp_path / "x.csv").exists()


def test_train_without_a_seed_draws_one_and_records_it(tmp_path):
    """`eyeviz train bayes` (small): the drawn seed is printed, kept in the table's
    metadata and in its recorded command (the shipped table's is 12345)."""
    import subprocess
    import sys

    out = tmp_path / "b.npz"
    res = subprocess.run(
        [sys.executable, "-m", "eyeviz", "train", "bayes", "-n", "2000", "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert res.returncode == 0, res.stderr
    m = re.search(r"bayes: seed (\d+) \(drawn afresh; --seed \1 repeats this run\)", res.stderr)
    assert m, res.stderr
    with np.load(out, allow_pickle=False) as z:
        meta = json.loads(str(z["meta"]))
    assert meta["seed"] == int(m.group(1)) != 12345
    assert meta["command"].endswith(f"--seed {m.group(1)}")


def test_the_estimator_report_test_sets_share_no_seed_with_shipped_training():
    """`report estimators` draws its single- and multi-pass test sets with TEST_SEED and
    TEST_SEED + 1: neither may be a seed a shipped model was fitted on."""
    from eyeviz.reports.estimators_measure import TEST_SEED, TEST_SETS

    shipped = {s.seed for s in _seeds.shipped_seeds()}
    assert shipped  # the metadata was found
    assert not shipped & {TEST_SEED + i for i in range(len(TEST_SETS))}


def test_a_shipped_3d_seed_is_warned_about_and_never_drawn(tmp_path, capsys):
    """The learned3d weights were trained on 3D sets (learned3d.json: train_seed,
    val_seed); a 3D generate with that seed and those parameters is warned about."""
    found = [s for s in _seeds.shipped_seeds() if s.kind == "spherical"]
    assert found, "learned3d.json's seeds not found"
    s = found[0]
    h, l, nside, r_min, r_max, g_max, el_max = s.domain
    out = tmp_path / "t.npz"
    args = ["generate", "-n", "3", "--quiet", "--nside", str(int(nside)), "--h", str(h)]
    args += ["--l", str(l), "--r-min", str(r_min), "--r-max", str(r_max)]
    args += ["--g-max", str(g_max), "--el-max", repr(el_max), "--seed", str(s.seed)]
    assert cli.main([*args, "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert f"warning: seed {s.seed}" in err and "learned3d" in err
    assert s.seed not in {_seeds.fresh_seed() for _ in range(50)}
