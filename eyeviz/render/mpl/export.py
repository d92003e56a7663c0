"""Export a scene as a figure: PNG (raster, any scale), SVG and PDF (true vectors).

``export(scene, path)`` picks the format by the file suffix and writes atomically: the
figure goes to a temporary file in the target's directory that replaces the target only
when complete, so an error or Ctrl-C leaves no (partial) file. The figure itself is
:func:`eyeviz.render.mpl.vector.figure`, drawn from the scene model (never from VTK).

matplotlib is imported inside :func:`export`, so importing this module stays light.
"""

from __future__ import annotations

import math
from pathlib import Path

from eyeviz import EyevizError
from eyeviz.files.atomic import atomic_output
from eyeviz.render.mpl.glyphs import one_glyph_warning
from eyeviz.render.mpl.style import BASE_DPI, WIDTHS

__all__ = ["FORMATS", "export", "format_of"]

FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf"}


def format_of(path) -> str:
    """'png', 'svg' or 'pdf' from the suffix of ``path``; EyevizError otherwise."""
    suffix = Path(path).suffix.lower()
    if suffix not in FORMATS:
        got = f"'{suffix}'" if suffix else "no suffix"
        raise EyevizError(f"{path}: cannot export to {got}; use .png, .svg or .pdf")
    return FORMATS[suffix]


#: PNG scale bounds (the app's export dialog offers the same range).
SCALE_MIN, SCALE_MAX = 0.25, 20.0
#: Widest PNG, in pixels: a single column at the largest scale (21000 x 28740 px, 15 s).
#: A double-width or 10 inch figure gets a smaller largest scale (a 10 in figure at scale
#: 20 was 60000 px wide: gigabytes of pixels, minutes of drawing).
MAX_PNG_PX = round(WIDTHS["single"] * BASE_DPI * SCALE_MAX)


def _check_scale(scale) -> float:
    try:
        s = float(scale)
    except (TypeError, ValueError):
        raise EyevizError(f"scale must be a number > 0, got {scale!r}") from None
    if not math.isfinite(s) or s <= 0:
        raise EyevizError(f"scale must be a finite number > 0, got {scale!r}")
    if s < SCALE_MIN:
        raise EyevizError(
            f"scale must be >= {SCALE_MIN:g} ({BASE_DPI * SCALE_MIN:g} dpi; a smaller "
            f"PNG has no readable text), got {scale!r}"
        )
    if s > SCALE_MAX:
        raise EyevizError(
            f"scale must be <= {SCALE_MAX:g} (a {s:g}x PNG would be huge), got {scale!r}"
        )
    return s


def export(
    scene,
    path,
    scale: float = 1.0,
    transparent: bool = False,
    *,
    state=None,
    predictions: dict | None = None,
    merge: bool | None = None,
    width: float | str = "single",
    title: bool = True,
    table: bool = True,
    bitmaps: bool = True,
    predictor=None,
    aspect: float | None = None,
    min_font: float | None = None,
) -> Path:
    """Write ``scene`` to ``path`` (.png, .svg or .pdf), atomically; returns the path.

    ``scale`` multiplies the PNG's pixel size (300 dpi at scale 1; a 3.5 in column is
    1050 px wide); SVG and PDF are resolution independent and ignore it. ``transparent``
    drops the white background. ``width`` is 'single' (3.5 in), 'double' (7.2 in) or
    inches; ``title``, ``table`` and ``bitmaps`` (False) leave those parts out. ``state``,
    ``predictions``, ``merge``, ``predictor``, ``aspect`` (the main view's height / width:
    the app passes its window's) and ``min_font`` (points) go to
    :func:`eyeviz.render.mpl.vector.figure`.
    """
    fmt = format_of(path)
    scale = _check_scale(scale)
    target = Path(path)
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise EyevizError(f"{target}: directory {parent} does not exist")

    from eyeviz.render.mpl import vector

    if fmt == "png":
        w_in = vector.resolve_width(width)
        px = w_in * BASE_DPI * scale
        if px > MAX_PNG_PX:
            raise EyevizError(
                f"scale {scale:g} at width {w_in:g} in makes a PNG {px:,.0f} px wide; at most "
                f"{MAX_PNG_PX} px: scale <= {MAX_PNG_PX / (w_in * BASE_DPI):.3g} at this width"
            )
    dpi = vector.BASE_DPI * scale if fmt == "png" else vector.VECTOR_DPI
    with one_glyph_warning():  # an emoji name: one line, not a warning pair per glyph
        _draw(
            scene,
            target,
            fmt,
            dpi,
            transparent,
            state=state,
            predictions=predictions,
            merge=merge,
            width=width,
            title=title,
            table=table,
            bitmaps=bitmaps,
            predictor=predictor,
            aspect=aspect,
            min_font=min_font,
        )
    return target


def _draw(scene, target: Path, fmt: str, dpi: float, transparent: bool, **kw) -> None:
    import matplotlib

    from eyeviz.render.mpl import vector

    fig = vector.figure(scene, dpi=dpi, **kw)
    with atomic_output(target) as tmp, matplotlib.rc_context(vector.RC):
        fig.savefig(
            tmp,
            format=fmt,
            dpi=dpi if fmt == "png" else 72,
            transparent=transparent,
            metadata=_metadata(fmt, scene),
        )


def _metadata(fmt: str, scene) -> dict:
    from eyeviz import __version__

    title = scene.title or "eyeviz scene"
    if fmt == "png":
        return {"Title": title, "Software": f"eyeviz {__version__}"}
    if fmt == "svg":
        return {"Title": title, "Creator": f"eyeviz {__version__}", "Date": None}
    return {"Title": title, "Creator": f"eyeviz {__version__}", "CreationDate": None}
