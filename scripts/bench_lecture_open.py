"""Waiting for a spherical scene against the planar one, in the same run (issue 32 item 14).

Two measures, each a whole process as a user starts it (``python -m eyeviz ...``), median
of ``--repeat`` runs, interleaved (planar, spherical, planar, ...) so that the machine's
load falls on both alike:

- snapshot: ``eyeviz snapshot SCENE -o out.png`` of the planar ``lecture`` scene against
  the spherical ``sphere_lecture`` (target: the spherical one <= 2x the planar one);
- window: ``eyeviz app SCENE --screenshot out.png`` (the window shown, rendered, saved,
  closed) for the same two scenes (target: the spherical window <= 3 s).

Prints the medians and the ratios, and the load average before and after (a loaded
machine stretches both sides; the ratio is the figure to read).

    xvfb-run -a -s "-screen 0 1920x1080x24" .venv/bin/python scripts/bench_lecture_open.py
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _run(args: list[str]) -> float:
    env = dict(os.environ, QT_API="pyqt5", MPLBACKEND="Agg")
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "eyeviz", *args], check=True, env=env,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)  # fmt: skip
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--planar", default="lecture")
    ap.add_argument("--spherical", default="sphere_lecture")
    a = ap.parse_args()
    from eyeviz.resources import scene_path

    scenes = {"planar": str(scene_path(a.planar)), "spherical": str(scene_path(a.spherical))}
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    times: dict[tuple[str, str], list[float]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        settings = str(Path(tmp) / "settings.json")
        for _ in range(a.repeat):
            for side, path in scenes.items():
                out = str(Path(tmp) / f"{side}.png")
                times.setdefault(("snapshot", side), []).append(_run(["snapshot", path, "-o", out]))
                times.setdefault(("window", side), []).append(
                    _run(["app", path, "--screenshot", out, "--settings", settings])
                )
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    for what, target in (("snapshot", "<= 2x planar"), ("window", "<= 3 s")):
        p = statistics.median(times[(what, "planar")])
        s = statistics.median(times[(what, "spherical")])
        print(
            f"{what:9s} planar {p:6.2f} s   spherical {s:6.2f} s   ratio {s / p:4.2f}x"
            f"   (target {target})"
        )


if __name__ == "__main__":
    main()
