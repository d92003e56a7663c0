"""The vector figure: drawn from the scene model, one path per ommatidium and feature,
only the scene's layers, text as text, runs merged where triangles are below a pixel."""

import io
import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from eyeviz.model import scene as scene_mod
from eyeviz.model.state import compute_state
from eyeviz.render.mpl import vector
from eyeviz.render.mpl.layers.table import GROUPS

SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"
SVG = "{http://www.w3.org/2000/svg}"


def _svg(sc, **kw) -> ET.Element:
    import matplotlib

    fig = vector.figure(sc, dpi=vector.VECTOR_DPI, **kw)
    buf = io.BytesIO()
    with matplotlib.rc_context(vector.RC):
        fig.savefig(buf, format="svg")
    return ET.fromstring(buf.getvalue())


def _groups(root, prefix):
    return {g.get("id"): g for g in root.iter(f"{SVG}g") if (g.get("id") or "").startswith(prefix)}


def _paths_in(group):
    return list(group.iter(f"{SVG}path")) + list(group.iter(f"{SVG}use"))


def test_one_path_per_ommatidium_and_feature_small_m():
    sc = scene_mod.load(SCENES / "figure2.toml")
    root = _svg(sc)
    omm = _groups(root, "ommatidium-")
    omm = {k: v for k, v in omm.items() if not k.startswith("ommatidium-number")}
    m = sc.eyes.m
    assert set(omm) == {f"ommatidium-{e}-{k}" for e in "AB" for k in range(m)}
    assert all(len(_paths_in(g)) == 1 for g in omm.values())
    feats = _groups(root, "feature-")
    assert set(feats) == {"feature-feature"}
    assert len(_paths_in(feats["feature-feature"])) == 1
    # the lit ommatidia carry the feature's colour, the rest the unlit grey
    st = compute_state(sc)
    lit = {f"ommatidium-A-{k}" for k in np.flatnonzero(st.owner_a >= 0)}
    for gid, g in omm.items():
        style = _paths_in(g)[0].get("style", "")
        colour = sc.features[0].color.lower()
        assert (colour in style.lower()) == (
            gid in lit
            or (gid.startswith("ommatidium-B") and st.owner_b[int(gid.rsplit("-", 1)[1])] >= 0)
        )


def test_text_is_text_and_labels_present():
    sc = scene_mod.load(SCENES / "default.toml")
    root = _svg(sc)
    texts = " ".join("".join(t.itertext()) for t in root.iter(f"{SVG}text"))
    for word in ("target", "far", "side", sc.title, "\u03b8 = 120\u00b0"):
        assert word in texts
    assert "[173, 180]" in texts  # the lit interval beside the bitmap strip


@pytest.mark.slow
def test_unmerged_default_scene_has_every_triangle():
    sc = scene_mod.load(SCENES / "default.toml")
    omm = _groups(_svg(sc, merge=False), "ommatidium-")
    assert len([k for k in omm if k.count("-") == 2]) == 2 * 720


def _expected_runs(sc, eye: str) -> set[str]:
    """Runs of equal colour per ommatidium, from EyePair.intervals and a plain loop
    (independent of eyeviz's own run and owner helpers)."""
    pair = sc.eyes.pair()
    m = pair.m
    colour = ["unlit"] * m
    for f in sc.features:
        LA, RA, LB, RB = pair.intervals(np.array([f.x]), np.array([f.y]), np.array([f.g]))
        lo, hi = (int(LA[0]), int(RA[0])) if eye == "A" else (int(LB[0]), int(RB[0]))
        if hi <= lo:
            continue
        for k in range(lo, hi + 1):
            colour[k % m] = f.color.lower()
    out, start = set(), 0
    for k in range(1, m + 1):
        if k == m or colour[k] != colour[start]:
            out.add(
                f"ommatidia-{eye}-{start}-{k - 1}" if k - start > 1 else f"ommatidium-{eye}-{start}"
            )
            start = k
    return out


def test_merged_runs_match_the_lit_intervals():
    sc = scene_mod.load(SCENES / "default.toml")
    root = _svg(sc, merge=True)
    runs = _groups(root, "ommatidia-") | _groups(root, "ommatidium-")
    ids = sorted(k for k in runs if "number" not in k)
    for e in "AB":
        want = _expected_runs(sc, e)
        assert want == {i for i in ids if i.split("-")[1] == e}


def test_huge_m_merges_runs():
    sc = scene_mod.load(SCENES / "default.toml")
    sc.eyes.m = 100_000
    root = _svg(sc)
    runs = [k for k in _groups(root, "ommatidi") if "number" not in k]
    # 3 features: at most 2 * (3 lit + 4 unlit) runs, never 10^5 paths
    assert 2 <= len(runs) <= 14
    n_paths = len(list(root.iter(f"{SVG}path")))
    assert n_paths < 400


