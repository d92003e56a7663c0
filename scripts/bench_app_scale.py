"""The app at scale (issue 25): a drag frame with 10^4 features against one with 10, with
and without the backdrop of the merged discs (same run, same scenes).

Runs under Xvfb (re-executes itself with xvfb-run when $DISPLAY is unset), 1280x800, this
machine's software OpenGL, the app's default view widget. For m = 720 with 10 and with
10,000 features (random discs in the view, bench_app.py's scenes: the harness is
scripts/_bench_app_common.py) it presses on the last feature, sends mouse-move events
along a path and times each from the event to the end of the first frame that reflects it
(glFinish, then the panels' paint events); right after each drag frame it times a bare
re-render of the window, and after the drag a *full* render (the backdrop's kept discs
dropped: every disc filled again, what a frame cost before the backdrop). It then releases
the button (the gesture's one undo step), times the release and an undo, and counts the
Scene copies an edit makes (the first run's). The 10^4 case is measured twice: with the
backdrop (eyeviz/render/vtk/backdrop.py, the app's path from BACKDROP_MIN_FEATURES
features) and with every disc in the main renderer (the path before it, and small
scenes'). The cases run in the order a, b, c, c, b, a and pool their two runs.

Printed: p50 / p95 of the drag frames, bare and full renders, the backdrop's captures and
hits during the drag; the ratios drag(10^4) / drag(10) (target <= 3x), drag(10^4) /
full render(10^4), and drag(10^4, backdrop) / drag(10^4, without). ``--crossover`` also
times renders of a drag's state at 10, 30, 100, 150, 300 and 1,000 features with the
discs in the main renderer and kept by the backdrop, alternating in one window (where
BACKDROP_MIN_FEATURES comes from: a drag frame is that render plus the same updates).

Measured 2026-11-26 on the 2-core machine (load 1.2-3.5 during the run), 120 drag frames
a case: drag p50 / p95 9.5 / 10.2 ms at 10 features; at 10^4 with the backdrop 18.7 /
35.5 ms (p50 1.97x of 10 features'), without it 196.7 / 409.3 ms (before the backdrop, on
a quiet machine, 138 ms: 17.9x); the full render at 10^4 172 ms. What is left at 10^4 is
Python: update_state's owners (a loop over the features, ~6 ms when the dragged feature's
lit facets change), the Frame and the actors' updates (~5 ms), and a full garbage
collection (~60 ms) about one frame in 60.

    xvfb-run -a .venv/bin/python scripts/bench_app_scale.py [--events 60] [--crossover]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _bench_app_common import (  # noqa: E402
    bare_render,
    drag,
    open_window,
    pct,
    release,
    scene,
    under_display,
)

SMALL, BIG = 10, 10_000
CROSSOVER = (10, 30, 100, 150, 300, 1_000)
M = 720
RATIO_TARGET = 3.0
NEVER = 10**9  # a backdrop threshold no scene reaches: every disc in the main renderer


def bench_drag(n: int, events: int, settings: str, backdrop_min: int | None, undo=True) -> dict:
    """One window of n features, the backdrop from ``backdrop_min`` features (None: the
    app's BACKDROP_MIN_FEATURES)."""
    import eyeviz.model.scene as scene_mod

    app, win, up = open_window(scene(M, n), settings)
    feats = win.actors.features
    if backdrop_min is not None:
        feats.set_backdrop_min(backdrop_min)
    bd = feats.backdrop
    c0, h0 = bd.captures, bd.hits
    d = drag(app, win, events, skip=5, period=40, warmup=3)
    captures, hits = bd.captures - c0, bd.hits - h0  # during the drag (warm-up included)
    full = []
    for _ in range(5):
        bd.invalidate()
        full.append(bare_render(win))
    out = {
        "lat": d.lat,
        "base": d.base,
        "full": full,
        "up": up,
        "captures": captures,
        "hits": hits,
        "backdrop": bd.active,
    }
    if not undo:
        release(win, d)
        win.force_close()
        app.processEvents()
        return out
    copies = [0]
    real_copy = scene_mod.Scene.copy

    def counted(self):
        copies[0] += 1
        return real_copy(self)

    scene_mod.Scene.copy = counted  # type: ignore[method-assign]
    try:
        t = time.perf_counter()
        release(win, d)
        app.processEvents()
        out["release"] = 1e3 * (time.perf_counter() - t)
        out["copies"] = copies[0]
        moved = win.model.scene.features[-1].x != 0.0
        steps = win.undo_stack.count()
        t = time.perf_counter()
        win.model.finish_gestures()
        win.undo_stack.undo()
        app.processEvents()
        win.ren_win.WaitForCompletion()
        out["undo"] = 1e3 * (time.perf_counter() - t)
        restored = win.model.scene.features[-1].x == 0.0
    finally:
        scene_mod.Scene.copy = real_copy  # type: ignore[method-assign]
    sc = win.model.scene
    t = time.perf_counter()
    for _ in range(5):
        sc.copy()
    out["copy_ms"] = 1e3 * (time.perf_counter() - t) / 5
    win.force_close()
    app.processEvents()
    out["ok"] = moved and restored and steps == 1
    return out


def crossover(n: int, settings: str, rounds: int) -> tuple[list[float], list[float]]:
    """Renders of one window of n features (a drag's state: the dragged one selected and
    moved), the discs in the main renderer and in the backdrop in turn, ``rounds`` times:
    (renders without, renders with the backdrop kept) in ms. A drag frame is this render
    plus the same model and actor updates either way."""
    app, win, _up = open_window(scene(M, n), settings)
    feats = win.actors.features
    win.model.select(n - 1)
    win.model.begin_live("bench")
    win.model.live(n - 1, x=120.0, y=1600.0)
    app.processEvents()
    off: list[float] = []
    on: list[float] = []
    for _ in range(rounds):
        feats.set_backdrop_min(NEVER)
        bare_render(win)
        off += [bare_render(win) for _ in range(3)]
        feats.set_backdrop_min(0)
        bare_render(win)  # the capture
        on += [bare_render(win) for _ in range(3)]
    win.model.end_live()
    win.force_close()
    app.processEvents()
    return off, on


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--events", type=int, default=60, help="mouse-move events per case (>= 20)")
    ap.add_argument(
        "--crossover",
        action="store_true",
        help="also time renders at 10-1,000 features with the discs kept or not",
    )
    args = ap.parse_args()
    if args.events < 20:
        ap.error(f"--events must be >= 20, got {args.events}")
    code = under_display("bench_app_scale")
    if code is not None:
        return code
    res: dict[str, dict] = {}
    with tempfile.TemporaryDirectory() as tmp:
        ini = str(Path(tmp) / "bench.ini")
        # in the order a, b, c, c, b, a (the machine's load drifts; the first window of a
        # run is the slowest): each case pools its two runs' frames
        cases = {"small": (SMALL, None), "big": (BIG, None), "big, no backdrop": (BIG, NEVER)}
        for key in [*cases, *reversed(cases)]:
            n, backdrop_min = cases[key]
            r = bench_drag(n, args.events, ini, backdrop_min)
            if key not in res:
                res[key] = r
                continue
            for k in ("lat", "base", "full"):
                res[key][k] += r[k]
            for k in ("captures", "hits"):
                res[key][k] += r[k]
            res[key]["ok"] &= r["ok"]
        cross = {n: crossover(n, ini, 10) for n in CROSSOVER} if args.crossover else {}
    names = {
        "small": f"{SMALL}",
        "big": f"{BIG:,} backdrop",
        "big, no backdrop": f"{BIG:,} no backdrop",
    }
    print(
        f"{'features':<20}{'events':>7}{'drag50':>8}{'drag95':>8}{'bare50':>8}{'full50':>8}"
        f"{'capt':>6}{'hits':>6}{'release':>9}{'undo':>8}{'copies':>7}{'copy ms':>8}{'up s':>6}"
    )
    for key, r in res.items():
        lat = r["lat"]
        print(
            f"{names[key]:<20}{len(lat):>7}{pct(lat, 50):>8.1f}{pct(lat, 95):>8.1f}"
            f"{pct(r['base'], 50):>8.1f}{pct(r['full'], 50):>8.1f}{r['captures']:>6}"
            f"{r['hits']:>6}{r['release']:>9.1f}{r['undo']:>8.1f}{r['copies']:>7}"
            f"{r['copy_ms']:>8.2f}{r['up']:>6.1f}"
        )
    big, small, old = res["big"], res["small"], res["big, no backdrop"]
    q_small = pct(big["lat"], 50) / pct(small["lat"], 50)
    q95_small = pct(big["lat"], 95) / pct(small["lat"], 95)
    print(
        f"drag at {BIG:,} / drag at {SMALL}: p50 {q_small:.2f}x, p95 {q95_small:.2f}x "
        f"(target <= {RATIO_TARGET:g}x)"
    )
    print(
        f"drag p50 at {BIG:,}, backdrop / without: {pct(big['lat'], 50) / pct(old['lat'], 50):.2f}x"
        f" ({pct(big['lat'], 50):.1f} ms / {pct(old['lat'], 50):.1f} ms)"
    )
    print(
        f"drag p50 at {BIG:,} / full render p50 at {BIG:,}: "
        f"{pct(big['lat'], 50) / pct(big['full'], 50):.2f}x"
    )
    print(
        f"full render p50 at {BIG:,} / at {SMALL}: "
        f"{pct(big['full'], 50) / pct(small['full'], 50):.2f}x"
    )
    if cross:
        print("crossover: render p50 (ms) of a drag's state, discs in the main renderer or kept")
        print(f"{'features':>9}{'main':>9}{'kept':>9}{'kept/main':>11}{'saved ms':>10}")
        for n, (off, on) in cross.items():
            a, b = pct(off, 50), pct(on, 50)
            print(f"{n:>9,}{a:>9.2f}{b:>9.2f}{b / a:>10.2f}x{a - b:>10.2f}")
    ok = all(r["ok"] for r in res.values()) and q_small <= RATIO_TARGET and big["backdrop"]
    print("all targets met" if ok else "SOME TARGETS MISSED")
    return 0


if __name__ == "__main__":
    sys.exit(main())
