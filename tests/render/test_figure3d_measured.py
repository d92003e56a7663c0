"""`eyeviz snapshot bee.toml` (a measured honeybee, assets/scenes/bee.toml) as true vector:
each eye's Voronoi patches on its Mollweide map and its hexagons in the 3D view are paths,
the lit ones in their ball's colour; PDF without raster images; the readout's rows."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from matplotlib.colors import to_hex

from eyeviz.cli import main
from eyeviz.model.facet_patches import facet_patches
from eyeviz.model.scene import load
from eyeviz.model.state3d import compute_state3d
from eyeviz.render.mpl.facet_map import view_polys
from eyeviz.render.mpl.figure3d import figure3d, readout_rows

ROOT = Path(__file__).resolve().parents[2]
BEE = ROOT / "assets" / "scenes" / "bee.toml"
SVG = "{http://www.w3.org/2000/svg}"


@pytest.fixture(scope="module")
def bee():
    sc = load(BEE)
    return sc, compute_state3d(sc)


def _fills(group) -> list[str | None]:
    out = []
    for p in group.iter(f"{SVG}path"):
        m = re.search(r"fill:\s*(#[0-9a-f]{6})", p.get("style", ""))
        out.append(m.group(1) if m else None)
    return out


def _owner(st, eye):
    """Per lit facet the ball that colours it (the last one lighting it)."""
    own: dict[int, int] = {}
    for i in range(st.n):
        own.update(dict.fromkeys(st.lit(i, eye).tolist(), i))
    return own


@pytest.mark.slow
def test_svg_snapshot_draws_the_patches_as_paths(bee, tmp_path, capsys):
    sc, st = bee
    out = tmp_path / "bee.svg"
    assert main(["snapshot", str(BEE), "-o", str(out)]) == 0
    root = ET.parse(out).getroot()
    groups = {g.get("id"): g for g in root.iter(f"{SVG}g") if g.get("id")}
    for e in "AB":
        patches = facet_patches(st.pair, e)
        _, over, _ = view_polys(patches, np.arange(patches.n))
        fills = _fills(groups[f"map{e}"])
        own = _owner(st, e)
        assert len(own) > 0
        for i, f in enumerate(sc.features):  # each ball's lit patches in its colour
            mine = [k for k, b in own.items() if b == i]
            want = len(mine) + int(over[mine].sum())
            assert fills.count(to_hex(f.color)) == want, (e, f.name)
        # every facet is a path: the unlit ones light grey
        grey = fills.count(to_hex("#eeeeee"))
        assert grey == patches.n - len(own) + int(over.sum()) - sum(int(over[k]) for k in own)
    # the 3D view: each eye's hexagons (the front ones, culled) as paths
    view = groups["view-eyes"]
    assert sum(1 for _ in view.iter(f"{SVG}path")) > 1000
    texts = "".join(t.text or "" for t in root.iter(f"{SVG}text"))
    assert not texts or "eye A" in texts  # text as text (or as paths when fonts embed)


def test_pdf_snapshot_is_vector(tmp_path, capsys):
    out = tmp_path / "bee.pdf"
    assert main(["snapshot", str(BEE), "-o", str(out)]) == 0
    data = out.read_bytes()
    assert data.startswith(b"%PDF") and len(data) > 100_000
    assert b"/Subtype /Image" not in data


def test_figure_maps_titles_and_readout(bee):
    sc, st = bee
    fig = figure3d(sc)
    axes = {ax.get_gid(): ax for ax in fig.axes}
    for e, side in (("A", "left"), ("B", "right")):
        lit = len(_owner(st, e))
        assert axes[f"map{e}"].get_title() == f"eye {e} ({side}): {lit:,} of 3,187 facets lit"
    rows = readout_rows(st, sc)
    assert [r[0] for r in rows] == [f.name for f in sc.features]
    for i, r in enumerate(rows):
        assert r[-1] == f"{st.facets_a[i]}/{st.facets_b[i]}" and r[5] == "yes"
    shown = {t.get_text() for t in axes["readout"].texts}
    assert {"near", "mid", "far", "facets A/B"} <= shown
