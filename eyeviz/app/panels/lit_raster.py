"""The lit facets of an eye whose facets are smaller than the dock's pixels, painted
straight into the canvas's pixels (the Facets dock, :mod:`eyeviz.app.panels.bitmaps3d`).

At nside 180 a HEALPix facet is about 0.4 pixel wide on the dock's map and a ball at the
paper's distances lights thousands of them: filling and stroking their polygons took most
of a drag frame (80-100 ms of Agg under load, more than the 3D view's render), for what
ends up as a few hundred pixels. Here each pixel of the map knows the facet under its
centre (:func:`eyeviz.render.mpl.facet_map.facet_at`, computed once per layout), so a
frame is one gather of the lit facets' colours over the map's pixels; each lit facet also
colours the pixel holding its centre (a ball lighting a few sub-pixel facets still
shows). The selected ball's outline is a ring of pixels, the halo's half-width wide, one
pixel away from its facets, where no lit facet is: at nside 180 a ball is a dot of a few
pixels, and a ring touching it made it a black blob.
"""

from __future__ import annotations

import math

import numpy as np

from eyeviz.model.facet_patches import FacetPatches
from eyeviz.render.mpl.facet_map import facet_at, mollweide, view_lonlat

__all__ = ["GAP_PX", "LitRaster"]

GAP_PX = 1  # unpainted pixels between the selected ball's dot and its outline


