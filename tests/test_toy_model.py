"""docs/extending.md, "A new eye model", followed step by step with a toy model in space
(``ToyEyes`` of tests/conftest.py: seven facets per eye, a kind of its own), all the way
through ``eyeviz generate``, ``eyeviz predict`` and ``eyeviz report estimators``; the
app's view of it is tests/app/test_toy_model_view.py. Each step checks that the toy's
own geometry, not the package's idea of it, is what arrives. The last tests give the toy
a data set format of its own kind ("toy", registered in eyeviz.dataset.kinds), written by
generate's write step and read by predict's one run loop."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from eyeviz import cli
from eyeviz.core.eyes import EyeModel
from eyeviz.core.measured_from import as_measured
from eyeviz.dataset import sparse3d
from eyeviz.dataset.kinds import kind_of
from eyeviz.measured import load_eyes, save_eyes


def _balls(n: int, seed: int = 0) -> tuple[np.ndarray, ...]:
    """Balls in front of the toy's eyes, r in [1, 6], g in [0.05, 0.6]."""
    rng = np.random.default_rng(seed)
    r, az, el = rng.uniform(1, 6, n), rng.uniform(0.6, 2.5, n), rng.uniform(-0.6, 0.6, n)
    x, y, z = r * np.cos(el) * np.cos(az), r * np.cos(el) * np.sin(az), r * np.sin(el)
    return x, y, z, rng.uniform(0.05, 0.6, n)


@pytest.fixture(scope="module")
def toy_files(toy_eyes, tmp_path_factory):
    """Steps 2-3: the toy written as an eye file, and a data set generated from it."""
    d = tmp_path_factory.mktemp("toy")
    eye = save_eyes(toy_eyes, d / "toy.eye")
    npz = d / "toy.npz"
    assert cli.main(["generate", "--eye", str(eye), "-n", "40", "--seed", "3", "-o", str(npz)]) == 0
    return eye, npz


def test_step1_the_toy_implements_the_protocol(toy_eyes):
    assert isinstance(toy_eyes, EyeModel)
    assert (toy_eyes.kind, toy_eyes.dims, toy_eyes.facet_counts) == ("toy", 3, (7, 7))
    a, b = toy_eyes.bitmaps(*_balls(500))
    assert a.shape == b.shape == (500, 7)
    both = toy_eyes.in_bfv(*_balls(500))
    assert 20 < both.sum() < 480  # a binocular field, and not everything in it


def test_step2_its_facets_enter_as_a_pair_with_the_toys_own_lit_sets(toy_eyes):
    pair = as_measured(toy_eyes)
    assert pair.facet_counts == (7, 7)
    for w in "AB":
        for got, want in zip(pair.facets(w), toy_eyes.facets(w), strict=True):
            assert np.array_equal(got, want)
    balls = _balls(1000, seed=1)
    for got, want in zip(pair.bitmaps(*balls), toy_eyes.bitmaps(*balls), strict=True):
        assert got.sum() > 300 and np.array_equal(got, want)
    assert np.array_equal(pair.in_bfv(*balls), toy_eyes.in_bfv(*balls))
    for got, want in zip(pair.overlaps_eye(*balls), toy_eyes.overlaps_eye(*balls), strict=True):
        assert np.array_equal(got, want)


def test_step2_a_model_without_facets_is_refused_by_name():
    class NoFacets:
        kind = "nofacets"

    with pytest.raises(TypeError, match="a model with facets\\(eye\\), got NoFacets"):
        as_measured(NoFacets())


def test_step3_the_eye_file_keeps_the_toy_to_the_last_bit(toy_eyes, toy_files):
    eye, _ = toy_files
    assert load_eyes(eye).fingerprint == as_measured(toy_eyes).fingerprint


