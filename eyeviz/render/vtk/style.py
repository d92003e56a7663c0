"""Colours, heights and the font of the app's VTK view (no geometry, no actors)."""

from __future__ import annotations

import numpy as np

__all__ = [
    "BACKGROUND",
    "INSET_BACKGROUND",
    "UNLIT",
    "INK",
    "BFV_FILL",
    "BFV_LINE",
    "FILL_ALPHA",
    "OUT_FILL",
    "OUT_LINE",
    "LABEL_ALL_MAX",
    "EDGE_MIN_PX",
    "Z_BFV",
    "Z_AMBIGUITY",
    "Z_EYES",
    "Z_FEAT",
    "Z_LINE",
    "Z_POINT",
    "FONT_FILE",
    "style_text",
    "halo",
    "hex_rgb",
    "rgbf",
]

BACKGROUND = (1.0, 1.0, 1.0)
INSET_BACKGROUND = (0.965, 0.965, 0.955)
UNLIT = np.array([225, 225, 225], dtype=np.uint8)
INK = (0.15, 0.15, 0.15)
HALO_OPACITY = 0.92  # the title's and notes' background box (style.halo)
HALO_FRAME = (0.82, 0.82, 0.82)
BFV_FILL = (0.93, 0.91, 0.80)
BFV_LINE = (0.45, 0.42, 0.30)
FILL_ALPHA = 0.4
OUT_FILL = np.array([214, 214, 214], dtype=np.uint8)  # a feature outside the domain
OUT_LINE = np.array([140, 140, 140], dtype=np.uint8)
LABEL_ALL_MAX = 6  # more features than this: only the selected one is labelled
EDGE_MIN_PX = 7.0  # draw triangle edges when an ommatidium's rim is at least this wide
Z_BFV, Z_EYES, Z_FEAT, Z_LINE, Z_POINT = -3.0, 0.0, 1.0, 2.0, 3.0
Z_AMBIGUITY = -1.5  # above the BFV wedge, below the eyes and the features


def _font_file() -> str | None:
    """DejaVu Sans Bold from matplotlib's data (has Greek; VTK's built-in Arial has not)."""
    import importlib.util
    from pathlib import Path

    spec = importlib.util.find_spec("matplotlib")
    if spec is None or spec.origin is None:
        return None
    f = Path(spec.origin).parent / "mpl-data" / "fonts" / "ttf" / "DejaVuSans-Bold.ttf"
    return str(f) if f.exists() else None


FONT_FILE = _font_file()


def style_text(tp, size: int, color) -> None:
    """Bold DejaVu Sans at ``size`` pixels in ``color``."""
    if FONT_FILE:
        tp.SetFontFamily(4)  # VTK_FONT_FILE
        tp.SetFontFile(FONT_FILE)
    tp.SetFontSize(size)
    tp.BoldOn()
    tp.SetColor(*color)


def halo(tp, opacity: float = HALO_OPACITY) -> None:
    """A background box behind a screen text (the view's white, nearly opaque, a thin grey
    frame): geometry panned under the title or a note never crosses the letters."""
    tp.SetBackgroundColor(*BACKGROUND)
    tp.SetBackgroundOpacity(opacity)
    tp.SetFrame(True)
    tp.SetFrameColor(*HALO_FRAME)
    tp.SetFrameWidth(1)


def hex_rgb(color: str) -> tuple[int, int, int]:
    c = color.lstrip("#")
    return int(c[0:2], 16), int(c[2:4], 16), int(c[4:6], 16)


def rgbf(color: str) -> tuple[float, float, float]:
    r, g, b = hex_rgb(color)
    return r / 255.0, g / 255.0, b / 255.0
