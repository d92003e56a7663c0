"""The 3D study's per-bin errors as Markdown (issue 38.3): for each design of a 3D study
table (``eyeviz study --nside``), its DD per distance band with the band's sampling error,
the band being ``--band`` wide (a multiple of the table's 500-wide bins, merged: the DD of
the merged band is the count-weighted mean of its bins', its standard error
sqrt(sum (count_i se_i)^2) / sum count_i, the bins being disjoint sets of balls), the
error relative to the DD (marked when above 5 %), and DD / (gamma r_mid / 2h), the law's
constant C for that band alone.

    python scripts/table_study3d.py STUDY3D.csv [--band 1000] [--estimator limit3d]
"""

from __future__ import annotations

import argparse
import math

from eyeviz.reports.errors import with_error
from eyeviz.reports.study3d import choose_estimator, designs3d, read_study3d
from eyeviz.study.point import BIN_WIDTH

#: the largest relative sampling error of a band the study aims for (issue 38.3)
REL_MAX = 0.05


def bands(bins: list[dict], width: float) -> list[dict]:
    """Merge consecutive distance bins into bands ``width`` wide (see the docstring)."""
    per = max(1, round(width / BIN_WIDTH))
    out = []
    for i in range(0, len(bins), per):
        part = bins[i : i + per]
        n = sum(b["count"] for b in part)
        if not n:
            continue
        dd = sum(b["count"] * b["dd_mape"] for b in part) / n
        se = math.sqrt(sum((b["count"] * b["dd_se"]) ** 2 for b in part)) / n
        out.append({"lo": part[0]["lo"], "hi": part[-1]["hi"], "count": n, "dd": dd, "se": se})
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("table")
    ap.add_argument("--band", type=float, default=1000.0)
    ap.add_argument("--estimator", default=None)
    a = ap.parse_args()
    rows = read_study3d(a.table)
    est = a.estimator or choose_estimator(rows)
    designs = designs3d(rows, est, "single")
    print(f"{est}: DD (MAPE, %) per {a.band:g}-wide distance band, ± the bootstrap "
          f"standard error over the band's balls; * marks a relative error above "
          f"{REL_MAX:.0%}\n")  # fmt: skip
    print("| h | l | nside | balls | r | balls in band | DD % | rel. error | "
          "DD / (γ r / 2h) |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|")
    over = 0
    for d in sorted(designs.values(), key=lambda d: (d.nside, d.h, d.l)):
        for b in bands(d.r_bins, a.band):
            rel = b["se"] / b["dd"]
            over += rel > REL_MAX
            x = d.gamma * 0.5 * (b["lo"] + b["hi"]) / (2 * d.h)
            print(
                f"| {d.h:g} | {d.l:g} | {d.nside} | {d.all['n']} | {b['lo']:.0f}-{b['hi']:.0f} "
                f"| {b['count']} | {with_error(b['dd'], b['se'])} | {100 * rel:.1f} %"
                f"{' *' if rel > REL_MAX else ''} | {b['dd'] / 100 / x:.4f} |"
            )
        al = d.all
        rel = al["dd_se"] / al["dd_mape"]
        print(
            f"| {d.h:g} | {d.l:g} | {d.nside} | {al['n']} | all | {al['count']} | "
            f"{with_error(al['dd_mape'], al['dd_se'])} | {100 * rel:.1f} % | |"
        )
    print(f"\n{over} band(s) with a relative error above {REL_MAX:.0%}")


if __name__ == "__main__":
    main()
