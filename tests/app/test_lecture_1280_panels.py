"""The spherical lecture's last step in a 1280 x 720 window in presentation mode at 100 %
(issue 32): its panels show their words whole. The Balls table elided every name
("ta…": the docks' column was held to 40 % of the window, 512 px for the 534 px its
tables want), and the Mollweide maps dropped their "left" / "right" (too narrow a map for
the three words under it). Also checked whole: the Facets panel's two lines and the
status bar's message. Real keys (xdotool) into the real window."""

from matplotlib.text import Text
from PyQt5 import QtCore, QtGui, QtWidgets
from test_lecture3d import _focus3d
from test_presenting_real_x import _keys, window_manager  # noqa: F401

from eyeviz.model.scene import load
from eyeviz.resources import scene_path


def _overlap(a, b) -> bool:
    return min(a.x1, b.x1) > max(a.x0, b.x0) and min(a.y1, b.y1) > max(a.y0, b.y0)


def test_step_8_panels_show_their_words_whole_at_1280x720(make_window, qtbot):
    path = scene_path("sphere_lecture")
    win = make_window(load(path), path)
    win.resize(1200, 700)  # opened smaller, then as large as the screen (as F11 does)
    qtbot.waitUntil(lambda: win.width() == 1200, timeout=3000)
    qtbot.wait(300)
    win.resize(1280, 720)
    qtbot.waitUntil(lambda: win.width() == 1280, timeout=3000)
    _focus3d(win, qtbot)
    _keys(qtbot, "F5", until=lambda: win.presenter.presenting)
    n = len(load(path).steps)
    for step in range(n):
        _keys(qtbot, "Next", until=lambda s=step: win.step_index == s)
    qtbot.wait(600)
    host = win.host3d
    host.draw()
    # the Balls table: each name whole beside its swatch
    t = host.readout.table
    assert t.isVisible()
    style = t.style()
    delegate = QtWidgets.QStyledItemDelegate()  # Qt's own layout of a cell: its text room
    margin = style.pixelMetric(QtWidgets.QStyle.PixelMetric.PM_FocusFrameHMargin, None, t) + 1
    names = 0
    for i in range(t.rowCount()):
        item = t.item(i, 0)
        if item is None or not item.text():
            continue
        index = t.model().index(i, 0)
        opt = QtWidgets.QStyleOptionViewItem()
        opt.initFrom(t.viewport())
        opt.rect = t.visualRect(index)
        opt.font = t.font()
        icon = t.iconSize()
        if not icon.isValid():  # the style's own size, as the view draws it
            px = style.pixelMetric(QtWidgets.QStyle.PixelMetric.PM_SmallIconSize, None, t)
            icon = QtCore.QSize(px, px)
        opt.decorationSize = icon
        delegate.initStyleOption(opt, index)
        room = style.subElementRect(QtWidgets.QStyle.SubElement.SE_ItemViewItemText, opt, t)
        wide = QtGui.QFontMetricsF(t.font()).horizontalAdvance(item.text())  # as Qt elides
        assert wide <= room.width() - 2 * margin, (item.text(), wide, room.width())  # not "ta…"
        names += 1
    assert names == len(host.model.scene.features) == 3
    # the Facets panel's two lines and the status bar, whole
    maps = host.bitmaps
    counts = maps.counts
    assert QtWidgets.QLabel.text(counts) == counts.text(), QtWidgets.QLabel.text(counts)
    bar = win.statusBar()
    msg = bar.currentMessage()
    assert msg and bar.fontMetrics().horizontalAdvance(msg) <= bar.width() - 8, msg
    # the maps' words: left, forward, right under each map, inside the panel, apart
    maps.canvas.draw()
    rend = maps.canvas.get_renderer()
    fig = maps.fig
    words = [t for t in fig.findobj(Text) if t.get_visible() and t.get_text()]
    for name in ("left", "forward", "right"):
        shown = [t for t in words if t.get_text() == name]
        assert len(shown) == 2, (name, len(shown))  # one under each map
    boxes = [(t.get_text(), t.get_window_extent(rend)) for t in words]
    for k, (text, b) in enumerate(boxes):
        assert 0 <= b.x0 and b.x1 <= fig.bbox.width, (text, b)
        for other, b2 in boxes[k + 1 :]:
            assert not _overlap(b, b2), (text, other, b, b2)
