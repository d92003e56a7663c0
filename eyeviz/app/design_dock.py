"""The "Eye design" dock (issue 11 item 4): the information limit against distance for the
current eyes beside the paper's.

Two plots, DD and AD limit (MAPE %, Eq. 34) against the distance r, from
:func:`eyeviz.study.point.limit_curve` (a small study point: :data:`N_CURVE` test
features of Algorithm 1's single-pass prior over r in [r_min, r_max] of Table 4, 500-wide
bins): the best any estimator that sees only the bitmaps can do with these eyes. The
paper's eyes (h 40, l 20, m 720) are computed once per process and kept.

A change of h, l or m never waits for the curve: the old curve is greyed and marked
"computing…" at once; after :data:`DEBOUNCE_MS` without a further change the new one is
computed on a worker thread (a :class:`eyeviz.app.jobs.Job` on this dock's own one-thread
pool, so an export's busy cursor and queue are not involved) and drawn when it arrives. A
result for eyes that are no longer the scene's is kept in a small cache but not drawn.
The selected feature's distance is a vertical line that follows a drag (redrawn at most
every :data:`MARKER_MS`) without any recomputation.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from typing import Any

from PyQt5 import QtCore, QtWidgets

from eyeviz.app.docks import follows_text_scale, text_scale
from eyeviz.app.jobs import Job
from eyeviz.app.panels import set_message, wrap_label
from eyeviz.core import paper
from eyeviz.model.app_model import AppModel

__all__ = ["DesignPanel", "compute_curve", "N_CURVE", "PAPER_EYES"]

N_CURVE = 5000  # test features per curve (about 0.3 s on one core)
DEBOUNCE_MS = 250  # quiet time after the last change of h, l or m before computing
MARKER_MS = 40  # the feature's marker is redrawn at most this often during a drag
CACHE = 16  # curves kept (undo / redo of an eye change shows them at once)
PLOT_PT = 10  # the smallest text of the plot (as the trajectory dock)
PAPER_EYES = (paper.H, paper.L, paper.M)
CURRENT = "#0072B2"  # Okabe-Ito blue
PAPER = "#262626"
STALE = "#B8B8B8"

Key = tuple[float, float, int]


def compute_curve(h: float, l: float, m: int) -> dict:  # noqa: E741 (the paper's name)
    """The DD and AD limit against distance for eyes (h, l, m) on Table 4's ranges."""
    from eyeviz.core.domain import DEFAULTS, Domain
    from eyeviz.study.point import limit_curve

    d = Domain(h, l, m, DEFAULTS["r_min"], DEFAULTS["r_max"], DEFAULTS["g_max"])
    out: dict[str, Any] = limit_curve(d, "single", N_CURVE, seed=0)
    out["r_min"], out["r_max"] = d.r_min, d.r_max
    return out


