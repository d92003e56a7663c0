"""The 3D design grid and point: one-line errors naming the parameter, the grid's order,
and a point's rows (bins, counts, determinism, the triangulation's accuracy)."""

import math

import numpy as np
import pytest

from eyeviz import EyevizError
from eyeviz.core.domain import Domain3D
from eyeviz.estimators import registry
from eyeviz.estimators.metrics import bootstrap_se
from eyeviz.study.grid import design_grid3d
from eyeviz.study.point import COLUMNS3D, EL_BINS, DesignPoint3D, evaluate3d


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"nside": "16,7"}, ["nside must be an even integer", "got 7"]),
        ({"nside": "0"}, ["nside must be an even integer", "got 0"]),
        ({"nside": "16,x"}, ["nside:", "'x' is not a number"]),
        ({"nside": ""}, ["nside: empty list"]),
        ({"h": "5", "l": "10"}, ["no design in the grid has l < h"]),
        ({"n": 0}, ["n must be", "got 0"]),
        ({"seed": -1}, ["seed", "-1"]),
        ({"el_max": 2.0}, ["el_max", "2.0"]),
        ({"el_max": 0}, ["el_max"]),
        ({"prior": "uniform"}, ["prior must be one of", "'uniform'"]),
        (
            {"estimator": "no such"},
            ["estimator must be an estimator of the spherical eyes", "'no such'"],
        ),
        ({"estimator": "limit"}, ["analytic3d", "got 'limit'"]),  # the planar one
        ({"r_min": 5000, "r_max": 100}, ["r_max"]),
        ({"g_max": -1}, ["g_max", "-1"]),
        # g_max below r_min sin(gamma/2): no ball can light two facets (named design)
        ({"h": "40", "l": "20", "nside": "16", "g_max": 10}, ["h=40, l=20, nside=16", "g_max=10"]),
    ],
)
def test_bad_grids_are_refused_in_one_line_naming_the_parameter(kwargs, words):
    with pytest.raises(EyevizError) as err:
        design_grid3d(**kwargs)
    msg = str(err.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg, msg


def test_the_grid_keeps_l_below_h_in_order_without_duplicates():
    pts = design_grid3d("20,40,20", "10,20", "16,8,16", n=10, seed=3, estimator="analytic3d")
    got = [(p.h, p.l, p.nside) for p in pts]
    assert got == [(20, 10, 16), (20, 10, 8), (40, 10, 16), (40, 10, 8), (40, 20, 16), (40, 20, 8)]
    assert {(p.n, p.seed, p.estimator, p.m) for p in pts} == {
        (10, 3, "analytic3d", 64),
        (10, 3, "analytic3d", 32),
    }
    assert len({p.key for p in pts}) == len(pts)


def test_a_points_rows_are_whole_and_deterministic():
    p = DesignPoint3D(h=40, l=20, nside=16, n=400, seed=5)
    a, b = evaluate3d(p), evaluate3d(p)
    strip = [{k: v for k, v in r.items() if k != "seconds"} for r in a]
    assert strip == [{k: v for k, v in r.items() if k != "seconds"} for r in b]
    assert all(tuple(r) == COLUMNS3D for r in a)
    names = [r["bin"] for r in a]
    assert names == ["all", *(f"r{i}" for i in range(8)), *(f"e{j}" for j in range(EL_BINS))]
    by = {r["bin"]: r for r in a}
    assert by["all"]["count"] == 400
    assert sum(by[f"r{i}"]["count"] for i in range(8)) == 400
    assert sum(by[f"e{j}"]["count"] for j in range(EL_BINS)) == 400
    assert by["e0"]["lo"] == pytest.approx(-math.pi / 6) and by["e5"]["hi"] == pytest.approx(
        math.pi / 6
    )
    assert a[0]["gamma"] == pytest.approx(2 * math.pi / 64) and a[0]["m"] == 64
    # another seed: other test elements, other errors
    c = evaluate3d(DesignPoint3D(h=40, l=20, nside=16, n=400, seed=6))
    assert c[0]["dd_mape"] != a[0]["dd_mape"]


def test_the_default_estimator_finds_a_known_ball_and_errors_shrink_with_nside():
    d = Domain3D(h=40, l=20, nside=64)
    eyes = d.eyes
    x, y, z, g = np.array([300.0]), np.array([1400.0]), np.array([200.0]), np.array([150.0])
    (pa, ia), (pb, ib) = eyes.lit_csr(x, y, z, g)
    p = registry.load(DesignPoint3D().estimator, domain=d).predict((pa, ia), (pb, ib))
    r, az, el = p.r, p.azimuth, p.elevation
    true_r = math.sqrt(300**2 + 1400**2 + 200**2)
    assert not p.flagged[0]
    assert abs(r[0] - true_r) / true_r < 0.03
    assert az[0] == pytest.approx(math.atan2(1400, 300), abs=2e-3)
    assert el[0] == pytest.approx(math.asin(200 / true_r), abs=2e-3)
    coarse = evaluate3d(DesignPoint3D(nside=16, n=600))[0]
    fine = evaluate3d(DesignPoint3D(nside=64, n=600))[0]
    assert fine["dd_mape"] < coarse["dd_mape"] / 2
    assert fine["el_mae_deg"] < coarse["el_mae_deg"] / 2


def test_the_estimator_is_a_parameter_loaded_from_the_registry():
    """A registered 3D estimator is loaded with the point's Domain3D and measured like the
    default (here one that answers the default's triangulation, as a plain record)."""
    from types import SimpleNamespace

    seen = {}

    class Tri:
        def __init__(self, domain):
            seen["domain"] = domain
            self.inner = registry.load("analytic3d", domain=domain)

        def predict(self, lit_a, lit_b):
            p = self.inner.predict(lit_a, lit_b)
            return SimpleNamespace(
                r=p.r, azimuth=p.azimuth, elevation=p.elevation, flagged=p.flagged
            )

    registry.register(
        registry.Entry(
            "tri_for_test",
            "test",
            load=lambda domain: Tri(domain),
            any_design=True,
            kind="spherical",
        )
    )
    try:
        p = DesignPoint3D(h=40, l=20, nside=16, n=300, seed=2)
        q = DesignPoint3D(h=40, l=20, nside=16, n=300, seed=2, estimator="tri_for_test")
        a, b = evaluate3d(p), evaluate3d(q)
        assert seen["domain"] == p.domain
        assert [r["estimator"] for r in b] == ["tri_for_test"] * len(b)
        drop = ("seconds", "estimator")
        assert [{k: v for k, v in r.items() if k not in drop} for r in a] == [
            {k: v for k, v in r.items() if k not in drop} for r in b
        ]
        assert p.key != q.key
    finally:
        registry.unregister("tri_for_test")
    with pytest.raises(EyevizError, match="unknown estimator 'tri_for_test'"):
        evaluate3d(q)


def test_each_bin_states_the_sampling_error_of_its_dd_and_elevation_error():
    """dd_se and el_se (issue 38.3) are the bootstrap standard errors of the bin's mean
    over its own rows: recomputed here from the same test set and answers, they agree,
    and both are close to the textbook sd / sqrt(count)."""
    from eyeviz.dataset.algorithm1_3d import iter_chunks3d, make_params3d

    p = DesignPoint3D(h=40, l=20, nside=16, n=500, seed=9)
    rows = {r["bin"]: r for r in evaluate3d(p)}
    est = registry.load(p.estimator, domain=p.domain)
    parts = []
    for c in iter_chunks3d(p.n, make_params3d(p.domain, p.prior, p.seed)):
        q = est.predict((c.indptr_a, c.indices_a), (c.indptr_b, c.indices_b))
        parts.append(np.column_stack([c.r, q.r, c.elevation, q.elevation]))
    r, rh, el, eh = np.concatenate(parts).T
    ape = 100 * np.abs(rh - r) / r
    ele = np.degrees(np.abs(eh - el))
    for name, sel in (("all", np.ones(r.size, bool)), ("r3", (r >= 2500) & (r < 3000))):
        b = rows[name]
        assert b["count"] == sel.sum() > 30
        assert b["dd_mape"] == pytest.approx(ape[sel].mean(), rel=1e-9)
        assert b["dd_se"] == pytest.approx(bootstrap_se(ape[sel]), rel=1e-9)
        assert b["el_se"] == pytest.approx(bootstrap_se(ele[sel]), rel=1e-9)
        textbook = ape[sel].std() / math.sqrt(sel.sum())
        assert 0.85 * textbook < b["dd_se"] < 1.15 * textbook
    assert rows["r3"]["dd_se"] > rows["all"]["dd_se"]  # fewer rows, larger error
