"""A measured eye through the spherical side's doors, end to end on the command line:
``eyeviz generate --eye`` (the shipped honeybee) -> ``eyeviz predict --estimator
analytic3d`` -> ``eyeviz report estimators --data``; and the one-line refusals on the way."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from eyeviz import cli
from eyeviz.core.domain import Domain3D
from eyeviz.dataset import algorithm1_3d, sparse3d
from eyeviz.files.eye_io import load_eyes
from eyeviz.measured import shipped_eye

BEE = str(shipped_eye("AM_60185-real.eye"))


@pytest.fixture(scope="module")
def bee_npz(tmp_path_factory):
    out = tmp_path_factory.mktemp("bee") / "bee.npz"
    assert cli.main(["generate", "--eye", BEE, "-n", "12", "--seed", "4", "-o", str(out)]) == 0
    return out


def test_generate_eye_writes_what_the_api_generates(bee_npz, honeybee, capsys):
    ds = sparse3d.load3d(bee_npz)
    dom = Domain3D.for_eyes(honeybee)
    assert ds.domain == dom and ds.domain.design == (honeybee.h, honeybee.l, honeybee.fingerprint)
    want = algorithm1_3d.generate3d(12, dom, seed=4)
    for k in ("indptr_a", "indices_a", "indptr_b", "indices_b", "r", "azimuth", "g", "x"):
        assert np.array_equal(getattr(ds, k), getattr(want, k)), k
    assert ds.params["seed"] == 4


def test_predict_analytic_then_report_estimators(bee_npz, tmp_path, capsys, read_predictions3d):
    pred = tmp_path / "p.csv"
    rc = cli.main(["predict", "--estimator", "analytic3d", str(bee_npz), "-o", str(pred)])
    err = capsys.readouterr().err
    assert rc == 0, err
    assert "analytic3d: 12 rows" in err and "DD MAPE" in err
    ds, vals, err, _ = read_predictions3d(pred, bee_npz)
    assert len(vals) == 12
    # the direction of the ball from the bee is found to a few degrees (the distance is
    # what a 3 mm baseline with 1 degree facets cannot give)
    assert np.median(np.degrees(err)) < 10

    out = tmp_path / "rep"
    rc = cli.main(
        ["report", "estimators", "--data", str(bee_npz), "--limit-rows", "2", "-o", str(out)]
    )
    text = capsys.readouterr().out
    assert rc == 0 and "analytic3d" in text, text
    md = (out / "estimators3d.md").read_text()
    assert "a measured pair of 3187 + 3187 facets" in md and "| analytic3d |" in md
    with open(out / "estimators3d.csv", newline="") as f:
        table = {r["estimator"]: r for r in csv.DictReader(f)}
    assert set(table) == {"analytic3d", "limit3d"} and table["analytic3d"]["status"] == "ok"
    assert table["limit3d"]["status"] == "ok"
    assert table["analytic3d"]["rows"] == "12"
    assert (out / "estimators3d.png").stat().st_size > 1000


@pytest.mark.parametrize("name", ["learned3d", "analytic"])
def test_predict_refuses_an_estimator_that_does_not_answer_for_measured_eyes(
    bee_npz, tmp_path, capsys, name
):
    rc = cli.main(["predict", "--estimator", name, str(bee_npz), "-o", str(tmp_path / "p.csv")])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert "is a measured-eye data set; use one of analytic3d, limit3d" in err
    assert not (tmp_path / "p.csv").exists()


@pytest.mark.parametrize(
    "args, message",
    [
        (["--nside", "8"], "--nside describes model eyes; with --eye the file gives the eyes"),
        (["--h", "3"], "--h describes model eyes"),
        (["--m", "64"], "--m describes model eyes"),
        (["--unique-bitmaps"], "--unique-bitmaps is for the planar data set only"),
        (["--el-max", "2"], "el_max must be a finite number > 0 and <= 1.5708"),
        (["--r-min", "50", "--r-max", "20"], "r_min must be < r_max"),
        (["--g-max", "0.0001"], "no feature can be visible"),
    ],
)
def test_bad_input_is_one_line_exit_2(tmp_path, capsys, args, message):
    rc = cli.main(["generate", "-n", "5", "--eye", BEE, *args, "-o", str(tmp_path / "x.npz")])
    err = capsys.readouterr().err
    assert rc == 2 and message in err and err.count("\n") == 1, err
    assert list(tmp_path.iterdir()) == []


def test_missing_eye_file_and_csv_output_are_refused(tmp_path, capsys):
    rc = cli.main(["generate", "-n", "5", "--eye", str(tmp_path / "no.eye"), "-o", "x.npz"])
    err = capsys.readouterr().err
    assert rc == 2 and "eye file" in err and "not found" in err and err.count("\n") == 1, err
    rc = cli.main(["generate", "-n", "5", "--eye", BEE, "-o", str(tmp_path / "x.csv")])
    err = capsys.readouterr().err
    assert rc == 2 and "written as .npz" in err, err
    assert list(tmp_path.iterdir()) == []


def test_an_implausible_size_is_one_warning_line(tmp_path, capsys):
    out = tmp_path / "m.npz"
    rc = cli.main(
        ["generate", "-n", "2", "--eye", BEE, "--units", "m", "--seed", "1", "-o", str(out)]
    )
    err = capsys.readouterr().err
    assert rc == 0 and out.exists(), err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("generate: warning: ") and "units" in lines[0]
    d = sparse3d.load3d(out).domain
    assert 1000 < d.h < 2000  # metres read as such: the bee is 1000 times larger


def test_report_estimators_on_a_fresh_set_of_an_eye_file(tmp_path, capsys):
    out = tmp_path / "rep"
    argv = ["report", "estimators", "--eye", BEE, "--n-test", "10", "--seed", "3", "-o", str(out)]
    argv += ["--estimators", "analytic3d"]  # the limit is scored in the test above
    rc = cli.main(argv)
    text = capsys.readouterr().out
    assert rc == 0 and "analytic3d" in text, text
    md = (out / "estimators3d.md").read_text()
    assert "10 rows of Algorithm 1 (single pass, seed 3) on the measured eyes" in md
    rc = cli.main([*argv, "--nside", "8"])
    err = capsys.readouterr().err
    assert rc == 2 and "give one of --data, --nside, --eye, not both --nside and --eye" in err, err


def test_predict_limit3d_on_a_measured_eye_data_set(bee_npz, tmp_path, capsys):
    """The limit answers for the honeybee's data set through the command line, every row
    in the prior's range of r, most of them not flagged."""
    pred = tmp_path / "p.csv"
    rc = cli.main(["predict", "--estimator", "limit3d", str(bee_npz), "-o", str(pred)])
    err = capsys.readouterr().err
    assert rc == 0, err
    assert "limit3d: 12 rows" in err
    with open(pred, newline="") as f:
        rows = list(csv.reader(f))
    vals = np.array(rows[1:], float)
    dom = sparse3d.load3d(bee_npz).domain
    assert len(vals) == 12 and np.isfinite(vals).all()
    assert ((vals[:, 0] >= dom.r_min) & (vals[:, 0] <= dom.r_max)).all()
    assert vals[:, 3].sum() <= 2


def test_eye_options_take_a_shipped_eyes_name(tmp_path, capsys):
    """``--eye AM_60185-real.eye`` (the README's commands) names the shipped honeybee
    wherever no such file is here; a name that is neither is one line listing them."""
    name, out = "AM_60185-real.eye", tmp_path / "named.npz"
    rc = cli.main(["generate", "--eye", name, "-n", "12", "--seed", "4", "-o", str(out)])
    assert rc == 0, capsys.readouterr().err
    assert sparse3d.load3d(out).domain == Domain3D.for_eyes(load_eyes(BEE))
    argv = ["report", "estimators", "--eye", name, "--n-test", "10", "--seed", "3"]
    rc = cli.main([*argv, "--estimators", "analytic3d", "-o", str(tmp_path / "rep")])
    assert rc == 0 and name in (tmp_path / "rep" / "estimators3d.md").read_text()
    capsys.readouterr()
    bad = tmp_path / "y.npz"
    rc = cli.main(["generate", "--eye", "no-such-bee.eye", "-n", "5", "-o", str(bad)])
    err = capsys.readouterr().err
    assert rc == 2 and "no shipped eye named 'no-such-bee.eye'" in err and name in err
    assert err.count("\n") == 1 and not bad.exists()