class DesignPanel(QtWidgets.QWidget):
    """DD and AD limit curves of the scene's eyes and the paper's, recomputed off the GUI
    thread when h, l or m change; the selected feature's distance marked."""

    _paper: dict | None = None  # the paper's curve, once per process

    def __init__(self, model: AppModel, parent: QtWidgets.QWidget | None = None) -> None:
        super().__init__(parent)
        from matplotlib.backends.backend_qt5agg import FigureCanvasQTAgg
        from matplotlib.figure import Figure
        from matplotlib.layout_engine import ConstrainedLayoutEngine

        self.model = model
        self.compute: Callable[[float, float, int], dict] = compute_curve  # tests slow it
        self.pool = QtCore.QThreadPool(self)
        self.pool.setMaxThreadCount(1)
        self.cache: dict[Key, dict] = {}
        self.wanted: Key | None = None  # the scene's eyes
        self.shown: Key | None = None  # the eyes of the curve on screen
        self.running: Key | None = None  # the eyes being computed
        self.job: Job | None = None
        self.error = ""
        self.jobs_started = 0
        self.compute_threads: list[int] = []  # thread ids of the computations (tests)
        self.marker_r: float | None = None
        self.marker_blits = 0  # marker-only redraws (tests: a drag blits, never recomputes)
        self._marker_note = ""

        self.debounce = QtCore.QTimer(self)
        self.debounce.setSingleShot(True)
        self.debounce.setInterval(DEBOUNCE_MS)
        self.debounce.timeout.connect(self._start)
        self.marker_timer = QtCore.QTimer(self)
        self.marker_timer.setSingleShot(True)
        self.marker_timer.setInterval(MARKER_MS)
        self.marker_timer.timeout.connect(self._draw_marker)

        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        lay.setSpacing(2)
        self.legend = QtWidgets.QLabel("")  # the curves' key, crisp Qt text above the plot
        self.legend.setTextFormat(QtCore.Qt.TextFormat.RichText)
        self.legend.setWordWrap(True)
        self.legend.setToolTip(
            "The information limit: the least MAPE (Eq. 34) any estimator that sees only the "
            f"two bitmaps can reach; Algorithm 1's single-pass prior, {N_CURVE} test features "
            "per curve, 500-wide distance bins (eyeviz.study.limit_curve)."
        )
        lay.addWidget(self.legend)
        self.info = wrap_label(QtWidgets.QLabel(""))
        lay.addWidget(self.info)
        self.fig = Figure(figsize=(3.0, 2.8), dpi=100, layout="constrained")
        engine = self.fig.get_layout_engine()
        assert isinstance(engine, ConstrainedLayoutEngine)  # layout="constrained"
        engine.set(h_pad=0.02, w_pad=0.02)
        self.canvas = FigureCanvasQTAgg(self.fig)
        self.canvas.setMinimumHeight(200)
        self.canvas.setMinimumWidth(220)
        self.canvas.setToolTip(self.legend.toolTip())
        lay.addWidget(self.canvas, 1)
        self.ax_dd = self.fig.add_subplot(2, 1, 1)
        self.ax_ad = self.fig.add_subplot(2, 1, 2, sharex=self.ax_dd)
        self.lines: dict[str, list] = {"current": [], "paper": []}
        self.markers = [
            ax.axvline(0, color="#333333", lw=1.4, zorder=5, visible=False, animated=True)
            for ax in (self.ax_dd, self.ax_ad)
        ]
        # the markers are blitted over a saved background: a full draw of this figure costs
        # ~90 ms, far too much for every move of a drag (issue 11: a drag never waits)
        self._bg = None
        self.canvas.mpl_connect("draw_event", self._after_draw)
        self.computing = self.ax_dd.text(
            0.5,
            0.5,
            "",
            transform=self.ax_dd.transAxes,
            ha="center",
            va="center",
            fontsize=PLOT_PT + 1,
            color="#555555",
            bbox={"boxstyle": "round,pad=0.3", "fc": "white", "ec": STALE, "alpha": 0.9},
            zorder=10,
        )
        self._style_axes()
        model.listeners.append(self._on_model)
        self.refresh()

    # --- model -> dock --------------------------------------------------------------------
    def _on_model(self, what: str, index: int | None) -> None:
        if what in ("view", "player"):
            return
        if what == "feature":  # a drag or the player: only the marker moves
            if index == self.model.selected and not self.marker_timer.isActive():
                self.marker_timer.start()
            return
        self.refresh()

    def refresh(self) -> None:
        """Follow the scene: new eyes -> stale now, computed after the debounce."""
        e = self.model.scene.eyes
        key: Key = (float(e.h), float(e.l), int(e.m))
        if key != self.wanted:
            self.wanted = key
            self.error = ""
            if key in self.cache and DesignPanel._paper is not None:
                self.debounce.stop()
                self._show(key)
            else:
                self._plot()  # greyed, "computing…"
                self.debounce.start()
        self._draw_marker()

    @property
    def stale(self) -> bool:
        """True while the curve on screen is not the scene's eyes' (or none is yet)."""
        return self.shown != self.wanted and not self.error

    # --- the computation (off the GUI thread) ---------------------------------------------
    def _start(self) -> None:
        key = self.wanted
        if key is None or self.running is not None:
            return  # a job is under way: its end starts the next one
        if key in self.cache and DesignPanel._paper is not None:
            self._show(key)
            return
        compute = self.compute
        need_paper = DesignPanel._paper is None
        threads = self.compute_threads

        def work() -> tuple[dict, dict | None]:  # worker thread
            threads.append(threading.get_ident())
            paper = compute(*PAPER_EYES) if need_paper else None
            return compute(*key), paper

        self.running = key
        self.jobs_started += 1
        job = Job(work)
        job.signals.finished.connect(  # type: ignore[call-arg]  # the stub lacks connect's type
            lambda res, err, k=key: self._finished(k, res, err),
            QtCore.Qt.ConnectionType.QueuedConnection,
        )
        self.job = job
        self.pool.start(job)

    def _finished(self, key: Key, res, err) -> None:
        self.running = None
        self.job = None
        if err is None:
            curve, paper = res
            if paper is not None:
                DesignPanel._paper = paper
            self.cache[key] = curve
            while len(self.cache) > CACHE:
                self.cache.pop(next(iter(self.cache)))
        if key == self.wanted:
            if err is not None:
                self.error = f"cannot compute the limit for these eyes: {err}"
                self._plot()
            else:
                self._show(key)
        elif not self.debounce.isActive():  # a stale result: not drawn; the latest next
            self._start()

    def wait(self, msecs: int = 30000) -> bool:
        """Block until no computation is pending (tests, screenshots)."""
        timer = QtCore.QElapsedTimer()
        timer.start()
        while self.debounce.isActive() or self.running is not None:
            if timer.elapsed() > msecs:
                return False
            QtWidgets.QApplication.processEvents(QtCore.QEventLoop.ProcessEventsFlag.AllEvents, 20)
            QtCore.QThread.msleep(5)
        return True

    # --- drawing --------------------------------------------------------------------------
    def _show(self, key: Key) -> None:
        self.shown = key
        self._plot()

    def _style_axes(self) -> None:
        """Grid, labels and ticks at the window's text scale (Ctrl+= / Ctrl+- / Ctrl+0)."""
        self._scale = scale = text_scale()
        pt = PLOT_PT * scale
        for ax, name in ((self.ax_dd, "DD"), (self.ax_ad, "AD")):
            ax.grid(True, color="#dddddd", lw=0.6)
            ax.set_ylabel(f"{name} MAPE (%)", fontsize=pt)
            ax.tick_params(labelsize=pt)
        self.ax_dd.tick_params(labelbottom=False)
        self.ax_ad.set_xlabel("distance r", fontsize=pt)
        self.computing.set_fontsize((PLOT_PT + 1) * scale)

    def changeEvent(self, ev) -> None:  # noqa: N802 (Qt name)
        """The app font changed (the text scale): the plot's text follows."""
        super().changeEvent(ev)
        drawn = getattr(self, "_scale", None)  # None: still being built
        if follows_text_scale(ev) and drawn is not None and text_scale() != drawn:
            self._style_axes()
            self.canvas.draw_idle()

    def _plot(self) -> None:
        for ln in self.lines["current"] + self.lines["paper"]:
            ln.remove()
        self.lines = {"current": [], "paper": []}
        from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

        cur = self.cache.get(self.shown) if self.shown is not None else None
        paper = DesignPanel._paper
        stale = self.stale  # being computed: "computing…"
        old = self.shown != self.wanted  # the curve drawn is not these eyes' (greyed)
        same = self.shown == PAPER_EYES
        h, l_, m = self.wanted if self.wanted is not None else PAPER_EYES
        ys: dict[str, list[float]] = {"dd": [], "ad": []}
        for ax, col in ((self.ax_dd, "dd_mape"), (self.ax_ad, "ad_mape")):
            if paper is not None and not (same and not old):
                (ln,) = ax.plot(
                    paper["r"],
                    paper[col],
                    color=PAPER,
                    lw=1.4,
                    ls="--",
                    label="paper's eyes (h 40, l 20, m 720)",
                )
                self.lines["paper"].append(ln)
                ys[col[:2]] += [float(v) for v in paper[col] if math.isfinite(v)]
            if cur is not None:
                assert self.shown is not None  # cur is its curve
                sh, sl, sm = self.shown
                label = f"{'current = paper: ' if same else ''}h {sh:g}, l {sl:g}, m {sm}"
                (ln,) = ax.plot(
                    cur["r"],
                    cur[col],
                    color=STALE if old else CURRENT,
                    lw=2.2,
                    marker="o",
                    ms=3.5,
                    label=label,
                    zorder=3,
                )
                self.lines["current"].append(ln)
                ys[col[:2]] += [float(v) for v in cur[col] if math.isfinite(v)]
        for ax, k in ((self.ax_dd, "dd"), (self.ax_ad, "ad")):
            v = [y for y in ys[k] if y > 0]
            if not v:
                continue
            lo, hi = min(v), max(v)
            if hi / lo > 8:  # log where the curves are far apart (m 180 beside m 2880)
                ax.set_yscale("log")
                ax.set_ylim(lo / 1.4, hi * 1.4)
                ax.yaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
                ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
                ax.yaxis.set_minor_formatter(NullFormatter())
            else:
                ax.set_yscale("linear")
                ax.set_ylim(0, hi * 1.12)
        ref = cur if cur is not None else paper
        if ref is not None:
            self.ax_dd.set_xlim(ref["r_min"], ref["r_max"])
        self._legend_text(cur, paper, old, same)
        self.computing.set_text(f"computing…\nh {h:g}, l {l_:g}, m {m}" if stale else "")
        self.computing.set_visible(stale)
        set_message(self.info, self.error)
        self.info.setVisible(bool(self.error))
        self.info.setStyleSheet("color: #b00020;")
        self._draw_marker(full=True)

    def _legend_text(self, cur, paper, stale: bool, same: bool) -> None:
        parts = []
        if cur is not None:
            assert self.shown is not None  # cur is its curve
            h, l_, m = self.shown
            color = STALE if stale else CURRENT
            what = "old: " if stale else ("= paper's: " if same else "")
            parts.append(f'<span style="color:{color}">━●━</span> {what}m {m}, h {h:g}, l {l_:g}')
        if paper is not None and not (same and not stale):
            parts.append(f'<span style="color:{PAPER}">╍╍╍</span> paper\'s: m 720, h 40, l 20')
        self._legend_parts = parts
        self._set_legend()

    def _set_legend(self) -> None:
        parts = list(getattr(self, "_legend_parts", []))
        if self._marker_note:
            parts.append(self._marker_note)
        self.legend.setText("<br>".join(parts))

    def _after_draw(self, _event) -> None:
        """After a full draw (inside Qt's paint): keep the background, add the markers to
        the buffer being painted (no blit here: that would repaint recursively)."""
        self._bg = self.canvas.copy_from_bbox(self.fig.bbox)
        for ax, ln in zip((self.ax_dd, self.ax_ad), self.markers, strict=True):
            ax.draw_artist(ln)

    def _blit_markers(self) -> None:
        if self._bg is None:
            return
        self.canvas.restore_region(self._bg)
        for ax, ln in zip((self.ax_dd, self.ax_ad), self.markers, strict=True):
            ax.draw_artist(ln)
        self.canvas.blit(self.fig.bbox)
        self.marker_blits += 1

    def _draw_marker(self, full: bool = False) -> None:
        """The selected feature's distance as a vertical line (no recomputation); blitted
        over the last full draw unless ``full``."""
        sc, i = self.model.scene, self.model.selected
        r = None
        if i is not None and i < len(sc.features):
            f = sc.features[i]
            r = math.hypot(f.x, f.y)
        self.marker_r = r
        lo, hi = self.ax_dd.get_xlim()
        inside = r is not None and lo <= r <= hi
        for ln in self.markers:
            ln.set_visible(inside)
            if inside:
                assert r is not None  # inside the plot
                ln.set_xdata([r, r])
                if i is not None:
                    ln.set_color(sc.features[i].color)
        note = ""
        if r is not None and i is not None:
            f = sc.features[i]
            name = f.name if len(f.name) <= 24 else f.name[:23] + "…"
            where = "" if inside else " (outside the plot)"
            note = f'<span style="color:{f.color}">┃</span> {_esc(name)}: r = {r:,.0f}{where}'
        if note != self._marker_note:
            self._marker_note = note
            self._set_legend()
        if full or self._bg is None:
            self.canvas.draw_idle()
        else:
            self._blit_markers()


def _esc(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