def test_step3_generate_writes_the_toys_lit_sets(toy_eyes, toy_files):
    _, npz = toy_files
    assert kind_of(npz) == "measured"
    ds = sparse3d.load3d(npz)
    assert len(ds.r) == 40 and ds.domain.facet_counts == (7, 7)
    assert ds.domain.design[2] == as_measured(toy_eyes).fingerprint
    bm = toy_eyes.bitmaps(ds.x, ds.y, ds.z, ds.g)
    for w, want in zip("ab", bm, strict=True):
        indptr, indices = getattr(ds, f"indptr_{w}"), getattr(ds, f"indices_{w}")
        for i in range(40):
            assert np.array_equal(indices[indptr[i] : indptr[i + 1]], np.flatnonzero(want[i]))
    assert toy_eyes.in_bfv(ds.x, ds.y, ds.z, ds.g).all()  # the sampler's field is the toy's


def test_step3_predict_and_report(toy_files, tmp_path, capsys, read_predictions3d):
    _, npz = toy_files
    pred = tmp_path / "p.csv"
    rc = cli.main(["predict", "--estimator", "analytic3d", str(npz), "-o", str(pred)])
    err = capsys.readouterr().err
    assert rc == 0, err
    assert "analytic3d: 40 rows" in err
    ds, vals, err, unit = read_predictions3d(pred, npz)
    assert len(vals) == 40
    # the direction from seven facets 0.3 rad apart: within about a facet at the median,
    # and better than guessing straight ahead (+y) for every ball
    guess = np.arccos(np.clip(unit[:, 1], -1, 1))
    assert np.median(err) < 0.4 and np.median(err) < 0.8 * np.median(guess)

    out = tmp_path / "rep"
    argv = ["report", "estimators", "--data", str(npz), "--estimators", "analytic3d"]
    rc = cli.main([*argv, "--limit-rows", "2", "-o", str(out)])
    text = capsys.readouterr().out
    assert rc == 0 and "analytic3d" in text, text
    md = (out / "estimators3d.md").read_text()
    assert "a measured pair of 7 + 7 facets" in md and "| analytic3d |" in md
    with open(out / "estimators3d.csv", newline="") as f:
        table = {r["estimator"]: r for r in csv.DictReader(f)}
    assert table["analytic3d"]["status"] == "ok" and table["analytic3d"]["rows"] == "40"


# --- a kind of its own: the toy's data set format, registered by this test -------------
#
# docs/extending.md, "A data set format of its own": a model whose lit sets the sparse
# format cannot carry registers a DataFormat for its kind (eyeviz.dataset.kinds); then
# `generate`'s write step, `predict`'s one run loop and the format lookups of the reports
# take its files by that kind. The toy's format below is the test's own (an NPZ of its
# bitmaps, meta {"kind": "toy"}); so are its sampler and its estimator.


class ToyDomain:
    """The toy's domain: its eyes and the ranges it samples (no record of the package)."""

    r_min, r_max, g_max = 1.0, 6.0, 0.6

    def __init__(self, eyes) -> None:
        self.eyes = eyes

    kind = property(lambda self: self.eyes.kind)
    design_names = property(lambda self: tuple(self.eyes.design))
    design = property(lambda self: tuple(float(v) for v in self.eyes.design.values()))


def _toy_write(path, n, domain, *, mode, seed, segments, progress, **own):
    """The toy format's writer: balls in the toy's binocular field (rejection), each
    eye's bitmap of seven facets, the truth in spherical coordinates."""
    import json

    assert mode == "single" and segments is None and not own
    rng = np.random.default_rng(seed)
    cols: list[list[np.ndarray]] = [[], [], [], []]
    while sum(len(c) for c in cols[0]) < n:
        r = rng.uniform(domain.r_min, domain.r_max, 4 * n)
        az, el = rng.uniform(0.6, 2.5, 4 * n), rng.uniform(-0.6, 0.6, 4 * n)
        x, y, z = r * np.cos(el) * np.cos(az), r * np.cos(el) * np.sin(az), r * np.sin(el)
        g = rng.uniform(0.05, domain.g_max, 4 * n)
        keep = domain.eyes.in_bfv(x, y, z, g)
        for c, v in zip(cols, (x, y, z, g), strict=True):
            c.append(v[keep])
    x, y, z, g = (np.concatenate(c)[:n] for c in cols)
    a, b = domain.eyes.bitmaps(x, y, z, g)
    r = np.sqrt(x * x + y * y + z * z)
    meta = json.dumps({"kind": "toy", "design": dict(domain.eyes.design), "n": n})
    with open(path, "wb") as f:
        np.savez(f, meta=np.array(meta), a=a, b=b, r=r, azimuth=np.arctan2(y, x),
                 elevation=np.arcsin(z / r))  # fmt: skip
    if progress is not None:
        progress(n)


