"""`field="both-eyes"` of the 3D Algorithm 1 (`eyeviz generate --nside N --field both-eyes`)
against the default wedge (docs/spherical.md, "Which field")."""

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.cli import main
from eyeviz.core.domain import Domain3D
from eyeviz.dataset.algorithm1_3d import _sight_clear, generate3d, make_params3d

D = Domain3D(nside=8)


@pytest.fixture(scope="module")
def both():
    return generate3d(200, D, "single", 11, field="both-eyes")


def test_both_eyes_rows_are_seen_by_both_eyes_and_reach_outside_the_wedge(both):
    x, y, z, g = both.x, both.y, both.z, both.g
    assert (np.diff(both.indptr_a) >= 2).all() and (np.diff(both.indptr_b) >= 2).all()
    ta, tb = D.eyes.overlaps_eye(x, y, z, g)
    assert not ta.any() and not tb.any()
    assert (y > 0).all()
    assert (
        _sight_clear(x, y, z, -D.h, D.h, D.l).all() and _sight_clear(x, y, z, D.h, -D.h, D.l).all()
    )
    outside = ~np.asarray(D.eyes.in_bfv(x, y, z, g), bool)
    assert 0.1 < outside.mean() < 0.6  # the wedge leaves out a large part of what both see
    assert both.params["field"] == "both-eyes"
    # the stored lit sets are the exact ones
    (pa, ia), _ = D.eyes.lit_csr(x[:20], y[:20], z[:20], g[:20])
    assert np.array_equal(pa, both.indptr_a[:21]) and np.array_equal(ia, both.indices_a[: pa[-1]])


def test_the_wedge_stays_the_default_and_keeps_its_records():
    default = generate3d(60, D, "single", 11)
    wedge = generate3d(60, D, "single", 11, field="wedge")
    assert "field" not in default.params  # files of the default field keep their bytes
    assert np.array_equal(default.r, wedge.r) and np.array_equal(default.indices_a, wedge.indices_a)
    assert np.asarray(D.eyes.in_bfv(default.x, default.y, default.z, default.g), bool).all()


def test_sight_clear_against_points_along_the_segment():
    rng = np.random.default_rng(3)
    p = rng.normal(size=(3, 400)) * np.array([[120.0], [60.0], [60.0]])
    t = np.linspace(0, 1, 2001)[:, None]
    for src, other in ((-40.0, 40.0), (40.0, -40.0)):
        dx = p[0] - src
        d2 = (src + t * dx - other) ** 2 + (t * p[1]) ** 2 + (t * p[2]) ** 2
        brute = d2.min(axis=0) > 20.0**2
        fast = _sight_clear(p[0], p[1], p[2], src, other, 20.0)
        near = np.abs(np.sqrt(d2.min(axis=0)) - 20.0) < 0.05  # the sampling's resolution
        assert np.array_equal(fast[~near], brute[~near])
        assert (~fast).sum() > 10 and fast.sum() > 10


def test_fields_refused_where_they_do_not_apply(toy_pair, capsys, tmp_path):
    with pytest.raises(EyevizError, match="field"):
        make_params3d(D, field="cones")
    with pytest.raises(EyevizError, match="a measured pair's binocular field is 'both-eyes'"):
        make_params3d(Domain3D.for_eyes(toy_pair), field="wedge")
    assert make_params3d(Domain3D.for_eyes(toy_pair)).field == "both-eyes"
    assert (
        main(["generate", "-n", "10", "--field", "both-eyes", "-o", str(tmp_path / "p.csv")]) == 2
    )
    err = capsys.readouterr().err
    assert "--field both-eyes needs --nside or --eye" in err and err.count("\n") == 1
    assert not (tmp_path / "p.csv").exists()
