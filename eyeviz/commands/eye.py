"""``eyeviz eye export|info``: measured eye files (docs/eye_files.md).

``eyeviz eye export (--nside N | --m M | FILE) -o OUT.eye|.gltf|.glb`` writes a HEALPix
pair, a planar ring or another eye file as a measured eye pair (CompoundRay ``.eye`` or
OCES glTF), so a CompoundRay user can render an eyeviz design; ``eyeviz eye info FILE``
prints what a file holds: ommatidia per eye, size, frame, units, acceptance angles and
the median interommatidial angle.
"""

from __future__ import annotations

import argparse
import math
import sys

NAME = "eye"
HELP = "export eyeviz's eyes as measured eye files (.eye, OCES .gltf/.glb), or describe one"
OUTPUTS = {"output": "file"}


def _file_options(p: argparse.ArgumentParser, what: str) -> None:
    p.add_argument(
        "--units",
        choices=("mm", "m", "um"),
        default=None,
        help=f"units of {what}; default the format's (mm for .eye, m for OCES)",
    )
    p.add_argument(
        "--frame",
        default=None,
        metavar="F",
        help=f"axes of {what} that become eyeviz's x (towards eye B), y (forward), z (up), "
        "e.g. 'x,-z,y', or compoundray, gltf, eyeviz; default compoundray for .eye, gltf "
        "for OCES",
    )


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    ex = sub.add_parser(
        "export",
        help="write a HEALPix pair, a planar ring or an eye file as .eye, .gltf or .glb",
        description="Write eyeviz eyes as a measured eye pair: one ommatidium per facet, the "
        "axis through the facet's centre, the acceptance angle the facet's width "
        "(docs/eye_files.md).",
    )
    src = ex.add_mutually_exclusive_group(required=True)
    src.add_argument("--nside", type=int, metavar="N", help="a HEALPix pair of nside N")
    src.add_argument("--m", type=int, metavar="M", help="a planar pair of M ommatidia a ring")
    src.add_argument("file", nargs="?", metavar="FILE", help="an eye file (.eye, .gltf, .glb)")
    ex.add_argument("--h", type=float, default=None, help="half the eye distance, mm; default 40")
    ex.add_argument("--l", type=float, default=None, help="eye radius, mm; default 20")
    ex.add_argument("-o", "--output", required=True, metavar="OUT", help="OUT.eye|.gltf|.glb")
    _file_options(ex, "the input FILE")
    ex.add_argument("--to-units", choices=("mm", "m", "um"), default=None, help="output units")
    ex.add_argument("--to-frame", default=None, metavar="F", help="output frame (as --frame)")
    ex.set_defaults(_act=_export)
    info = sub.add_parser("info", help="describe an eye file", description="Describe an eye file.")
    info.add_argument("file", metavar="FILE", help="an eye file (.eye, .gltf, .glb)")
    _file_options(info, "FILE")
    info.set_defaults(_act=_info)


def _load(args):
    from eyeviz.files.eye_io import load_eyes_quiet

    pair, warns = load_eyes_quiet(args.file, units=args.units, frame=args.frame)
    for w in warns:
        print(f"eyeviz: warning: {w}", file=sys.stderr)
    return pair


def _export(args) -> int:
    from eyeviz import EyevizError
    from eyeviz.files.eye_io import save_eyes

    if args.file is not None:
        if args.h is not None or args.l is not None:
            raise EyevizError("--h and --l are for --nside and --m, not for an eye FILE")
        pair = _load(args)
    else:
        if args.units is not None or args.frame is not None:
            raise EyevizError("--units and --frame describe an input FILE; use --to-units")
        from eyeviz.core import paper
        from eyeviz.core.geometry import EyePair
        from eyeviz.core.geometry3d import EyePair3D
        from eyeviz.core.measured_from import as_measured

        h = paper.H if args.h is None else args.h
        l = paper.L if args.l is None else args.l  # noqa: E741  (the model's name)
        if args.nside is not None:
            pair = as_measured(EyePair3D(h, l, args.nside))
        else:
            pair = as_measured(EyePair(h, l, args.m))
    out = save_eyes(pair, args.output, units=args.to_units, frame=args.to_frame)
    na, nb = pair.facet_counts
    print(f"wrote {out}: {na} + {nb} ommatidia")
    return 0


def _median_interommatidial(axes) -> float:
    """Median over facets of the angle to the nearest other facet's axis (rad)."""
    import numpy as np
    from scipy.spatial import cKDTree

    u = axes / np.linalg.norm(axes, axis=1)[:, None]
    if len(u) < 2:
        return float("nan")
    d, _ = cKDTree(u).query(u, k=2)
    return float(np.median(2 * np.arcsin(np.minimum(d[:, 1] / 2, 1.0))))


def _info(args) -> int:
    import numpy as np

    from eyeviz.files.eye_frames import parse_frame
    from eyeviz.files.eye_io import SUFFIXES, _suffix

    pair = _load(args)
    suf = _suffix(args.file)
    units = args.units or SUFFIXES[suf][0]
    frame = parse_frame(args.frame or SUFFIXES[suf][1])
    deg = 180 / math.pi
    print(f"file       {args.file}")
    print(f"format     {'CompoundRay .eye' if suf == '.eye' else 'OCES glTF ' + suf}")
    print(f"units      {units} (shown in mm)")
    print(f"frame      {frame.text} (file axes -> eyeviz x towards B, y forward, z up)")
    na, nb = pair.facet_counts
    print(f"ommatidia  A {na}, B {nb}")
    print(f"eyes       centroids {2 * pair.h:.4g} mm apart; largest lens distance from its")
    print(f"           eye's centroid {pair.l:.4g} mm")
    for e in (pair.eye_a, pair.eye_b):
        acc = e.acceptance * deg
        io = _median_interommatidial(e.axes) * deg
        print(
            f"eye {e.name}      acceptance {acc.min():.3g}..{np.median(acc):.3g}..{acc.max():.3g} "
            f"deg (min..median..max); median interommatidial angle {io:.3g} deg"
        )
    return 0


def run(args: argparse.Namespace) -> int:
    return int(args._act(args))
