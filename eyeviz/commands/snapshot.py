"""``eyeviz snapshot SCENE -o OUT.png|.svg|.pdf``: a scene as a figure, headless.

No window, no Qt, no VTK: the figure is drawn by matplotlib (Agg) from the scene model
(:mod:`eyeviz.render.mpl.vector`). torch is imported only when the scene shows predictions.
A spherical scene (``[eyes] nside``) is drawn by :mod:`eyeviz.render.mpl.figure3d`: the 3D
view (the eyes close up and the scene), each eye's facets on a Mollweide map and a readout
table. SVG and PDF draw the view from the model as polygons; the PNG is the same figure
with the view rendered off-screen by VTK, as the app's 3D view draws it
(:func:`eyeviz.render.vtk.png3d.export_png3d`, EGL: no display), at the view box's pixel
size: ``--width`` inches at 300 dpi times ``--scale``, the view ``--aspect`` of its width
high (docs/spherical.md).
"""

from __future__ import annotations

import argparse

NAME = "snapshot"
HELP = "export a scene as a figure (PNG, or true-vector SVG/PDF) without opening a window"
#: What the command writes, checked before any work (eyeviz.files.outputs).
OUTPUTS = {"output": "file"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", metavar="SCENE", help="scene file (TOML)")
    parser.add_argument(
        "-o",
        "--output",
        metavar="OUT",
        required=True,
        help="output file; the suffix picks the format: .png, .svg or .pdf",
    )
    parser.add_argument(
        "--scale",
        type=float,
        default=1.0,
        metavar="S",
        help="PNG pixel scale (1 = 300 dpi, 1050 px wide); default 1",
    )
    parser.add_argument(
        "--transparent", action="store_true", help="transparent background instead of white"
    )
    parser.add_argument(
        "--width",
        default="single",
        metavar="W",
        help="figure width: 'single' (3.5 in, one journal column), 'double' (7.2 in) "
        "or inches between 3 and 10; default single",
    )
    parser.add_argument(
        "--aspect",
        type=float,
        default=None,
        metavar="A",
        help="the scene view's height / width, in [0.3, 1.6]: a wide scene (features beside "
        "the eyes) wastes less of the figure at 0.5; default 0.86 at a single column, 0.5 at "
        "a double one, interpolated between (the app's File > Export uses its window's)",
    )
    parser.add_argument(
        "--min-font",
        default=None,
        metavar="PT",
        help="no text smaller than PT points, in [6, 12] (a journal asking for 7 or 8 pt); "
        "table rows and label lanes grow to match; default: the figure's own sizes (6 pt "
        "smallest)",
    )
    parser.add_argument(
        "--view",
        default="default",
        metavar="V",
        help="spherical scenes: the 3D view's camera preset, one of default, front, top, side, "
        "eye_a, eye_b, framing the balls; default: default",
    )
    parser.add_argument("--no-title", action="store_true", help="leave the title out")
    parser.add_argument("--no-table", action="store_true", help="leave the readout table out")
    parser.add_argument("--no-bitmaps", action="store_true", help="leave the bitmap strips out")


def run(args: argparse.Namespace) -> int:
    import os

    os.environ.setdefault("MPLBACKEND", "Agg")
    from eyeviz.model import scene as scene_mod
    from eyeviz.render.mpl.export import export, format_of
    from eyeviz.render.mpl.style import check_min_font
    from eyeviz.render.mpl.vector import check_drawable, resolve_aspect, resolve_width

    format_of(args.output)  # refuse a bad suffix, width or aspect before reading anything
    width = resolve_width(args.width)
    aspect = resolve_aspect(args.aspect, width)
    min_font = None if args.min_font is None else check_min_font(args.min_font)
    sc = scene_mod.load(args.scene)
    if sc.in_space:
        from eyeviz.core.validation import check_choice
        from eyeviz.model.camera3d import PRESETS

        check_choice("view", args.view, PRESETS)
    elif args.view != "default":
        from eyeviz import EyevizError

        raise EyevizError("view: a planar scene has one view (--view is for spherical scenes)")
    if sc.in_space:  # HEALPix or measured eyes: the view, the maps and the table (figure3d)
        from eyeviz import EyevizError
        from eyeviz.render.mpl.figure3d import check_drawable3d, export3d
        from eyeviz.render.mpl.glyphs import one_glyph_warning

        check_drawable3d(sc)
        from eyeviz.model.draw_bounds import check_drawable_eyes

        check_drawable_eyes(sc, "png" if format_of(args.output) == "png" else "vector")
        opts = dict(
            scale=args.scale,
            transparent=args.transparent,
            width=width,
            title=not args.no_title,
            table=not args.no_table,
            bitmaps=not args.no_bitmaps,
            aspect=None if args.aspect is None else aspect,
            view=args.view,
            min_font=min_font,
        )
        with one_glyph_warning():  # an emoji name: one line, not a warning pair per glyph
            if format_of(args.output) == "png":  # the same figure, the view rendered by VTK
                from eyeviz.render.vtk.png3d import export_png3d

                out = export_png3d(sc, args.output, **opts)
            else:
                out = export3d(sc, args.output, **opts)
        print(out)
        return 0
    check_drawable(sc)  # too many features or undrawable coordinates: refused at once
    out = export(
        sc,
        args.output,
        scale=args.scale,
        transparent=args.transparent,
        width=width,
        title=not args.no_title,
        table=not args.no_table,
        bitmaps=not args.no_bitmaps,
        aspect=aspect,
        min_font=min_font,
    )
    print(out)
    return 0
