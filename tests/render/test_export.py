"""export(): format by suffix, PNG scale, transparent background, PDF that renders,
atomic writes (an interrupted export leaves no file and keeps an existing one)."""

import math
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure

from eyeviz import EyevizError
from eyeviz.model import scene as scene_mod
from eyeviz.render.mpl.export import export
from eyeviz.render.mpl.layers.table import GROUPS

SCENES = Path(__file__).resolve().parents[2] / "assets" / "scenes"


@pytest.fixture(scope="module")
def default_scene():
    return scene_mod.load(SCENES / "default.toml")


def png_size(path) -> tuple[int, int]:
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


def read_png(path) -> np.ndarray:
    from matplotlib.image import imread

    return imread(path)


def test_png_scale_doubles_pixels(tmp_path, default_scene):
    a = export(default_scene, tmp_path / "a.png")
    b = export(default_scene, tmp_path / "b.png", scale=2)
    wa, ha = png_size(a)
    wb, hb = png_size(b)
    assert wa == 1050  # 3.5 in at 300 dpi
    assert (wb, hb) == (2 * wa, 2 * ha)


def test_png_shows_the_scene(tmp_path, default_scene):
    img = read_png(export(default_scene, tmp_path / "a.png"))
    rgb = (img[..., :3] * 255).round().astype(int)
    assert img.shape[2] in (3, 4) and (img[..., 3] == 1).all() if img.shape[2] == 4 else True
    for f in default_scene.features:  # every feature's colour is there (rim or lit cells)
        want = np.array([int(f.color[i : i + 2], 16) for i in (1, 3, 5)])
        assert (np.abs(rgb - want).sum(axis=2) < 30).sum() > 20, f.name
    assert rgb.std() > 20


def test_png_transparent(tmp_path, default_scene):
    img = read_png(export(default_scene, tmp_path / "t.png", transparent=True))
    assert img.shape[2] == 4
    assert img[0, 0, 3] == 0  # the corner: no white ground
    assert (img[..., 3] > 0.9).sum() > 1000  # the scene itself is opaque


def test_pdf_renders_and_is_not_blank(tmp_path, default_scene):
    pdf = export(default_scene, tmp_path / "f.pdf")
    data = pdf.read_bytes()
    assert data.startswith(b"%PDF")
    assert b"/Type3" not in data and b"FontFile2" in data  # TrueType (fonttype 42) text
    subprocess.run(
        ["pdftoppm", "-r", "60", "-png", "-singlefile", str(pdf), str(tmp_path / "render")],
        check=True,
        timeout=60,
    )
    img = read_png(tmp_path / "render.png")
    rgb = (img[..., :3] * 255).round().astype(int)
    assert rgb.std() > 20
    blue = np.array([0x00, 0x72, 0xB2])  # the "far" feature
    assert (np.abs(rgb - blue).sum(axis=2) < 40).sum() > 10


def test_svg_written(tmp_path, default_scene):
    import xml.etree.ElementTree as ET

    svg = export(default_scene, tmp_path / "f.SVG")
    root = ET.parse(svg).getroot()
    assert root.tag.endswith("svg")


def test_unknown_suffix_and_bad_scale(tmp_path, default_scene):
    with pytest.raises(EyevizError, match=r"\.gif.*use \.png, \.svg or \.pdf") as exc:
        export(default_scene, tmp_path / "f.gif")
    assert "\n" not in str(exc.value)
    with pytest.raises(EyevizError, match="no suffix"):
        export(default_scene, tmp_path / "figure")
    for bad in (0, -1, float("nan"), "big"):
        with pytest.raises(EyevizError, match="scale"):
            export(default_scene, tmp_path / "f.png", scale=bad)
    with pytest.raises(EyevizError, match="does not exist"):
        export(default_scene, tmp_path / "nodir" / "f.png")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("exc", [KeyboardInterrupt, RuntimeError])
