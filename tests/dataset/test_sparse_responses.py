"""Graded responses in the sparse data set (``generate --responses``): written beside the
lit sets, read back equal to the eyes' own, and checked by the reader as the lit sets are
(out-of-range values, values that are not the eyes', members the meta names missing)."""

from __future__ import annotations

import zipfile

import numpy as np
import pytest

from eyeviz import EyevizError, cli
from eyeviz.core.domain import Domain3D
from eyeviz.dataset import sparse3d
from eyeviz.dataset.algorithm1_3d import generate3d


@pytest.fixture(scope="module")
def toy_responses(tmp_path_factory, toy_pair):
    path = tmp_path_factory.mktemp("responses") / "toy.npz"
    dom = Domain3D.for_eyes(toy_pair)
    sparse3d.write3d(path, 20, dom, seed=7, responses="gaussian")
    return path, dom


def test_values_are_the_eyes_responses(toy_responses, toy_pair):
    path, dom = toy_responses
    ds = sparse3d.load3d(path)
    assert ds.params["responses"] == "gaussian"
    plain = generate3d(20, dom, seed=7)
    np.testing.assert_array_equal(ds.indices_a, plain.indices_a)  # the same lit sets
    (pa, ia, va), (pb, ib, vb) = toy_pair.responses(ds.x, ds.y, ds.z, ds.g, kind="gaussian")
    np.testing.assert_array_equal(ia, ds.indices_a)
    np.testing.assert_array_equal(ds.values_a, va)
    np.testing.assert_array_equal(ds.values_b, vb)
    assert ds.values_a.size == ds.indices_a.size and (ds.values_a > 0).any()


def _rewrite(src, dst, dom, change):
    """The data set of ``src`` written again with its chunk passed through ``change``
    (a valid file: the writer computes the CRCs)."""
    ds = sparse3d.load3d(src)
    change(ds)
    sparse3d.write_chunks3d(dst, len(ds), dom, dict(ds.params), [ds], responses="gaussian")


def test_reader_refuses_a_value_outside_0_1(toy_responses, tmp_path):
    path, dom = toy_responses
    bad = tmp_path / "bad.npz"

    def change(ds):
        ds.values_b[3] = 1.5

    _rewrite(path, bad, dom, change)
    with pytest.raises(EyevizError, match=r"values_b: row \d+: value 1.5 outside \[0, 1\]"):
        sparse3d.load3d(bad)


def test_reader_refuses_values_that_are_not_the_eyes(toy_responses, tmp_path):
    path, dom = toy_responses
    bad = tmp_path / "swapped.npz"

    def change(ds):  # row 1 (a checked row) gets other, valid values
        lo, hi = ds.indptr_a[0], ds.indptr_a[1]
        ds.values_a[lo:hi] = 0.5 * ds.values_a[lo:hi] + 0.25

    _rewrite(path, bad, dom, change)
    with pytest.raises(EyevizError, match="row 1: eye A's gaussian responses are not the eyes'"):
        sparse3d.load3d(bad)


def test_reader_refuses_missing_value_members(toy_responses, tmp_path):
    path, _ = toy_responses
    bad = tmp_path / "missing.npz"
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(bad, "w") as dst:
        for info in src.infolist():
            if info.filename != "values_b.npy":
                dst.writestr(info, src.read(info))
    with pytest.raises(EyevizError, match="member 'values_b' is missing"):
        sparse3d.load3d(bad)


def test_cli_generate_responses(tmp_path, capsys):
    from eyeviz.measured import shipped_eye

    out = tmp_path / "bee.npz"
    bee = str(shipped_eye("AM_60185-real.eye"))
    args = ["generate", "--eye", bee, "-n", "6", "--seed", "2", "--responses", "flat"]
    assert cli.main([*args, "-o", str(out), "--quiet"]) == 0
    ds = sparse3d.load3d(out)
    assert ds.params["responses"] == "flat" and ds.values_a.size == ds.indices_a.size
    rc = cli.main(["generate", "-n", "5", "--responses", "flat", "-o", str(tmp_path / "p.npz")])
    err = capsys.readouterr().err
    assert rc == 2 and "--responses flat needs --eye" in err and err.count("\n") == 1
    assert not (tmp_path / "p.npz").exists()


def test_cli_generate_healpix_cell_responses(tmp_path, capsys):
    """``generate --nside N --responses cell``: the HEALPix cells' shares beside the lit
    sets, checked on reading; ``cell`` without --nside is refused in one line."""
    out = tmp_path / "h.npz"
    args = ["generate", "--nside", "8", "-n", "6", "--seed", "3", "--responses", "cell"]
    assert cli.main([*args, "-o", str(out), "--quiet"]) == 0
    ds = sparse3d.load3d(out)
    assert ds.params["responses"] == "cell" and ds.values_a.size == ds.indices_a.size
    assert ((ds.values_a >= 0) & (ds.values_a <= 1)).all() and (ds.values_b > 0).any()
    from eyeviz.measured import shipped_eye

    bee = str(shipped_eye("AM_60185-real.eye"))
    for extra in (["--eye", bee], []):
        bad = ["generate", *extra, "-n", "5", "--responses", "cell"]
        rc = cli.main([*bad, "-o", str(tmp_path / "p.npz"), "--quiet"])
        err = capsys.readouterr().err
        assert rc == 2 and "--responses cell needs --nside" in err and err.count("\n") == 1
    assert not (tmp_path / "p.npz").exists()