class _ToyReader:
    """The toy format's block reader: ``domain`` and blocks of 16 rows."""

    def __init__(self, path, toy_eyes) -> None:
        import json

        from eyeviz import EyevizError

        try:
            with np.load(path) as z:
                self.meta = json.loads(str(z["meta"][()]))
                self.cols = {k: z[k] for k in ("a", "b", "r", "azimuth", "elevation")}
        except Exception as exc:  # noqa: BLE001 - one line naming the file
            raise EyevizError(f"{path}: not a toy data set ({type(exc).__name__})") from None
        assert self.meta["design"] == toy_eyes.design
        self.domain = ToyDomain(toy_eyes)

    def __iter__(self):
        from types import SimpleNamespace

        n = len(self.cols["r"])
        for s in range(0, n, 16):
            yield SimpleNamespace(
                domain=self.domain, **{k: v[s : s + 16] for k, v in self.cols.items()}
            )


class ToyEstimator:
    """Estimator of the toy's rows: the direction of the lit facets' summed axes (both
    eyes), r the middle of the range; flagged where an eye lit fewer than two facets."""

    name = "toytri"

    def __init__(self, domain) -> None:
        self.domain = domain

    def predict_dataset(self, b):
        from eyeviz.estimators.base import Prediction3D

        eyes = self.domain.eyes
        d = b.a.astype(float) @ eyes.facets("A")[1] + b.b.astype(float) @ eyes.facets("B")[1]
        valid = b.a.any(1) & b.b.any(1)
        u = d / np.maximum(np.linalg.norm(d, axis=1), 1e-300)[:, None]
        az = np.where(valid, np.arctan2(u[:, 1], u[:, 0]), np.nan)
        el = np.where(valid, np.arcsin(np.clip(u[:, 2], -1, 1)), np.nan)
        r = np.where(valid, 0.5 * (self.domain.r_min + self.domain.r_max), np.nan)
        flagged = (b.a.sum(1) < 2) | (b.b.sum(1) < 2)
        return Prediction3D(r, az, el, valid, valid & ~flagged, flagged)


@pytest.fixture
def toy_kind(toy_eyes):
    """The toy's data set format and its estimator, registered for this test only."""
    from eyeviz.dataset import kinds
    from eyeviz.estimators import registry

    fmt = kinds.DataFormat(
        "toy",
        reader=lambda path, **kw: _ToyReader(path, toy_eyes),
        loader=lambda path: list(_ToyReader(path, toy_eyes)),
        writer=_toy_write,
        sampler=None,
        chunker=None,
        rows=kinds.SPARSE_ROWS,
        what="a toy data set",
    )
    kinds.register_format(fmt)
    dom = ToyDomain(toy_eyes)
    entry = registry.Entry(
        "toytri", "the toy's facets' axes", lambda **kw: ToyEstimator(dom), design=None,
        kind="spherical", models=("toy",),
    )  # fmt: skip
    registry.register(entry)
    try:
        yield dom
    finally:
        registry.unregister("toytri")
        kinds.unregister_format("toy")