class LitRaster:
    """One eye's map as pixels: :meth:`layout` after each full draw (the axes' pixels and
    the facet under each), :meth:`paint` into the canvas's RGBA buffer on every repaint."""

    def __init__(self, patches: FacetPatches, halo_px: int) -> None:
        self.patches = patches
        self.halo_px = max(1, int(halo_px))
        self.box: tuple[int, int, int, int] | None = None  # rows r0:r1, columns c0:c1
        self.rows = self.cols = self.facet = np.zeros(0, np.int64)
        self.crow = self.ccol = np.zeros(0, np.int64)
        self.on_img = np.zeros((0, 0), bool)
        self.height = 0
        self.trans = None
        self.owner = np.full(patches.n, -1, np.int64)
        self.pix = np.zeros(0, np.int64)  # lit facets (sorted)
        self.ball = np.zeros(0, np.int64)  # the ball colouring each
        self.rgba = np.zeros((0, 4), np.uint8)
        self.sel = np.zeros(0, np.int64)  # the selected ball's lit facets

    def layout(self, ax, height: int) -> None:
        """The pixels of ``ax`` (buffer rows counted from the top of a canvas ``height``
        pixels high) and the facet under each pixel's centre (-1 off the map)."""
        x0, y0, x1, y1 = ax.bbox.extents
        c0, c1 = max(0, math.ceil(x0)), math.floor(x1)
        b0, b1 = max(0, math.ceil(y0)), min(height, math.floor(y1))
        if c1 <= c0 or b1 <= b0:
            self.box = None
            return
        xs, ys = np.meshgrid(np.arange(c0, c1) + 0.5, np.arange(b0, b1) + 0.5)
        data = ax.transData.inverted().transform(np.column_stack([xs.ravel(), ys.ravel()]))
        fac = facet_at(self.patches, data[:, 0], data[:, 1])
        on = fac >= 0
        rows = (height - 1 - np.floor(ys.ravel()).astype(np.int64))[on]
        cols = np.floor(xs.ravel()).astype(np.int64)[on]
        fac = fac[on]
        order = np.argsort(fac, kind="stable")  # the pixels by facet (see _pixels)
        self.facet, self.rows, self.cols = fac[order], rows[order], cols[order]
        self.box = (height - b1, height - b0, c0, c1)
        self.on_img = np.zeros((b1 - b0, c1 - c0), bool)  # the map's pixels in the box
        self.on_img[rows - self.box[0], cols - c0] = True
        self.trans = ax.transData
        self.height = height
        self.crow = np.full(self.patches.n, -1, np.int64)  # facets' centre pixels, lazily
        self.ccol = np.full(self.patches.n, -1, np.int64)

    def _pixels(self, pix: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Buffer (rows, columns) of the pixels whose centre lies in the facets ``pix``,
        and the facet of each."""
        lo = np.searchsorted(self.facet, pix, "left")
        cnt = np.searchsorted(self.facet, pix, "right") - lo
        idx = np.repeat(lo - np.cumsum(cnt) + cnt, cnt) + np.arange(int(cnt.sum()))
        return self.rows[idx], self.cols[idx], np.repeat(pix, cnt)

    def set(self, pix: np.ndarray, ball: np.ndarray, rgba: np.ndarray, sel: np.ndarray) -> None:
        """The lit facets (sorted), the ball colouring each, the balls' colours (0-1 RGBA)
        and the selected ball's lit facets."""
        self.owner[self.pix] = -1
        self.owner[pix] = ball
        self.pix, self.ball, self.sel = pix, ball, sel
        self.rgba = np.round(np.clip(np.asarray(rgba, np.float64), 0, 1) * 255).astype(np.uint8)

    def _centres(self, pix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Buffer (row, column) of the facets' centres, -2 outside the axes' box (a zoomed
        map); each facet's computed once per layout (a drag lights mostly the facets lit
        before)."""
        new = pix[self.crow[pix] < 0]
        if new.size:
            self.crow[new], self.ccol[new] = self._project(new)
        return self.crow[pix], self.ccol[pix]

    def _project(self, pix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        c = self.patches.centers(pix)
        lon, lat = view_lonlat(np.arctan2(c[:, 1], c[:, 0]), np.arcsin(np.clip(c[:, 2], -1, 1)))
        x, y = mollweide(lon, lat)
        assert self.trans is not None and self.box is not None
        d = self.trans.transform(np.column_stack([x, y]))
        r0, r1, c0, c1 = self.box
        rows = self.height - 1 - np.floor(d[:, 1]).astype(np.int64)
        cols = np.floor(d[:, 0]).astype(np.int64)
        out = (rows < r0) | (rows >= r1) | (cols < c0) | (cols >= c1)
        rows[out] = cols[out] = -2
        return rows, cols

    def paint(self, buf: np.ndarray, ink: np.ndarray) -> int:
        """Paint the halo (``ink``, 4 uint8) then the lit facets into ``buf`` (H, W, 4
        uint8, the canvas's buffer); returns the pixels painted."""
        if self.box is None or (self.pix.size == 0 and self.sel.size == 0):
            return 0
        r, c, f = self._pixels(self.pix)
        cr, cc = self._centres(self.pix)
        shown = cr >= 0
        rows, cols = np.concatenate([r, cr[shown]]), np.concatenate([c, cc[shown]])
        own = self.owner[np.concatenate([f, self.pix[shown]])]
        done = 0
        if self.sel.size:
            done = self._halo(buf, ink, rows, cols)
        buf[rows, cols] = self.rgba[own]
        return done + rows.size

    def _halo(self, buf: np.ndarray, ink: np.ndarray, rows, cols) -> int:
        """The selected ball's outline: a ring ``halo_px`` wide one pixel away from its
        pixels (a dot of a few pixels stays whole inside it, issue 32.9), on the map,
        not lit (``rows``, ``cols``: the lit pixels), within the box around its pixels."""
        r0, r1, c0, c1 = self.box  # type: ignore[misc]
        sr, sc, _ = self._pixels(self.sel)
        cr, cc = self._centres(self.sel)
        sr, sc = np.concatenate([sr, cr[cr >= 0]]), np.concatenate([sc, cc[cr >= 0]])
        if sr.size == 0:  # off a zoomed map
            return 0
        k = self.halo_px + GAP_PX
        ra, rb = max(r0, int(sr.min()) - k), min(r1, int(sr.max()) + k + 1)
        ca, cb = max(c0, int(sc.min()) - k), min(c1, int(sc.max()) + k + 1)
        sel = np.zeros((rb - ra, cb - ca), bool)
        sel[sr - ra, sc - ca] = True
        ring = _grown(sel, k) & ~_grown(sel, GAP_PX)
        inside = (rows >= ra) & (rows < rb) & (cols >= ca) & (cols < cb)
        ring[rows[inside] - ra, cols[inside] - ca] = False
        ring &= self.on_img[ra - r0 : rb - r0, ca - c0 : cb - c0]
        hr, hc = np.nonzero(ring)
        buf[hr + ra, hc + ca] = ink
        return int(hr.size)


def _grown(sel: np.ndarray, k: int) -> np.ndarray:
    """``sel`` grown by a disc of radius ``k`` pixels."""
    grown = sel.copy()
    h, w = sel.shape
    for dr in range(-k, k + 1):
        for dc in range(-k, k + 1):
            if dr * dr + dc * dc <= k * k + k and (dr or dc):
                grown[max(dr, 0) : h + min(dr, 0), max(dc, 0) : w + min(dc, 0)] |= sel[
                    max(-dr, 0) : h - max(dr, 0), max(-dc, 0) : w - max(dc, 0)
                ]
    return grown