@pytest.mark.parametrize("suffix", [".png", ".pdf"])
def test_interrupted_export_leaves_no_file(tmp_path, default_scene, monkeypatch, exc, suffix):
    real = Figure.savefig

    def half_then_fail(self, fname, *args, **kw):
        real(self, fname, *args, **kw)  # the whole file is there ...
        with open(fname, "r+b") as fh:  # ... then cut short, as by Ctrl-C mid-write
            fh.truncate(100)
        raise exc("interrupted mid-save")

    monkeypatch.setattr(Figure, "savefig", half_then_fail)
    target = tmp_path / f"fig{suffix}"
    with pytest.raises(exc):
        export(default_scene, target)
    assert list(tmp_path.iterdir()) == []
    # an existing figure is kept unchanged
    target.write_bytes(b"previous figure")
    with pytest.raises(exc):
        export(default_scene, target)
    assert target.read_bytes() == b"previous figure"
    assert [p.name for p in tmp_path.iterdir()] == [target.name]


# --- export for journals (issue 12 item 10) and hostile inputs (issue 13) ---------------

from eyeviz.render.mpl import vector  # noqa: E402


def _renderer(fig):
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return canvas.get_renderer()


def _texts(fig):
    """Every Text the figure draws (tick labels only for the ticks inside the view)."""
    ticks, drawn = set(), set()
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                ticks |= {id(tick.label1), id(tick.label2)}
            for tick in axis._update_ticks() if ax.axison else []:
                drawn |= {id(tick.label1), id(tick.label2)}
    out = []
    for t in fig.findobj(lambda a: hasattr(a, "get_text") and hasattr(a, "get_fontsize")):
        if not (t.get_visible() and t.get_text().strip()):
            continue
        if id(t) in ticks and id(t) not in drawn:
            continue
        out.append(t)
    return out


def _all_scenes():
    scenes = [scene_mod.load(p) for p in sorted(SCENES.glob("*.toml"))]
    # the spherical scenes (sphere_*.toml) have their own figure: tests/commands/test_snapshot3d.py
    scenes = [sc for sc in scenes if sc.kind == "planar"]
    for sc in scenes:
        sc.estimators = ["analytic"]  # no torch in this test
    return scenes


@pytest.mark.slow
@pytest.mark.parametrize("width", ["single", "double", 5.0])
def test_no_text_below_6pt_and_all_inside_the_figure(width):
    for sc in _all_scenes():
        fig = vector.figure(sc, width=width)
        r = _renderer(fig)
        W, H = fig.bbox.width, fig.bbox.height
        for t in _texts(fig):
            assert t.get_fontsize() >= 6.0, (sc.title, t.get_text(), t.get_fontsize())
            if t.get_clip_on() and t.axes is not None and t.get_gid() != "title":
                continue  # feature labels clipped to the view are checked by placement
            bb = t.get_window_extent(r)
            assert bb.x0 >= -1 and bb.y0 >= -1 and bb.x1 <= W + 1 and bb.y1 <= H + 1, (
                sc.title,
                t.get_text(),
                bb,
            )


@pytest.mark.slow
def test_width_single_double_and_inches(tmp_path, default_scene):
    for w, inches in (("single", 3.5), ("double", 7.2), (4.25, 4.25)):
        out = export(default_scene, tmp_path / f"w{w}.png", width=w)
        assert png_size(out)[0] == round(300 * inches)
    for bad in ("triple", 0.5, 100, float("nan")):
        with pytest.raises(EyevizError, match="width"):
            export(default_scene, tmp_path / "bad.png", width=bad)
    assert not (tmp_path / "bad.png").exists()


def test_toggles_title_table_bitmaps(tmp_path, default_scene):
    full = export(default_scene, tmp_path / "full.svg").read_text()
    bare = export(
        default_scene, tmp_path / "bare.svg", title=False, table=False, bitmaps=False
    ).read_text()
    assert 'id="title"' in full and 'id="title"' not in bare
    assert 'id="readout"' in full and 'id="readout"' not in bare
    assert 'id="bitmaps"' in full and 'id="bitmaps"' not in bare
    assert 'id="feature-target"' in bare


def test_framing_follows_the_scene_view(default_scene):
    fig = vector.figure(default_scene, width="double")
    ax = next(a for a in fig.axes if a.get_gid() == "main")
    cx, cy = default_scene.view.center
    x0, x1 = ax.get_xlim()
    assert (x0 + x1) / 2 == pytest.approx(cx) and x1 - x0 == pytest.approx(default_scene.view.width)
    assert sum(ax.get_ylim()) / 2 == pytest.approx(cy)