def test_only_the_scenes_layers_are_drawn():
    sc = scene_mod.load(SCENES / "default.toml")
    sc.layers = ["features"]
    root = _svg(sc)
    assert _groups(root, "feature-")
    for prefix in ("ommatidi", "bfv", "bitmap", "readout", "label", "tangent", "sector", "inset"):
        assert not _groups(root, prefix), prefix
    sc.layers = ["eyes", "bfv", "features", "tangents", "sectors"]
    root = _svg(sc)
    for prefix in ("ommatidi", "bfv-wedge", "tangent-", "sector-", "inset"):
        assert _groups(root, prefix), prefix
    assert not _groups(root, "bitmap")


def test_predictions_drawn_as_ghosts_and_out_of_domain_greyed():
    sc = scene_mod.load(SCENES / "figure5.toml")
    sc.layers = ["eyes", "bfv", "features", "predictions", "readout"]
    sc.estimators = ["analytic"]
    st = compute_state(sc)
    r_hat, phi_hat = st.r * 1.05, st.phi + 0.01
    root = _svg(sc, predictions={"analytic": (r_hat, phi_hat)})
    ghosts = _groups(root, "prediction-analytic-")
    domain = st.in_domain()
    assert not domain.all() and domain.any()
    want = {
        f"prediction-analytic-{f.name.replace(' ', '-')}"
        for f, ok in zip(sc.features, domain, strict=True)
        if ok
    }
    assert set(ghosts) == want
    texts = " ".join("".join(t.itertext()) for t in root.iter(f"{SVG}text"))
    assert "outside the networks' domain" in texts
    for i in np.flatnonzero(~domain):  # the reason in full, short enough for one column
        why = "not in the BFV" if not st.in_bfv[i] else "not seen by both eyes"
        assert f"analytic: outside the networks' domain ({why})" in texts
    assert "+5.0 %" in texts


def test_predictions_from_a_real_estimator():
    sc = scene_mod.load(SCENES / "default.toml")
    sc.layers = ["features", "predictions", "readout"]
    sc.estimators = ["analytic"]
    root = _svg(sc)
    assert set(_groups(root, "prediction-analytic-")) == {
        "prediction-analytic-target",
        "prediction-analytic-far",
        "prediction-analytic-side",
    }


def test_ambiguity_and_trajectory_layers():
    sc = scene_mod.load(SCENES / "default.toml")
    sc.layers = ["features", "ambiguity", "trajectory", "readout"]
    sc.trajectory = scene_mod.Trajectory("horizontal", 3000.0, 50.0)
    root = _svg(sc)
    assert set(_groups(root, "ambiguity-")) == {
        "ambiguity-target",
        "ambiguity-far",
        "ambiguity-side",
    }
    assert _groups(root, "trajectory-horizontal")


@pytest.mark.parametrize("name", ["default", "figure2", "figure3b", "figure5"])
def test_every_shipped_scene_draws(name):
    sc = scene_mod.load(SCENES / f"{name}.toml")
    root = _svg(sc)
    assert _groups(root, "feature-")


def test_predictions_for_a_scene_the_estimator_was_not_made_for():
    """m = 24 against an estimator trained for m = 720: a one-line note, not a crash;
    analytic triangulation answers for any eyes (issue 10 item 4)."""
    sc = scene_mod.load(SCENES / "figure3b.toml")
    sc.features.append(scene_mod.Feature("front", 0.0, 150.0, 20.0, "#0072B2"))
    sc.layers = ["eyes", "features", "predictions", "readout"]
    sc.estimators = ["compact", "analytic"]
    root = _svg(sc)
    texts = " ".join("".join(t.itertext()) for t in root.iter(f"{SVG}text"))
    assert "compact: trained for h = 40, l = 20, m = 720" in texts
    assert not _groups(root, "prediction-compact-")
    assert _groups(root, "prediction-analytic-")


# --- the figure's geometry checked from first principles (issue 9: four injected bugs) ---

H3B = 40.0  # figure3b.toml: h = 40, eye A at (-h, 0), eye B at (h, 0)


def _figure3b(**kw):
    sc = scene_mod.load(SCENES / "figure3b.toml")
    sc.features.append(scene_mod.Feature("wide", -120.0, 220.0, 70.0, "#0072B2"))
    return sc, vector.figure(sc, dpi=vector.VECTOR_DPI, **kw)


def _lines(fig, prefix):
    out = []
    for ax in fig.axes:
        out += [ln for ln in ax.lines if (ln.get_gid() or "").startswith(prefix)]
    return out


def test_tangent_lines_touch_the_discs():
    """Each drawn tangent ray from an eye centre is at distance g from the disc's centre."""
    sc, fig = _figure3b()
    h = sc.eyes.h
    lines = _lines(fig, "tangent-")
    assert len(lines) >= 4 * len(sc.features)
    by_name = {f.name: f for f in sc.features}
    for ln in lines:
        _, eye, name = ln.get_gid().split("-", 2)
        f = by_name[name]
        (x0, x1), (y0, y1) = ln.get_xdata(), ln.get_ydata()
        assert (x0, y0) == pytest.approx((-h if eye == "A" else h, 0.0))
        dx, dy = x1 - x0, y1 - y0
        dist = abs(dx * (f.y - y0) - dy * (f.x - x0)) / math.hypot(dx, dy)
        assert dist == pytest.approx(f.g, rel=1e-6)


