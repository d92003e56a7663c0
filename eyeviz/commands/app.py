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
    if args.scene is not None:
        refuse_spherical(args.scene)
    from eyeviz.app.main import run_app

    return run_app(args.scene, args.screenshot, args.settings)


def refuse_spherical(path) -> None:
    """EyevizError (one line) for a spherical scene, before any window opens: the app
    draws planar eyes only (issue 22's 3D view is not built yet); ``eyeviz snapshot``
    draws a spherical scene. A scene that does not load is left to the app's own error."""
    from eyeviz import EyevizError
    from eyeviz.model.scene import SceneError, load

    try:
        kind = load(path).kind
    except SceneError:
        return
    if kind == "spherical":
        raise EyevizError(
            f"{path}: spherical eyes ([eyes] nside): the app's 3D view is not built yet; "
            "use eyeviz snapshot"
        )
