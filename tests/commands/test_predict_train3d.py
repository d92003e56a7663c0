"""``eyeviz train learned3d`` and ``eyeviz predict`` on the spherical eyes' sparse 3D data
sets: training is reachable (a tiny run at nside 8), the CSV holds the estimator's own
r, azimuth, elevation per row, and kind mismatches or bad options end in one line, exit
2, nothing written."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz import cli, dataset
from eyeviz.core.domain import Domain3D
from eyeviz.dataset import sparse3d
from eyeviz.estimators import learned3d, registry

TINY = ["--nside", "8", "-n", "1100", "--n-val", "50", "--epochs", "1", "--hidden", "8"]


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    d = tmp_path_factory.mktemp("data3d")
    sparse3d.write3d(d / "d8.npz", 120, Domain3D(nside=8), seed=11)
    dataset.write(d / "planar.npz", 50, seed=2)
    return d


def _csv(path):
    with open(path, encoding="ascii") as fh:
        assert fh.readline() == "r_hat,azimuth_hat,elevation_hat,flagged\n"
    return np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


def _one_line_refusal(capsys, rc, message):
    err = capsys.readouterr().err
    assert rc == 2, err
    assert message in err and "Traceback" not in err, err
    assert err.strip().splitlines()[-1].startswith("eyeviz: error:"), err


@pytest.mark.parametrize("name", ["analytic3d", "limit3d"])
def test_predict_writes_the_estimators_answers(tmp_path, capsys, data, name):
    out = tmp_path / "p.csv"
    # the limit with a loose target and few batches: the same answers either way, faster
    opts = {"accuracy": 0.05, "max_batches": 2} if name == "limit3d" else {}
    flags = [f"--{k.replace('_', '-')}={v}" for k, v in opts.items()]
    rc = cli.main(["predict", "-e", name, *flags, str(data / "d8.npz"), "-o", str(out)])
    assert rc == 0, capsys.readouterr().err
    got = _csv(out)
    ds = sparse3d.load3d(data / "d8.npz")
    want = registry.load(name, domain=ds.domain, **opts).predict_dataset(ds)
    assert got.shape == (len(ds), 4)
    assert np.array_equal(got[:, :3], np.column_stack(list(want)), equal_nan=True)
    assert np.array_equal(got[:, 3], want.flagged)


def test_train_learned3d_then_predict_with_its_weights(tmp_path, capsys, data):
    models = tmp_path / "m"
    rc = cli.main(["train", "learned3d", *TINY, "--seed", "1", "-o", str(models)])
    assert rc == 0, capsys.readouterr().err
    est = learned3d.load(models)
    assert est.domain.nside == 8 and est.hidden == 8
    out = tmp_path / "p.csv"
    argv = ["predict", "-e", "learned3d", "--weights", str(models), str(data / "d8.npz")]
    rc = cli.main([*argv, "-o", str(out)])
    assert rc == 0, capsys.readouterr().err
    ds = sparse3d.load3d(data / "d8.npz")
    pred = est.predict_dataset(ds)
    want = np.column_stack([*pred, pred.flagged])
    assert np.array_equal(_csv(out), want, equal_nan=True)


def test_train_learned3d_takes_a_3d_data_file(tmp_path, capsys):
    d8 = tmp_path / "train.npz"
    sparse3d.write3d(d8, 1300, Domain3D(nside=8), seed=12)
    models = tmp_path / "m"
    argv = ["train", "learned3d", str(d8), "--nside", "8", "--epochs", "1", "--hidden", "4"]
    rc = cli.main([*argv, "--seed", "2", "-o", str(models)])
    assert rc == 0, capsys.readouterr().err
    assert learned3d.load(models).hidden == 4


@pytest.mark.parametrize(
    "args, message",
    [
        (["--nside", "7"], "nside must be an even integer"),
        (["--m", "30"], "--m must be a multiple of 4"),
        (["--nside", "8", "--epochs", "0"], "epochs must be an integer >= 1"),
    ],
)
def test_train_learned3d_refuses_bad_options(tmp_path, capsys, args, message):
    rc = cli.main(["train", "learned3d", *args, "--seed", "1", "-o", str(tmp_path / "m")])
    _one_line_refusal(capsys, rc, message)
    assert not (tmp_path / "m").exists()


@pytest.mark.parametrize(
    "name, file, message",
    [
        ("compact", "d8.npz", "estimator 'compact' answers for planar eyes, but"),
        ("analytic", "d8.npz", "use one of analytic3d, learned3d, limit3d"),
        ("analytic3d", "planar.npz", "'analytic3d' answers for spherical and measured eyes, but"),
        ("learned3d", "d8.npz", "answers for (40.0, 20.0, 180)"),
    ],
)
def test_predict_refuses_the_other_kind(tmp_path, capsys, data, name, file, message):
    out = tmp_path / "p.csv"
    rc = cli.main(["predict", "-e", name, str(data / file), "-o", str(out)])
    _one_line_refusal(capsys, rc, message)
    assert not out.exists()


def test_predict_3d_refuses_design_flags(tmp_path, capsys, data):
    out = tmp_path / "p.csv"
    rc = cli.main(
        ["predict", "-e", "analytic3d", "--h", "30", str(data / "d8.npz"), "-o", str(out)]
    )
    _one_line_refusal(capsys, rc, "carries its design")
    assert not out.exists()


def test_learned3d_over_the_poles_is_flagged_never_written_unmarked(tmp_path, capsys, monkeypatch):
    """Balls over the eye's poles (lit sets {0, npix - 1} in each eye, issues 35.8 and
    36.1): the shipped weights answered r = 1.97e38 and elevation 2.74 rad, exit 0, no
    word. Now the row is flagged (the CSV's column and a count on stderr) and its answer
    is the triangulation's inside the training domain, or nan."""
    est = learned3d.load()
    d = est.domain
    npix = d.npix
    ptr = np.array([0, 2])
    ind = np.array([0, npix - 1])
    p = est.predict((ptr, ind), (ptr, ind))
    assert bool(p.flagged[0])
    assert not np.isfinite(p.r[0]) or learned3d.inside_domain(d, p.r, p.azimuth, p.elevation)[0]
    # the CLI on a file holding such a row beside ordinary ones
    from eyeviz.dataset.records import Dataset3D

    good = sparse3d.load3d(_shipped_like(tmp_path, d))
    rows = []
    for e in ("a", "b"):
        gp, gi = getattr(good, f"indptr_{e}"), getattr(good, f"indices_{e}")
        rows += [np.concatenate([gp, [gp[-1] + 2]]), np.concatenate([gi, [0, npix - 1]])]
    floats = {k: np.concatenate([getattr(good, k), getattr(good, k)[:1]]) for k in sparse3d.FLOATS}
    poles = Dataset3D(*rows, **floats, domain=d, params=dict(good.params))
    path = tmp_path / "poles.npz"
    sparse3d.write_chunks3d(path, len(poles), d, dict(good.params), [poles])
    out = tmp_path / "p.csv"
    # the pole row is hand-made, not its ball's lit sets: the reader's re-computation off
    monkeypatch.setattr(sparse3d.embedded_eyes, "LIT_CHECK_ROWS", 0)
    rc = cli.main(["predict", "-e", "learned3d", str(path), "-o", str(out)])
    err = capsys.readouterr().err
    assert rc == 0, err
    got = _csv(out)
    assert got[-1, 3] == 1 and "1 flagged" in err
    r, az, el = got[-1, :3]
    assert not np.isfinite(r) or learned3d.inside_domain(d, r, az, el)
    assert np.all(learned3d.inside_domain(d, got[:-1, 0], got[:-1, 1], got[:-1, 2]))


def _shipped_like(tmp_path, d):
    path = tmp_path / "ok.npz"
    sparse3d.write3d(path, 6, d, seed=4)
    return path