def test_sector_rays_and_fan_span_the_lit_cells():
    sc, fig = _figure3b()
    pair = sc.eyes.pair()
    m, gamma = pair.m, 2 * math.pi / pair.m
    for f in sc.features:
        LA, RA, LB, RB = pair.intervals(np.array([f.x]), np.array([f.y]), np.array([f.g]))
        for eye, lo, hi in (("A", int(LA[0]), int(RA[0])), ("B", int(LB[0]), int(RB[0]))):
            fans = [
                p
                for ax in fig.axes
                for p in ax.patches
                if p.get_gid() == f"sector-fan-{eye}-{f.name}"
            ]
            assert fans, (f.name, eye)
            for fan in fans:
                assert fan.theta1 == pytest.approx(math.degrees(lo * gamma))
                assert fan.theta2 == pytest.approx(math.degrees((hi + 1) * gamma))
    # rays at k * gamma for the boundaries of every lit cell, no more
    want = set()
    for f in sc.features:
        LA, RA, LB, RB = pair.intervals(np.array([f.x]), np.array([f.y]), np.array([f.g]))
        for eye, lo, hi in (("A", int(LA[0]), int(RA[0])), ("B", int(LB[0]), int(RB[0]))):
            want |= {f"sector-{eye}-{k % m}" for k in range(lo, hi + 2)}
    got = {ln.get_gid() for ln in _lines(fig, "sector-")}
    assert got == want
    for ln in _lines(fig, "sector-"):
        k = int(ln.get_gid().rsplit("-", 1)[1])
        (x0, x1), (y0, y1) = ln.get_xdata(), ln.get_ydata()
        ang = math.atan2(y1 - y0, x1 - x0) % (2 * math.pi)
        assert ang == pytest.approx((k * gamma) % (2 * math.pi), abs=1e-9)


def test_table_columns_hold_the_right_values():
    """r and phi about O, A and B in their own columns (r_B never in r_A's)."""
    sc = scene_mod.load(SCENES / "default.toml")
    root = _svg(sc)
    h = sc.eyes.h
    texts = {}
    for g in root.iter(f"{SVG}g"):
        gid = g.get("id") or ""
        if gid.startswith("readout-") and gid.split("-")[1].isdigit():
            texts[gid] = "".join("".join(t.itertext()) for t in g.iter(f"{SVG}text"))
    for i, f in enumerate(sc.features):
        want = [
            f.name,
            f"{math.hypot(f.x, f.y):.0f}",
            f"{math.degrees(math.atan2(f.y, f.x)) % 360:.1f}\u00b0",
            f"{math.hypot(f.x + h, f.y):.0f}",
            f"{math.degrees(math.atan2(f.y, f.x + h)) % 360:.1f}\u00b0",
            f"{math.hypot(f.x - h, f.y):.0f}",
            f"{math.degrees(math.atan2(f.y, f.x - h)) % 360:.1f}\u00b0",
        ]
        for j, w in enumerate(want):
            assert texts[f"readout-{j}-{i}-{f.name}"] == w, (i, j)


def test_svg_counts_and_table_text():
    """Parse the SVG itself: one path per ommatidium, the table's header and rows."""
    sc = scene_mod.load(SCENES / "figure2.toml")
    root = _svg(sc, merge=False)
    omm = [
        g for g in root.iter(f"{SVG}g") if re.fullmatch(r"ommatidium-[AB]-\d+", g.get("id") or "")
    ]
    assert len(omm) == 2 * sc.eyes.m
    assert sum(len(_paths_in(g)) for g in omm) == 2 * sc.eyes.m
    texts = [("".join(t.itertext())).strip() for t in root.iter(f"{SVG}text")]
    for long, short, _, _ in GROUPS:  # the short header where the long one does not fit
        assert long in texts or short in texts
    for head in ("seen by", "BFV"):
        assert head in texts
    assert sc.features[0].name in texts


def test_far_view_wedge_is_drawn_over_the_feature():
    """Issue 12 item 5: at x = y = 1e7 the drawn wedge covers the feature."""
    from matplotlib.path import Path as MPath

    sc = scene_mod.Scene(
        features=[scene_mod.Feature("far", 1e7, 1e7, 5e4)],
        layers=["bfv", "features", "readout"],
        view=scene_mod.View((1e7, 1e7), 4e5),
    )
    fig = vector.figure(sc)
    ax = next(a for a in fig.axes if a.get_gid() == "main")
    wedge = next(p for p in ax.patches if p.get_gid() == "bfv-wedge")
    assert MPath(wedge.get_xy()).contains_point((1e7, 1e7))
