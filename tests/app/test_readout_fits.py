"""The planar readout shows whole, unscrolled, at 1280x720 with the predictions and the
ambiguity layers on (its last row, "same bitmaps", needed a scroll bar before)."""

from __future__ import annotations

import pytest
from PyQt5 import QtWidgets

from eyeviz.model.app_model import AppModel
from eyeviz.model.scene import load
from eyeviz.resources import scene_path


def _scroll(win) -> QtWidgets.QScrollArea:
    scroll = win._docks["readout"].widget()
    assert isinstance(scroll, QtWidgets.QScrollArea) and scroll.widget() is win.readout
    return scroll


def _window(make_window, qtbot):
    path = scene_path("predictions")
    sc = load(path)
    assert sc.shows("predictions") and sc.shows("ambiguity") and len(sc.estimators) == 2
    win = make_window(sc, path)
    win.resize(1280, 720)
    qtbot.waitUntil(lambda: win.width() == 1280 and win.height() == 720, timeout=3000)
    win.jobs.wait()  # the estimators' answers, not "loading…"
    qtbot.wait(100)
    return win


@pytest.mark.parametrize("selected", [0, 1])
def test_every_row_shows_unscrolled_at_1280x720(make_window, qtbot, selected):
    win = _window(make_window, qtbot)
    win.model.select(selected)
    qtbot.wait(50)
    ro, scroll = win.readout, _scroll(win)
    assert {"r", "rA", "rB", "visible", "overlap", "ambiguity", "g"} <= set(ro.texts)
    assert {"pred:analytic", "pred:compact"} <= set(ro.texts)
    assert "Δr" in ro.texts["pred:analytic"] and "g ∈ [" in ro.texts["ambiguity"]
    win._docks["readout"].raise_()
    qtbot.wait(50)
    port = scroll.viewport()
    # the widget's own size hint fits: no scroll bar is needed, none is shown
    assert ro.sizeHint().height() <= port.height(), (ro.sizeHint(), port.size())
    bar = scroll.verticalScrollBar()
    assert bar.maximum() == 0 and not bar.isVisible()
    shown = [(k, v) for k, v in ro._rows if v.isVisible()]
    assert len(shown) == len(ro.texts) - 1  # every row but g (on the title line) is shown
    for w in [ro.title, ro.size_text] + [x for row in shown for x in row]:
        top = w.mapTo(port, w.rect().topLeft())
        bottom = w.mapTo(port, w.rect().bottomRight())
        assert top.y() >= 0 and bottom.y() < port.height(), (w, bottom.y(), port.height())
        assert bottom.x() < port.width()
    # and whole: no value line is elided
    for v in [ro.size_text] + [v for _, v in shown]:
        for line in v.text().split("\n"):
            assert v.fontMetrics().horizontalAdvance(line) <= v.width(), line
    assert ro.size_text.text() == f"g = {win.model.scene.features[selected].g:g}"


def test_the_height_does_not_change_when_the_estimators_answer(make_window, qtbot, monkeypatch):
    """The dock is laid out while the estimators load: a row keeps its two lines then, or
    the readout grows past the height it was given when they answer."""
    win = _window(make_window, qtbot)
    ro = win.readout
    loaded = ro.sizeHint().height()
    monkeypatch.setattr(
        AppModel, "predictions", property(lambda m: {n: m.loading for n in m.scene.estimators})
    )
    monkeypatch.setattr(win.model, "loading", "loading analytic, compact…")
    ro.refresh()
    qtbot.wait(20)
    assert ro.texts["pred:analytic"] == "loading…"
    assert ro.sizeHint().height() == loaded