@pytest.mark.parametrize("aspect", [0.45, 0.69, 1.3])
def test_an_aspect_frames_what_a_window_of_that_shape_shows(default_scene, aspect):
    fig = vector.figure(default_scene, width="single", aspect=aspect)
    ax = next(a for a in fig.axes if a.get_gid() == "main")
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    assert x1 - x0 == pytest.approx(default_scene.view.width)
    assert (y1 - y0) / (x1 - x0) == pytest.approx(aspect, rel=2e-3)
    pos = ax.get_position()  # the axes have that shape on the page too
    w_in, h_in = fig.get_size_inches()
    assert pos.height * h_in / (pos.width * w_in) == pytest.approx(aspect, rel=2e-3)


@pytest.mark.parametrize("bad", [0.1, 2.0, float("nan"), "tall"])
def test_an_aspect_outside_its_range_is_refused(default_scene, bad):
    with pytest.raises(EyevizError, match=r"aspect .* must be in \[0\.3, 1\.6\]"):
        vector.figure(default_scene, aspect=bad)


def test_inset_leader_stays_inside_the_axes():
    for sc in _all_scenes() + [_origin_below_view()]:
        fig = vector.figure(sc)
        main = next(a for a in fig.axes if a.get_gid() == "main")
        box = main.get_position()
        for ln in fig.lines:
            if ln.get_gid() == "inset-leader":
                xs, ys = ln.get_xdata(), ln.get_ydata()
                assert all(box.x0 - 1e-9 <= v <= box.x1 + 1e-9 for v in xs)
                assert all(box.y0 - 1e-9 <= v <= box.y1 + 1e-9 for v in ys)


def _origin_below_view():
    sc = scene_mod.load(SCENES / "default.toml")
    sc.view = scene_mod.View((0.0, 9000.0), 8000.0)
    return sc


def test_seven_digit_distances_do_not_run_together():
    sc = scene_mod.Scene(
        features=[
            scene_mod.Feature("far", 1e7, 1e7, 5e4),
            scene_mod.Feature("farther", -4e6, 9.9e6, 5e4),
        ],
        layers=["bfv", "features", "readout", "labels"],
        view=scene_mod.View((1e7, 1e7), 4e5),
    )
    for width in ("single", "double"):
        fig = vector.figure(sc, width=width)
        r = _renderer(fig)
        table = next(a for a in fig.axes if a.get_gid() == "readout")
        rows: dict[int, list] = {}
        for t in table.texts:
            gid = t.get_gid() or ""
            if gid.startswith("readout-") and gid.split("-")[1].isdigit():
                rows.setdefault(int(gid.split("-")[2]), []).append(t.get_window_extent(r))
        assert len(rows) == 2
        for boxes in rows.values():
            boxes.sort(key=lambda b: b.x0)
            for a, b in zip(boxes, boxes[1:], strict=False):
                assert a.x1 + 2 <= b.x0  # at least 2 px between cells
        # the main axes' tick labels do not overlap either, and no offset text
        main = next(a for a in fig.axes if a.get_gid() == "main")
        ticks = [t.get_window_extent(r) for t in main.get_xticklabels() if t.get_text()]
        ticks.sort(key=lambda b: b.x0)
        for a, b in zip(ticks, ticks[1:], strict=False):
            assert a.x1 < b.x0
        assert not main.xaxis.get_offset_text().get_text()
        W = fig.bbox.width
        for t in _texts(fig):
            bb = t.get_window_extent(r)
            assert bb.x0 >= -1 and bb.x1 <= W + 1, t.get_text()
        # full distances: r, r_A and r_B of the far feature differ and are all shown
        cells = {t.get_gid(): t.get_text() for t in table.texts if t.get_gid()}
        if width == "double":
            assert cells["readout-1-0-far"] == f"{math.hypot(1e7, 1e7):.0f}"


def test_theta_label_not_on_a_feature():
    sc = scene_mod.load(SCENES / "figure5.toml")
    # a feature exactly where the theta label would go
    sc.features.append(scene_mod.Feature("blocker", 0.0, 145.0, 20.0, "#CC79A7"))
    fig = vector.figure(sc)
    r = _renderer(fig)
    ax = next(a for a in fig.axes if a.get_gid() == "main")
    lab = next(t for t in ax.texts if t.get_gid() == "bfv-theta-label")
    bb = lab.get_window_extent(r).transformed(ax.transData.inverted())
    for f in sc.features:
        dx = max(bb.x0 - f.x, 0, f.x - bb.x1)
        dy = max(bb.y0 - f.y, 0, f.y - bb.y1)
        assert math.hypot(dx, dy) >= f.g, f.name


