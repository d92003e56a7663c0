"""``eyeviz app [SCENE] [--screenshot IMAGE] [--settings JSON]``: the desktop app (issue 5)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile

NAME = "app"
HELP = "open the desktop app on a scene (default: assets/scenes/default.toml)"
#: What the command writes, checked before any work (eyeviz.files.outputs).
OUTPUTS = {"screenshot": "file"}


def add_arguments(parser) -> None:
    parser.add_argument("scene", nargs="?", help="scene file (.toml); default: the paper's setting")
    parser.add_argument(
        "--screenshot",
        metavar="IMAGE",
        help="show the window, render it, save it (.png, .jpg or .jpeg) and exit; with no "
        "display it runs itself on a virtual one (xvfb-run), if installed",
    )
    parser.add_argument("--settings", metavar="JSON", help=argparse_settings_help())


def argparse_settings_help() -> str:
    return (
        "JSON settings file for window layout and recent files (default: $EYEVIZ_SETTINGS, "
        "else ~/.config/eyeviz/settings.json); a file holding Qt @Variant/pickled values is "
        "refused and ignored"
    )


#: Set in the environment of the copy started under xvfb-run (never starts another).
VIRTUAL_ENV_FLAG = "EYEVIZ_ON_XVFB"


def _no_display() -> bool:
    return not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY")


def screenshot_on_xvfb(argv: list[str]) -> int | None:
    """With no display, ``--screenshot`` runs this same command on a virtual X display
    (``xvfb-run -a``) and returns its exit status; None when there is a display, when
    xvfb-run is not installed (the window's own one-line "no display" error follows) or
    when this process already is that copy."""
    if not _no_display() or os.environ.get(VIRTUAL_ENV_FLAG):
        return None
    xvfb = shutil.which("xvfb-run")
    if xvfb is None:
        return None
    print("eyeviz: no display: rendering the window on a virtual one (xvfb-run)", file=sys.stderr)
    env = dict(os.environ, **{VIRTUAL_ENV_FLAG: "1"})
    if env.get("VTK_DEFAULT_OPENGL_WINDOW") == "vtkEGLRenderWindow":
        del env["VTK_DEFAULT_OPENGL_WINDOW"]  # set by eyeviz.render.vtk for no display
    if not env.get("XDG_RUNTIME_DIR"):  # else Qt warns on every start
        env["XDG_RUNTIME_DIR"] = tempfile.mkdtemp(prefix="eyeviz-xdg-")
    cmd = [xvfb, "-a", "-s", "-screen 0 1920x1080x24", sys.executable, "-m", "eyeviz", *argv]
    return subprocess.run(cmd, env=env, check=False).returncode


def run(args) -> int:
    """A planar scene opens in the 2D top view, a spherical one ([eyes] nside) in the
    3D view (eyeviz.app.view3d)."""
    if args.screenshot:
        argv = ["app"] + ([args.scene] if args.scene else [])
        argv += ["--screenshot", args.screenshot]
        argv += ["--settings", args.settings] if args.settings else []
        rc = screenshot_on_xvfb(argv)
        if rc is not None:
            return rc
    from eyeviz.app.main import run_app

    try:
        return run_app(args.scene, args.screenshot, args.settings)
    except MemoryError:
        # fatal: exit now. Returning left the process alive until killed (issue 36: "out
        # of memory" printed, then Qt's thread pool waited on a job that never ended)
        print("eyeviz: error: out of memory", file=sys.stderr, flush=True)
        os._exit(2)
