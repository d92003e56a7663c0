"""`eyeviz snapshot` of a spherical scene: PNG, true-vector SVG/PDF, one-line refusals;
the planar path unchanged; `eyeviz app` refuses a spherical scene in one line."""

from __future__ import annotations

import json
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import pytest
from matplotlib.collections import PathCollection, PolyCollection

from eyeviz.cli import main
from eyeviz.core import healpix
from eyeviz.model.scene import load
from eyeviz.model.state3d import compute_state3d
from eyeviz.render.mpl.figure3d import MAX_BALLS, figure3d, readout_rows

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "assets" / "scenes"
SVG = "{http://www.w3.org/2000/svg}"

CASES = [
    pytest.param(name, fmt, marks=[pytest.mark.slow] if slow else [])
    for name in ("sphere_teaching", "sphere_paper", "sphere_equator")
    for fmt in ("png", "svg", "pdf")
    # nside 180 in SVG/PDF takes 2-3 s each: slow; its PNG stays in the quick run
    for slow in [name != "sphere_teaching" and fmt != "png"]
]


def _one_line_error(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("eyeviz: error:"), err
    return err[0]


@pytest.mark.parametrize(("name", "fmt"), CASES)
def test_snapshot3d_written_and_opened(name, fmt, tmp_path, capsys):
    out = tmp_path / f"s.{fmt}"
    args = ["snapshot", str(SCENES / f"{name}.toml"), "-o", str(out)]
    assert main(args + (["--scale", "0.5"] if fmt == "png" else [])) == 0
    assert capsys.readouterr().out.strip() == str(out)
    if fmt == "png":  # the whole figure, its 3D view rendered off-screen by VTK
        img = mpimg.imread(out)
        fig = figure3d(load(SCENES / f"{name}.toml"))  # the SVG's figure, same layout
        assert img.shape[:2] == (round(fig.get_figheight() * 150), 525)  # 3.5 in at 150 dpi
        # not blank: the first ball's colour (#D55E00: the ball, its lit facets) is in it
        rgb = (img[..., :3] * 255).round().astype(int).reshape(-1, 3)
        assert (np.abs(rgb - [0xD5, 0x5E, 0x00]).sum(axis=1) < 60).sum() > 20
        assert len(np.unique(rgb, axis=0)) > 100
    elif fmt == "svg":
        root = ET.parse(out).getroot()
        assert root.tag == f"{SVG}svg"
        assert len(root.findall(f".//{SVG}path")) > 100
        assert not root.findall(f".//{SVG}image")  # true vector: nothing rasterised
        texts = "".join("".join(t.itertext()) for t in root.iter(f"{SVG}text"))
        assert "facets lit" in texts and "BFV" in texts  # text kept as text
    else:
        data = out.read_bytes()
        assert data.startswith(b"%PDF") and b"/Subtype /Image" not in data


def test_bad_spherical_scene_refused_in_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('[eyes]\nnside = 8\n\n[layers]\nshow = ["eyes", "sectors"]\n')
    out = tmp_path / "x.png"
    assert main(["snapshot", str(bad), "-o", str(out)]) == 2
    line = _one_line_error(capsys)
    assert "layers.show" in line and "'sectors'" in line and "planar-only" in line
    bad.write_text("[eyes]\nnside = 8\nm = 32\n")
    assert main(["snapshot", str(bad), "-o", str(out)]) == 2
    assert "eyes.nside" in _one_line_error(capsys)
    many = "[eyes]\nnside = 4\n" + "".join(
        f'[[features]]\nname = "b{i}"\nx = 0.0\ny = {100 + i}.0\nz = 1.0\ng = 1.0\n'
        for i in range(MAX_BALLS + 1)
    )
    bad.write_text(many)
    assert main(["snapshot", str(bad), "-o", str(out)]) == 2
    assert f"at most {MAX_BALLS} balls" in _one_line_error(capsys)
    assert (
        main(["snapshot", str(SCENES / "sphere_teaching.toml"), "-o", str(out), "--scale", "30"])
        == 2
    )
    assert "scale" in _one_line_error(capsys)
    assert [p.name for p in tmp_path.iterdir()] == ["bad.toml"]  # no file written


def test_bad_spherical_scene_exit_2_in_a_process(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(
        '[eyes]\nm = 720\n\n[[features]]\nname = "up"\nx = 0.0\ny = 9.0\nz = 3.0\ng = 1.0\n'
    )
    out = subprocess.run(
        [sys.executable, "-m", "eyeviz", "snapshot", str(bad), "-o", str(tmp_path / "x.svg")],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=ROOT,
    )
    assert out.returncode == 2 and "Traceback" not in out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "features[0].z" in lines[0] and "'up'" in lines[0], lines
    assert [p.name for p in tmp_path.iterdir()] == ["bad.toml"]


@pytest.mark.slow
def test_snapshot3d_imports_no_vtk_qt_or_torch(tmp_path):
    """The SVG, then the PNG (VTK's off-screen render of the 3D view) of a HEALPix pair
    with predictions and of a measured pair, in one fresh process: after each, still no
    Qt, no torch, no vtk umbrella and no pyvista (its meshes are made with VTK alone:
    pyvista's import cost ~0.2 s, issue 32.14), nor pyplot."""
    probe = (
        "import json, sys\nfrom eyeviz.cli import main\n"
        "for argv in json.loads(sys.argv[1]):\n    rc = main(argv)\n"
        "    heavy = sorted(m for m in ('torch', 'PyQt5', 'vtk', 'pyvista', 'matplotlib.pyplot')"
        " if m in sys.modules)\n    print(json.dumps({'rc': rc, 'heavy': heavy}), flush=True)\n"
    )
    runs = [["snapshot", str(SCENES / "sphere_teaching.toml"), "-o", str(tmp_path / "t.svg")]]
    for name in ("sphere_teaching", "bee"):  # a HEALPix pair with predictions, a measured
        runs.append(["snapshot", str(SCENES / f"{name}.toml"), "-o",
                     str(tmp_path / f"{name}.png"), "--scale", "0.25"])  # fmt: skip
    out = subprocess.run(
        [sys.executable, "-c", probe, json.dumps(runs)],
        capture_output=True, text=True, timeout=300, cwd=ROOT,
    )  # fmt: skip
    res = [json.loads(x) for x in out.stdout.splitlines() if x.startswith("{")]
    assert res == [{"rc": 0, "heavy": []}] * 3, (res, out.stderr)
    for name in ("t.svg", "sphere_teaching.png", "bee.png"):
        assert (tmp_path / name).stat().st_size > 1000, name


def _maps(fig):
    return {a.get_gid(): a for a in fig.axes}


def test_maps_draw_the_lit_facets_in_their_colours():
    """nside 8: every facet drawn, the lit ones in their ball's colour; nside 180: only the
    lit facets (the unlit sphere is the map's background)."""
    sc = load(SCENES / "sphere_teaching.toml")
    st = compute_state3d(sc)
    axes = _maps(figure3d(sc))
    for eye in "AB":
        (coll,) = [c for c in axes[f"map{eye}"].collections if isinstance(c, PolyCollection)]
        n = healpix.npix(8)
        fc = coll.get_facecolors()
        assert len(fc) >= n  # plus the facets across the map's edge, drawn twice
        owner = {}
        for i, f in enumerate(sc.features):
            owner.update(dict.fromkeys(st.lit(i, eye).tolist(), f.color))
        lit_rgba = {tuple(np.round(c, 4)) for c in fc[list(owner)]} if owner else set()
        from matplotlib.colors import to_rgba

        assert lit_rgba == {tuple(np.round(to_rgba(c), 4)) for c in owner.values()}
    sc = load(SCENES / "sphere_paper.toml")
    st = compute_state3d(sc)
    axes = _maps(figure3d(sc, table=False))
    for eye in "AB":
        back, coll = [
            c
            for c in axes[f"map{eye}"].collections
            if isinstance(c, PolyCollection | PathCollection)
        ]
        assert len(back.get_paths()) == 1  # the unlit sphere, one solid outline
        lit = np.unique(np.concatenate([st.lit(i, eye) for i in range(st.n)]))
        # one compound path per ball colour, a closed polygon per lit facet (no facet of
        # these balls crosses the map's edge)
        assert len(coll.get_paths()) == len(sc.features)
        subpaths = sum(int((p.codes == p.MOVETO).sum()) for p in coll.get_paths())
        assert subpaths == lit.size
        assert lit.size < 2000 < healpix.npix(180)
    assert "readout" not in axes


def test_readout_rows_and_table():
    sc = load(SCENES / "sphere_equator.toml")
    st = compute_state3d(sc)
    rows = readout_rows(st, sc)
    assert [r[0] for r in rows] == [f.name for f in sc.features]
    mid = rows[0]
    assert mid[1:5] == ("1500", "90.0", "0.0", "50")
    assert mid[5:8] == ("yes", "AB", "no")
    assert mid[8] == f"{st.facets_a[0]}/{st.facets_b[0]}" == "126/126"
    up = rows[1]
    assert float(up[3]) == pytest.approx(np.degrees(np.arctan2(600, 1500)), abs=0.05)
    fig = figure3d(sc)
    texts = {t.get_text() for t in _maps(fig)["readout"].texts}
    assert {"126/126", "mid up", "1616", "-21.8"} <= texts


def test_perspective_culls_back_faces():
    """The 3D view's eyes: only the facets facing the camera are drawn (nside 8: about
    half of each eye's 768, in the scene and in the close-up)."""
    sc = load(SCENES / "sphere_teaching.toml")
    sc.layers = ["eyes"]
    axes = _maps(figure3d(sc))
    for part in ("perspective-eyes", "perspective-scene"):
        (coll,) = [c for c in axes[part].collections if isinstance(c, PolyCollection)]
        n = len(coll.get_paths())
        assert 2 * 0.35 * healpix.npix(8) < n < 2 * 0.6 * healpix.npix(8), (part, n)


def test_planar_snapshot_still_the_planar_figure(tmp_path, capsys):
    """The dispatch leaves a planar scene to the planar export: the same pixels."""
    from eyeviz.render.mpl.export import export

    a, b = tmp_path / "cli.png", tmp_path / "api.png"
    assert main(["snapshot", str(SCENES / "default.toml"), "-o", str(a), "--scale", "0.25"]) == 0
    export(load(SCENES / "default.toml"), b, scale=0.25)
    assert np.array_equal(mpimg.imread(a), mpimg.imread(b))


def test_app_takes_a_spherical_scene_to_the_display_check(capsys, monkeypatch):
    """The app opens spherical scenes (issue 22's 3D view): without a display the one
    line is the display's, as for a planar scene."""
    monkeypatch.delenv("DISPLAY", raising=False)
    assert main(["app", str(SCENES / "sphere_paper.toml")]) == 2
    assert "no display" in _one_line_error(capsys)


def test_transparent_export_keeps_the_unlit_sphere(tmp_path, capsys):
    """At nside 180 the unlit sphere is an artist, not the axes' background (which a
    transparent export empties): the map's centre stays opaque grey, its corner clear."""
    from eyeviz.render.mpl.figure3d import export3d

    out = tmp_path / "t.png"  # the figure's PNG (the snapshot command's PNG is the 3D view)
    export3d(load(SCENES / "sphere_paper.toml"), out, scale=0.25, transparent=True, table=False)
    img = mpimg.imread(out)
    fig = figure3d(load(SCENES / "sphere_paper.toml"), table=False)
    box = _maps(fig)["mapA"].get_position()  # figure fractions, origin at the bottom
    h, w = img.shape[:2]
    x = int((box.x0 + 0.1 * box.width) * w)  # left of centre, off the equator and graticule
    y = int((1 - (box.y0 + 0.55 * box.height)) * h)
    assert img[y, x, 3] == 1.0 and np.allclose(img[y, x, :3], 0xEE / 255, atol=0.02)
    assert img[int((1 - box.y1) * h) + 1, int(box.x0 * w) + 1, 3] == 0.0  # outside the map


@pytest.mark.slow
def test_snapshot3d_view_presets(tmp_path, capsys):
    """--view picks the 3D view's camera preset (vector and PNG); a bad name or a planar
    scene is refused in one line naming --view, before anything is written."""
    teaching = str(SCENES / "sphere_teaching.toml")
    paths = {}
    for view in ("default", "top"):
        out = tmp_path / f"{view}.svg"
        assert main(["snapshot", teaching, "-o", str(out), "--view", view, "--no-table"]) == 0
        paths[view] = out.read_text()
    capsys.readouterr()
    assert paths["default"] != paths["top"]
    assert "seen from above" in paths["top"] and "seen from front, right, above" in paths["default"]
    pngs = []
    for view in ("front", "side"):
        out = tmp_path / f"{view}.png"
        assert main(["snapshot", teaching, "-o", str(out), "--view", view, "--scale", "0.3"]) == 0
        pngs.append(mpimg.imread(out))
    assert pngs[0].shape == pngs[1].shape and not np.array_equal(pngs[0], pngs[1])
    capsys.readouterr()
    for args in (
        [teaching, "--view", "below"],
        [str(SCENES / "default.toml"), "--view", "top"],
    ):
        out = tmp_path / "bad.svg"
        assert main(["snapshot", args[0], "-o", str(out), *args[1:]]) == 2
        assert "view" in _one_line_error(capsys)
        assert not out.exists()


def test_snapshot3d_png_too_large_a_view_refused_in_one_line(tmp_path, capsys):
    """The PNG's 3D view is rendered by VTK at the view box's pixels: beyond 8192 px the
    scale is refused in one line naming it, and nothing is written."""
    out = tmp_path / "big.png"
    teaching = str(SCENES / "sphere_teaching.toml")
    assert main(["snapshot", teaching, "-o", str(out), "--scale", "19"]) == 2
    line = _one_line_error(capsys)
    assert "scale 19" in line and "8192" in line and "scale <=" in line
    assert not out.exists()
