"""``eyeviz app [SCENE] [--screenshot IMAGE] [--settings JSON]``: the desktop app (issue 5)."""

from __future__ import annotations

NAME = "app"
HELP = "open the desktop app on a scene (default: assets/scenes/default.toml)"


def add_arguments(parser) -> None:
    parser.add_argument("scene", nargs="?", help="scene file (.toml); default: the paper's setting")
    parser.add_argument(
        "--screenshot",
        metavar="IMAGE",
        help="show the window, render it, save it (.png, .jpg or .jpeg) and exit "
        "(needs a display or xvfb-run)",
    )
    parser.add_argument("--settings", metavar="JSON", help=argparse_settings_help())


def argparse_settings_help() -> str:
    return (
        "JSON settings file for window layout and recent files (default: $EYEVIZ_SETTINGS, "
        "else ~/.config/eyeviz/settings.json); a file holding Qt @Variant/pickled values is "
        "refused and ignored"
    )


def run(args) -> int:
    """A planar scene opens in the 2D top view, a spherical one ([eyes] nside) in the
    3D view (eyeviz.app.view3d)."""
    from eyeviz.app.main import run_app

    return run_app(args.scene, args.screenshot, args.settings)