def test_a_kind_of_its_own_goes_through_generate_and_predict(toy_kind, tmp_path, capsys):
    import argparse

    from eyeviz.commands import generate
    from eyeviz.dataset import kinds

    npz = tmp_path / "toy.npz"
    args = argparse.Namespace(output=str(npz), mode="single", seed=5, segments=None, quiet=True)
    generate._write(args, 40, toy_kind, 1)  # generate's one write step, by the domain's kind
    assert kinds.kind_of(npz) == "toy"
    rows = list(kinds.open_reader(npz))
    assert len(rows) == 3 and sum(len(b.r) for b in rows) == 40  # 16 + 16 + 8
    a = np.concatenate([b.a for b in rows])
    assert a.shape == (40, 7) and a.sum(1).min() >= 2  # the toy's own bitmaps, 7 facets

    pred = tmp_path / "p.csv"
    rc = cli.main(["predict", "--estimator", "toytri", str(npz), "-o", str(pred)])
    err = capsys.readouterr().err
    assert rc == 0, err
    assert "toytri: 40 rows" in err and "azimuth MAE" in err
    vals = np.loadtxt(pred, delimiter=",", skiprows=1)
    assert pred.read_text().splitlines()[0] == "r_hat,azimuth_hat,elevation_hat,flagged"
    est = ToyEstimator(toy_kind)
    want = [
        np.column_stack([*est.predict_dataset(b), est.predict_dataset(b).flagged]) for b in rows
    ]
    assert np.array_equal(vals, np.concatenate(want))  # every block, in order, to the last bit
    # the direction of the summed axes is within about a facet of the ball's
    truth = np.concatenate([b.azimuth for b in rows])
    assert np.median(np.abs(vals[:, 1] - truth)) < 0.3

    rc = cli.main(["predict", "--estimator", "analytic3d", str(npz), "-o", str(pred)])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and err.count("\n") == 0
    assert "answers for spherical and measured eyes, but" in err
    assert "is a toy data set; use one of toytri" in err


def test_a_kind_nobody_registered_is_refused_in_one_line(toy_kind, tmp_path, capsys):
    import argparse
    import json

    from eyeviz.commands import generate
    from eyeviz.dataset import kinds

    npz = tmp_path / "toy.npz"
    args = argparse.Namespace(output=str(npz), mode="single", seed=5, segments=None, quiet=True)
    generate._write(args, 8, toy_kind, 1)
    kinds.unregister_format("toy")
    out = tmp_path / "p.csv"
    rc = cli.main(["predict", "--estimator", "toytri", str(npz), "-o", str(out)])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and err.count("\n") == 0 and not out.exists()
    assert err.endswith(
        "no data set format for eyes of kind 'toy' (known kinds: measured, planar, spherical)"
    )
    # a format nobody reads: named, with the known kinds
    odd = tmp_path / "odd.npz"
    np.savez(odd, meta=np.array(json.dumps({"format": "eyeviz.hexagons", "n": 0})))
    rc = cli.main(["predict", "--estimator", "analytic3d", str(odd), "-o", str(out)])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and err.count("\n") == 0 and not out.exists()
    assert "format 'eyeviz.hexagons', which no kind of eyes reads (known kinds: measured, " in err


def test_a_corrupt_file_of_the_kind_is_refused_in_one_line(toy_kind, tmp_path, capsys):
    import argparse
    import zipfile

    from eyeviz.commands import generate

    npz = tmp_path / "toy.npz"
    args = argparse.Namespace(output=str(npz), mode="single", seed=5, segments=None, quiet=True)
    generate._write(args, 8, toy_kind, 1)
    cut, gap = tmp_path / "cut.npz", tmp_path / "gap.npz"
    cut.write_bytes(npz.read_bytes()[:200])  # no meta to read: the planar reader names it
    with zipfile.ZipFile(npz) as z, zipfile.ZipFile(gap, "w") as w:  # the toy's own reader
        for name in z.namelist():
            if name != "a.npy":
                w.writestr(name, z.read(name))
    for path, says in ((cut, "not an eyeviz NPZ data set"), (gap, "not a toy data set")):
        rc = cli.main(
            ["predict", "--estimator", "toytri", str(path), "-o", str(tmp_path / "p.csv")]
        )
        err = capsys.readouterr().err.strip()
        assert rc == 2 and err.count("\n") == 0, err
        assert err.startswith(f"eyeviz: error: {path}: {says}"), err
        assert not (tmp_path / "p.csv").exists()
