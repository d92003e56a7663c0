"""Add a report to eyeviz: one module with HELP, add_arguments and run, one register call.

Run it: ``python examples/add_a_report.py [-o DIR]``. It registers ``eyeviz report
visibility``: the share of features, drawn uniformly in the binocular field of view
(Proposition 4), that both eyes see (Definition 1), against distance, for a few disc
radii g. Small, far discs fall between the ommatidia; the report shows where. It is written
like the package's own reports: a Markdown summary, the table as CSV and a plot, each file
written atomically (``eyeviz.reports.common.write_atomic`` / ``save_figure``). The report
asks only the eye-model seam (``eyeviz.core.eyes``) for its answers, so it runs as it is on
any eye design.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

HELP = "share of features in the binocular field that both eyes see, against distance"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("-o", "--out", required=True, type=Path, help="output directory")
    p.add_argument("--m", type=int, default=720, help="ommatidia per eye (default 720)")
    p.add_argument("--n", type=int, default=4000, help="features per radius (default 4000)")


def measure(m: int, n: int, seed: int = 0) -> list[tuple[float, float, float]]:
    """Rows (g, r, share seen by both eyes) over 8 distance bins from 1000 to 5000."""
    from eyeviz.core.eyes import eyes_from_design

    eyes = eyes_from_design({"h": 40.0, "l": 20.0, "m": m})
    rng = np.random.default_rng(seed)
    edges = np.linspace(1000.0, 5000.0, 9)
    rows = []
    for g in (2.0, 5.0, 20.0):
        r = rng.uniform(1000.0, 5000.0, n)
        phi = rng.uniform(np.pi / 6, 5 * np.pi / 6, n)
        x, y, gg = r * np.cos(phi), r * np.sin(phi), np.full(n, g)
        keep = eyes.in_bfv(x, y, gg)
        va, vb = eyes.visible(x, y, gg)
        both = (va & vb)[keep]
        rk = r[keep]
        for lo, hi in zip(edges[:-1], edges[1:], strict=True):
            sel = (rk >= lo) & (rk < hi)
            rows.append((g, (lo + hi) / 2, float(both[sel].mean()) if sel.any() else np.nan))
    return rows


def run(args: argparse.Namespace) -> int:
    from matplotlib.figure import Figure

    from eyeviz.reports.common import save_figure, write_atomic

    rows = measure(args.m, args.n)
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    csv = "g,r,seen_by_both\n" + "".join(f"{g:g},{r:g},{s:.4f}\n" for g, r, s in rows)
    write_atomic(out / "visibility.csv", csv)
    fig = Figure(figsize=(4.5, 3.0))
    ax = fig.add_subplot()
    for g in sorted({row[0] for row in rows}):
        pts = [(r, s) for gg, r, s in rows if gg == g]
        ax.plot(*zip(*pts, strict=True), marker="o", lw=1, label=f"g = {g:g}")
    ax.set(xlabel="distance r", ylabel="seen by both eyes", ylim=(0, 1.05))
    ax.legend(frameon=False)
    fig.tight_layout()
    save_figure(fig, out / "visibility.png")
    worst = min(rows, key=lambda row: row[2])
    md = (
        f"# Visibility (m = {args.m})\n\nShare of features in the BFV seen by both eyes "
        f"(Definition 1). Lowest: {worst[2]:.1%} at g = {worst[0]:g}, r = {worst[1]:g}.\n\n"
        "![visibility](visibility.png)\n"
    )
    write_atomic(out / "visibility.md", md)
    print(f"visibility: {len(rows)} rows, lowest share {worst[2]:.1%} -> {out}")
    return 0


def main() -> int:
    from eyeviz import cli
    from eyeviz.commands import report

    sys.modules.setdefault("add_a_report", sys.modules[__name__])
    report.register("visibility", "add_a_report")
    out = sys.argv[sys.argv.index("-o") + 1] if "-o" in sys.argv else tempfile.mkdtemp()
    status = cli.main(["report", "visibility", "-o", str(out), "--n", "1500"])
    for name in ("visibility.md", "visibility.csv", "visibility.png"):
        assert (Path(out) / name).stat().st_size > 0, name
    return status


if __name__ == "__main__":
    raise SystemExit(main())
