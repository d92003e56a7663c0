"""Figures of many features: labels placed without overlap in a bounded number of lanes,
and a figure whose size does not grow with the number of features (issue 25, item 1)."""

from __future__ import annotations

import numpy as np
import pytest

from eyeviz.model.scene import Eyes, Feature, Scene, View
from eyeviz.render.mpl import vector
from eyeviz.render.mpl.layout import (
    MAX_LABELS,
    MAX_LANES,
    MAX_TABLE_ROWS,
    default_aspect,
    interval_lanes,
    label_width,
    readout_rows,
    table_features,
)

M = 720


def _random_intervals(n: int, seed: int, m: int = M):
    rng = np.random.default_rng(seed)
    L = rng.integers(0, m // 2, n)
    R = L + rng.integers(0, m // 3, n)
    whole = rng.random(n) < 0.02
    L[whole], R[whole] = 0, m - 1
    return L, R


def _overlaps(lanes, m: int, strip_in: float) -> list[tuple[int, int]]:
    """Pairs of labels in one lane whose boxes overlap (the placement's own width rule)."""
    idx_per_in = m / strip_in
    by_lane: dict[int, list[tuple[float, float, int]]] = {}
    for i, text, centre, lane in lanes:
        half = label_width(text, 6.0) * idx_per_in / 2
        by_lane.setdefault(lane, []).append((centre - half, centre + half, i))
    bad = []
    for boxes in by_lane.values():
        for a, (l0, r0, i) in enumerate(boxes):
            for l1, r1, j in boxes[a + 1 :]:
                if l0 < r1 - 1e-9 and l1 < r0 - 1e-9:
                    bad.append((i, j))
    return bad


def _depth(lanes, L, R, m: int, strip_in: float) -> int:
    """The most labels over one point: no placement can use fewer lanes."""
    idx_per_in = m / strip_in
    events = []
    for _i, text, centre, _ in lanes:
        half = label_width(text, 6.0) * idx_per_in / 2
        events += [(centre - half, 1), (centre + half, -1)]
    depth = best = 0
    for _, d in sorted(events, key=lambda e: (e[0], e[1])):  # an end before a start
        depth += d
        best = max(best, depth)
    return best


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("n", [1, 7, 60, 400])
def test_unbounded_lanes_never_overlap_and_use_the_fewest_lanes(n, seed):
    L, R = _random_intervals(n, seed)
    lanes = interval_lanes(L, R, M, 3.0, max_lanes=10**6)
    assert sorted(i for i, *_ in lanes) == list(range(n))  # each label once
    assert lanes.dropped == 0
    assert not _overlaps(lanes, M, 3.0)
    assert lanes.used == _depth(lanes, L, R, M, 3.0)  # interval partitioning is optimal
    for i, text, centre, _ in lanes:  # over its run, inside the strip
        lo, hi = int(L[i]), int(R[i])
        assert text == ("whole eye" if hi - lo >= M - 1 else f"[{lo}, {hi % M}]")
        half = label_width(text, 6.0) * M / 3.0 / 2
        assert half - 1e-9 <= centre <= M - half + 1e-9


@pytest.mark.parametrize("n", [50, 1000, 10_000])
def test_bounded_lanes_hold_at_most_max_lanes_and_count_the_rest(n):
    L, R = _random_intervals(n, 11)
    lanes = interval_lanes(L, R, M, 3.0)
    assert lanes.used <= MAX_LANES
    assert {ln for *_, ln in lanes} <= set(range(MAX_LANES))
    assert len(lanes.placed) + lanes.dropped == n
    assert not _overlaps(lanes, M, 3.0)
    if n >= 1000:  # more labels than MAX_LANES lanes can hold
        assert lanes.dropped > 0 and lanes.height == MAX_LANES + 1


def test_the_old_all_pairs_placement_agrees_on_small_cases():
    """The previous placement (every earlier label scanned per lane) used as many lanes."""
    for seed in range(20):
        L, R = _random_intervals(25, seed)
        new = interval_lanes(L, R, M, 3.5, max_lanes=10**6)
        idx_per_in = M / 3.5
        placed: list[tuple[float, float, int]] = []
        for i in sorted(range(len(L)), key=lambda j: int(L[j])):
            text = next(t for k, t, _, _ in new if k == i)
            c = next(c for k, _, c, _ in new if k == i)
            w = label_width(text, 6.0) * idx_per_in
            lane = 0
            while any(abs(c - c2) < (w + w2) / 2 and ln == lane for c2, w2, ln in placed):
                lane += 1
            placed.append((c, w, lane))
        assert new.used <= 1 + max(ln for *_, ln in placed)


def test_table_rows_are_capped_with_a_row_for_the_rest():
    layers = {"readout", "predictions", "ambiguity"}
    assert readout_rows(layers, 3, 1) == 2 + 3 * 3
    for n in (100, 10_000):
        shown = table_features(layers, n, 2)
        assert 1 <= shown < n
        assert readout_rows(layers, n, 2) <= MAX_TABLE_ROWS
        assert readout_rows(layers, n, 2) == readout_rows(layers, 100, 2)


def _scene(n: int, seed: int = 3, layers=None) -> Scene:
    rng = np.random.default_rng(seed)
    feats = [
        Feature(
            f"f{i}",
            float(rng.uniform(-3000, 3000)),
            float(rng.uniform(600, 5000)),
            float(rng.uniform(20, 200)),
            "#D55E00",
        )
        for i in range(n)
    ]
    return Scene(
        Eyes(),
        feats,
        layers or ["eyes", "bfv", "features", "bitmaps", "readout", "labels"],
        [],
        View((0.0, 2500.0), 8000.0),
        "many features",
    )


def _texts(fig, prefix: str) -> dict[str, str]:
    from matplotlib.text import Text

    return {
        t.get_gid(): t.get_text()
        for t in fig.findobj(Text)
        if t.get_gid() and t.get_gid().startswith(prefix)
    }


def test_figure_size_does_not_grow_with_the_number_of_features():
    """400 features once made a 3.5 x 105 inch figure (1050 x 31,620 px)."""
    sizes = {}
    for n in (60, 400, 2000):
        fig = vector.figure(_scene(n))
        sizes[n] = tuple(fig.get_size_inches())
        texts = _texts(fig, "")
        assert sum(g.startswith("label-f") for g in texts) <= MAX_LABELS
        assert texts["readout-more"].startswith("\u2026 and ")
        assert texts["readout-more"].split()[2].replace(",", "").isdigit()
        assert "label-more" in texts
    assert sizes[60] == sizes[400] == sizes[2000]
    assert sizes[2000][1] < 10  # inches


def test_a_few_features_are_all_listed_and_labelled():
    fig = vector.figure(_scene(4))
    texts = _texts(fig, "")
    assert "readout-more" not in texts and "label-more" not in texts
    assert sum(g.startswith("label-f") for g in texts) == sum(
        1 for f in _scene(4).features if abs(f.x) < 4000
    )
    assert {f"readout-0-{i}-f{i}" for i in range(4)} <= set(texts)


def test_a_full_table_counts_the_features_left_out():
    n = 500
    fig = vector.figure(_scene(n))
    texts = _texts(fig, "readout-")
    listed = {g.split("-")[2] for g in texts if g.startswith("readout-0-")}
    more = int(texts["readout-more"].split()[2].replace(",", ""))
    assert len(listed) + more == n


@pytest.mark.parametrize(
    ("width", "want"), [(3.5, 0.86), ("single", 0.86), (7.2, 0.5), ("double", 0.5), (10, 0.5)]
)
def test_default_aspect_per_journal_width(width, want):
    w = vector.resolve_width(width)
    assert default_aspect(w) == pytest.approx(want)
    sc = _scene(3)
    fig = vector.figure(sc, width=width)
    x0, x1 = fig.axes[0].get_xlim()
    y0, y1 = fig.axes[0].get_ylim()
    assert (y1 - y0) / (x1 - x0) == pytest.approx(want, rel=2e-3)


def test_double_column_default_is_not_a_page_tall():
    fig = vector.figure(_scene(3), width="double")
    w, h = fig.get_size_inches()
    assert h < 0.75 * w  # at aspect 0.86 the double column figure was ~1.05 w tall


def test_an_intermediate_width_interpolates():
    assert 0.5 < default_aspect(5.0) < 0.86


def _sizes(fig) -> list[float]:
    from matplotlib.text import Text

    fig.canvas.draw()  # tick labels exist once drawn
    return [t.get_fontsize() for t in fig.findobj(Text) if t.get_text() and t.get_visible()]


def test_min_font_raises_every_text_and_grows_the_table():
    sc = _scene(5, layers=["eyes", "bfv", "features", "bitmaps", "readout", "labels"])
    plain = vector.figure(sc)
    assert min(_sizes(plain)) < 8  # 6 pt tick labels, table and lanes
    big = vector.figure(sc, min_font=8)
    assert min(_sizes(big)) >= 8
    assert big.get_size_inches()[1] > plain.get_size_inches()[1]  # rows and lanes grew
    assert big.get_size_inches()[0] == plain.get_size_inches()[0]


@pytest.mark.parametrize("bad", [5, 13, "x", float("nan")])
def test_a_min_font_outside_its_range_is_refused(bad):
    from eyeviz import EyevizError

    with pytest.raises(EyevizError, match=r"min-font must be between 6 and 12 points"):
        vector.figure(_scene(2), min_font=bad)


def test_teaching_layers_draw_at_most_max_taught_features_and_count_the_rest():
    from eyeviz.render.mpl.layout import MAX_TAUGHT

    n = MAX_TAUGHT + 25
    fig = vector.figure(_scene(n, layers=["eyes", "features", "tangents", "sectors"]))
    names = set()
    for ax in fig.axes:
        for ln in ax.lines:
            gid = ln.get_gid() or ""
            if gid.startswith("tangent-"):
                names.add(gid.split("-", 2)[2])
        for p in ax.patches:
            gid = p.get_gid() or ""
            if gid.startswith("sector-fan-"):
                names.add(gid.split("-", 3)[3])
    assert names and names <= {f"f{i}" for i in range(MAX_TAUGHT)}
    note = _texts(fig, "label-more")["label-more"]
    assert "more without tangents" in note and "more without sectors" in note
    # a few features: every one drawn, no note
    fig = vector.figure(_scene(5, layers=["eyes", "features", "tangents", "sectors"]))
    assert "label-more" not in _texts(fig, "label-more")


@pytest.mark.parametrize("width", ["single", "double", 5.0])
def test_a_crowded_figure_keeps_within_a_pages_aspect(width):
    """A 2,000-feature snapshot was 1050 x 2343 px (aspect 2.23, issue 35 item 11): the
    lanes and the table's rows give way until the figure fits a page's aspect; what they
    leave out is counted."""
    from eyeviz.render.mpl.layout import MAX_FIGURE_ASPECT

    fig = vector.figure(_scene(2000), width=width)
    w, h = fig.get_size_inches()
    assert h <= MAX_FIGURE_ASPECT * w + 0.01, (w, h)
    texts = _texts(fig, "")
    listed = {g.split("-")[2] for g in texts if g.startswith("readout-0-")}
    more = int(texts["readout-more"].split()[2].replace(",", ""))
    assert listed and len(listed) + more == 2000
    assert "bitmap-interval-A-more" in texts and "bitmap-interval-B-more" in texts
    few = vector.figure(_scene(4), width=width)  # a small scene is laid out as before
    assert few.get_size_inches()[1] < h + 1e-9