def _with_blockers():
    """Figures 5-6 with a feature on one side of psi's label or the other, or both."""
    out = []
    for spots in ([(-120.0, 20.0)], [(120.0, 20.0)], [(-120.0, 20.0), (120.0, 20.0)]):
        sc = scene_mod.load(SCENES / "figure5.toml")
        for k, (x, y) in enumerate(spots):
            sc.features.append(scene_mod.Feature(f"blocker {k}", x, y, 50.0, "#CC79A7"))
        out.append(sc)
    return out


@pytest.mark.slow
@pytest.mark.parametrize("aspect", [0.4, 0.5, 0.58, 0.86, 1.3])
def test_angle_labels_never_under_the_inset(aspect):
    """psi and theta stay readable at any window shape: at 0.5 the inset took the lower
    right corner of Figures 5-6 and psi's label was cut under it ("psi = 3"); with a
    feature beside each place it can go, it goes over a feature, never under the inset."""
    shipped = _all_scenes()
    for sc in shipped + _with_blockers():
        fig = vector.figure(sc, aspect=aspect)
        r = _renderer(fig)
        inset = next((a for a in fig.axes if a.get_gid() == "inset"), None)
        ax = next(a for a in fig.axes if a.get_gid() == "main")
        if inset is None:
            continue
        box = inset.get_window_extent(r)
        for t in ax.texts:
            if t.get_gid() in ("bfv-theta-label", "bfv-psi-label"):
                bb = t.get_window_extent(r)
                overlap = bb.x0 < box.x1 and box.x0 < bb.x1 and bb.y0 < box.y1 and box.y0 < bb.y1
                assert not overlap, (sc.title, aspect, t.get_text())
        # and, in the shipped scenes at a window's usual shapes, the inset never hides a
        # feature to make room for the labels (the blockers leave no corner free, nor does
        # Figures 5-6 at 0.4: its view is then 1.2 in high and every corner meets a disc)
        for f in sc.features if sc in shipped and aspect >= 0.5 else []:
            px, py = ax.transData.transform((f.x, f.y))
            assert not (box.x0 < px < box.x1 and box.y0 < py < box.y1), (sc.title, f.name)


def test_unavailable_estimator_refused_never_written(tmp_path, default_scene):
    sc = default_scene.copy()
    sc.layers = [*sc.layers, "predictions"]
    sc.estimators = ["compact"]
    given = {"compact": "unavailable: weights missing in /home/someone/secret/compact_dd.pt"}
    with pytest.raises(EyevizError) as exc:
        export(sc, tmp_path / "p.svg", predictions=given)
    assert "\n" not in str(exc.value)
    assert not (tmp_path / "p.svg").exists()
    # an answer the estimator cannot give (another m) is a neutral note, not its message
    sc.estimators = ["analytic"]
    given = {"analytic": "cannot answer: made for m = 720 at /home/someone/x"}
    text = export(sc, tmp_path / "q.svg", predictions=given).read_text()
    assert "/home/someone" not in text and "no answer for this eye design" in text


def test_hostile_names_and_coordinates(tmp_path, default_scene, monkeypatch):
    sc = default_scene.copy()
    sc.features[0].name = r"$\undefined$ x"
    sc.features[1].name = "n" * 1_000_000
    sc.title = "$\\frac{1}{0}$ " + "t" * 1_000_000
    out = export(sc, tmp_path / "names.png")
    export(sc, tmp_path / "names.svg")
    assert png_size(out)[0] == 1050
    # the million-character names are cut before they are laid out: no text in the
    # figure is longer than a few hundred characters
    texts = vector.figure(sc).findobj(lambda a: hasattr(a, "get_text"))
    assert texts and max(len(t.get_text()) for t in texts) < 500
    fig = vector.figure(sc)
    r = _renderer(fig)
    title = next(t for t in fig.texts if t.get_gid() == "title")
    assert title.get_text().startswith("$\\frac{1}{0}$ ttt")
    assert title.get_window_extent(r).x1 <= fig.bbox.width + 1
    svg = (tmp_path / "names.svg").read_text()
    assert r"$\undefined$ x" in svg  # shown literally, not parsed as mathtext
    assert "n" * 39 + "\u2026" in svg and "n" * 1000 not in svg
    far = default_scene.copy()
    far.features[0].x = 1e308
    made = _count_figures(monkeypatch)
    with pytest.raises(EyevizError, match="cannot be drawn") as exc:
        export(far, tmp_path / "far.png")
    assert "\n" not in str(exc.value)
    assert made == []  # refused before any figure is made or drawn
    assert not (tmp_path / "far.png").exists()


