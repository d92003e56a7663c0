"""``eyeviz app [SCENE] [--screenshot PNG]``: the desktop app (issue 5)."""

from __future__ import annotations

NAME = "app"
HELP = "open the desktop app on a scene (default: assets/scenes/default.toml)"


def add_arguments(parser) -> None:
    parser.add_argument("scene", nargs="?", help="scene file (.toml); default: the paper's setting")
    parser.add_argument(
        "--screenshot",
        metavar="PNG",
        help="show the window, render it, save it to PNG and exit (needs a display or xvfb-run)",
    )
    parser.add_argument("--settings", metavar="INI", help=argparse_settings_help())


def argparse_settings_help() -> str:
    return "settings file for window layout and recent files (default: the user's config)"


def run(args) -> int:
    from eyeviz.app.window import run_app

    return run_app(args.scene, args.screenshot, args.settings)
