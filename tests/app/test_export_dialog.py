"""File > Export through the real dialog (eyeviz/app/docks.py ExportDialog): the journal's
width and the parts to include reach the file; the window never blocks on the export
(issue 12, "export for journals" and "long work never freezes the window")."""

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from PyQt5 import QtCore, QtWidgets

from eyeviz.model.scene import load

ROOT = Path(__file__).resolve().parents[2]


def _answer(win, fill):
    """Fill the dialog File > Export opens, then press OK (as the user would)."""

    def run():
        dlg = win.export_dialog_box
        if dlg is None or not dlg.isVisible():
            QtCore.QTimer.singleShot(20, run)
            return
        fill(dlg)
        ok = dlg.findChild(QtWidgets.QDialogButtonBox).button(QtWidgets.QDialogButtonBox.Ok)
        ok.click()

    QtCore.QTimer.singleShot(0, run)


@pytest.mark.slow
def test_width_and_parts_chosen_in_the_dialog_reach_the_file(make_window, tmp_path):
    win = make_window(load(ROOT / "assets" / "scenes" / "default.toml"))
    out = tmp_path / "fig.svg"

    def fill(dlg):
        dlg.path.setText(str(out))
        dlg.width_box.setCurrentIndex(1)  # double column
        dlg.parts["title"].setChecked(False)
        dlg.parts["table"].setChecked(False)

    _answer(win, fill)
    win.export_dialog()
    win.jobs.wait()
    root = ET.parse(out).getroot()
    assert root.get("width") == "518.4pt"  # 7.2 in
    texts = " ".join("".join(t.itertext()) for t in root.iter("{http://www.w3.org/2000/svg}text"))
    assert win.model.scene.title not in texts  # no title
    assert "about eye A" not in texts  # no table
    assert "m/2" in texts  # the bitmaps are kept

    seen = {}

    def check(dlg):  # the dialog opens on the previous choice
        seen.update(
            width=dlg.width_box.currentIndex(),
            title=dlg.parts["title"].isChecked(),
            table=dlg.parts["table"].isChecked(),
            bitmaps=dlg.parts["bitmaps"].isChecked(),
        )
        dlg.width_box.setCurrentIndex(2)
        dlg.inches.setValue(5.0)
        dlg.path.setText(str(tmp_path / "fig5.pdf"))

    _answer(win, check)
    win.export_dialog()
    win.jobs.wait()
    assert seen == {"width": 1, "title": False, "table": False, "bitmaps": True}
    head = (tmp_path / "fig5.pdf").read_bytes()
    assert head.startswith(b"%PDF") and b"/MediaBox [ 0 0 360 " in head  # 5 in = 360 pt


def test_the_dialog_returns_while_the_export_runs(make_window, tmp_path):
    win = make_window(load(ROOT / "assets" / "scenes" / "default.toml"))
    out = tmp_path / "big.png"

    def fill(dlg):
        dlg.path.setText(str(out))
        dlg.scale.setValue(3.0)

    _answer(win, fill)
    win.export_dialog()
    # back in the event loop at once: the window repaints and takes drags meanwhile
    assert win.jobs.busy(), "File > Export blocked the window until the file was written"
    assert QtWidgets.QApplication.overrideCursor() is not None
    win.jobs.wait()
    assert out.stat().st_size > 10_000 and not win.jobs.busy()


def test_the_exported_frame_is_the_windows(make_window, tmp_path, monkeypatch):
    """Issue 12 item 10: the exported frame differed from the window's (taller)."""
    from eyeviz.render.mpl import vector

    made = []
    real = vector.figure

    def spy(*a, **kw):
        made.append(real(*a, **kw))
        return made[-1]

    monkeypatch.setattr(vector, "figure", spy)
    win = make_window(load(ROOT / "assets" / "scenes" / "default.toml"))
    for size in ((1400, 900), (1280, 720)):
        win.resize(*size)
        QtWidgets.QApplication.processEvents()
        win.fit_view()
        assert win.export_to(tmp_path / "frame.pdf") is not None
        ax = next(a for a in made[-1].axes if a.get_gid() == "main")
        v, vp = win.model.scene.view, win.viewport("main")
        half_h = v.width * vp.height / vp.width / 2
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        assert (x0, x1) == (
            pytest.approx(v.center[0] - v.width / 2),
            pytest.approx(v.center[0] + v.width / 2),
        )
        assert y0 == pytest.approx(v.center[1] - half_h, rel=1e-3, abs=v.width * 2e-3)
        assert y1 == pytest.approx(v.center[1] + half_h, rel=1e-3, abs=v.width * 2e-3)