def _count_figures(monkeypatch) -> list:
    """Every matplotlib Figure made from now on appends to the returned list."""
    from matplotlib.figure import Figure

    made: list = []
    real = Figure.__init__

    def init(self, *a, **kw):
        made.append(self)
        real(self, *a, **kw)

    monkeypatch.setattr(Figure, "__init__", init)
    return made


def test_the_figure_counter_counts(monkeypatch, default_scene, tmp_path):
    made = _count_figures(monkeypatch)
    export(default_scene, tmp_path / "ok.svg")
    assert len(made) >= 1


def test_too_many_features_refused_quickly(tmp_path, default_scene, monkeypatch):
    sc = default_scene.copy()
    f = sc.features[0]
    sc.features = [
        scene_mod.Feature(f"f{i}", f.x + i, f.y, f.g) for i in range(vector.MAX_FEATURES + 1)
    ]
    made = _count_figures(monkeypatch)
    with pytest.raises(EyevizError, match="at most 10000 features"):
        export(sc, tmp_path / "many.png")
    assert made == []  # refused before any figure is made or drawn
    assert not (tmp_path / "many.png").exists()


def test_svg_predictions_for_other_eyes(tmp_path):
    """h = 80: analytic and limit answer for these eyes (within a few %, not -50 %);
    compact, trained for the paper's eyes, says so and draws no ring (issue 10 item 4)."""
    import re
    import xml.etree.ElementTree as ET

    sc = scene_mod.Scene(
        scene_mod.Eyes(80.0, 20.0, 720),
        [scene_mod.Feature("target", 300.0, 3000.0, 60.0, "#D55E00")],
        ["eyes", "features", "readout", "predictions"],
        estimators=["analytic", "limit", "compact"],
    )
    out = export(sc, tmp_path / "h80.svg", width="double")
    root = ET.parse(out).getroot()
    ns = "{http://www.w3.org/2000/svg}"
    texts = " ".join("".join(t.itertext()) for t in root.iter(f"{ns}text"))
    gids = {g.get("id") for g in root.iter(f"{ns}g")}
    assert "compact: trained for h = 40, l = 20, m = 720" in texts
    assert "prediction-compact-target" not in gids
    for name in ("analytic", "limit"):
        assert f"prediction-{name}-target" in gids
        m = re.search(name + r": r\u0302 = [^(]*\(\u0394r [^,]*, ([+\-\u2212]?[\d.]+) %\)", texts)
        assert m, (name, texts)
        assert abs(float(m.group(1).replace("\u2212", "-"))) < 10, (name, m.group(0))


@pytest.mark.parametrize("name", ["figure5", "trajectory", "default"])
def test_column_group_headers_stay_apart(name):
    """'about the origin O' ran into 'about eye A' at 3.5 in (a 1.4 pt gap)."""
    sc = scene_mod.load(SCENES / f"{name}.toml")
    for width in ("single", "double"):
        fig = vector.figure(sc, width=width)
        r = _renderer(fig)
        table = next(a for a in fig.axes if a.get_gid() == "readout")
        heads = sorted(
            (t for t in table.texts if (t.get_gid() or "").startswith("readout-group-")),
            key=lambda t: t.get_window_extent(r).x0,
        )
        assert len(heads) == 3
        word = fig.dpi * 6 / 72 * 0.6  # about a 6 pt space
        for a, b in zip(heads, heads[1:], strict=False):
            assert a.get_window_extent(r).x1 + word <= b.get_window_extent(r).x0, (
                width,
                a.get_text(),
                b.get_text(),
            )
        got = [h.get_text() for h in heads]
        assert got in ([g[0] for g in GROUPS], [g[1] for g in GROUPS])  # all long or all short
