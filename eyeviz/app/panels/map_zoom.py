"""Zoom and pan on the Facets dock's Mollweide maps (:mod:`eyeviz.app.panels.bitmaps3d`).

At nside 180 a facet is under half a pixel of the dock and a ball a dot of a few pixels:
the maps show where the balls are, not which facets they light. The wheel over a map
zooms both maps about the point under the mouse (both eyes show the same window of the
view sphere), a left drag pans them, and a double click (or the dock's "Whole map"
button) goes back to the whole map. The maps never zoom out past the whole map nor pan
off it. A pure helper: it holds the limits and calls ``changed`` after each change; the
panel redraws and re-lays its pixel raster.
"""

from __future__ import annotations

from collections.abc import Callable

__all__ = ["MapZoom", "WHEEL_FACTOR", "MAX_ZOOM"]

WHEEL_FACTOR = 1.25  # one wheel notch
MAX_ZOOM = 400.0  # a nside-180 facet ~160 px wide in a 400 px dock: past that nothing new

Limits = tuple[float, float, float, float]  # x0, x1, y0, y1


class MapZoom:
    """The maps' shared view window. ``home()`` gives the whole map's limits now (they
    depend on the dock's size: the equator's label sits beside the map)."""

    def __init__(self, home: Callable[[], Limits], changed: Callable[[], None]) -> None:
        self.home = home
        self.changed = changed
        self.limits: Limits | None = None  # None: the whole map
        self._grab: tuple[float, float, Limits, float, float] | None = None

    @property
    def zoomed(self) -> bool:
        return self.limits is not None

    @property
    def factor(self) -> float:
        """How many times the whole map's width the window shows (1: the whole map)."""
        if self.limits is None:
            return 1.0
        h = self.home()
        return (h[1] - h[0]) / (self.limits[1] - self.limits[0])

    def current(self) -> Limits:
        return self.home() if self.limits is None else self.limits

    def wheel(self, x: float, y: float, notches: float) -> None:
        """Zoom by ``WHEEL_FACTOR ** notches`` about the map point (x, y)."""
        x0, x1, y0, y1 = self.current()
        f = WHEEL_FACTOR ** (-notches)
        self._set((x - (x - x0) * f, x + (x1 - x) * f, y - (y - y0) * f, y + (y1 - y) * f))

    def press(self, px: float, py: float, per_px_x: float, per_px_y: float) -> None:
        """A left press at canvas pixel (px, py); ``per_px_*``: map units per pixel now."""
        self._grab = (px, py, self.current(), per_px_x, per_px_y)

    def drag(self, px: float, py: float) -> bool:
        """Pan so that the point under the press stays under the mouse; False without a
        press."""
        if self._grab is None:
            return False
        gx, gy, (x0, x1, y0, y1), sx, sy = self._grab
        dx, dy = (px - gx) * sx, (py - gy) * sy
        if self.limits is not None:  # the whole map does not pan
            self._set((x0 - dx, x1 - dx, y0 - dy, y1 - dy))
        return True

    def release(self) -> None:
        self._grab = None

    def reset(self) -> None:
        if self.limits is not None:
            self.limits = None
            self.changed()

    def _set(self, lim: Limits) -> None:
        """The window ``lim`` kept within the whole map (and no deeper than MAX_ZOOM)."""
        hx0, hx1, hy0, hy1 = self.home()
        w = min(max(lim[1] - lim[0], (hx1 - hx0) / MAX_ZOOM), hx1 - hx0)
        h = w * (hy1 - hy0) / (hx1 - hx0)
        if w >= (hx1 - hx0) * 0.999:
            self.reset()
            return
        cx = min(max(0.5 * (lim[0] + lim[1]), hx0 + w / 2), hx1 - w / 2)
        cy = min(max(0.5 * (lim[2] + lim[3]), hy0 + h / 2), hy1 - h / 2)
        self.limits = (cx - w / 2, cx + w / 2, cy - h / 2, cy + h / 2)
        self.changed()
