"""The 3D study's per-bin errors as Markdown (issue 38.3): for each design of a 3D study
table (``eyeviz study --nside``), its DD per distance band with the band's sampling error,
the band being ``--band`` wide (the table's 500-wide bins merged by
:func:`eyeviz.reports.study_design.merge_bins`: the band's DD is the count-weighted mean of its
bins', its standard error the stratified sqrt(sum (count_i se_i)^2) / sum count_i), the
error relative to the DD (marked when above 5 %), and DD / (gamma r / 2h), the law's
constant C for that band alone (r: the band's count-weighted mean distance). Then the law
DD = C gamma r / (2h) fitted on the bands as ``eyeviz report study --band`` fits it, with
its bootstrap error over the bands.

    python scripts/table_study3d.py STUDY3D.csv [--band 1000] [--estimator limit3d]
"""

from __future__ import annotations

import argparse
import math

from eyeviz.reports.errors import with_error
from eyeviz.reports.study_design import band_designs, choose_estimator, designs3d, read_study3d
from eyeviz.reports.study_law import REL_MAX, fit_law, law_points3d, law_uncertainty


def rows_md(designs: dict) -> tuple[list[str], int]:
    """The Markdown rows of every band and design (overall last), and how many of these
    rows have a relative error above :data:`REL_MAX` (or none stated)."""
    lines, over = [], 0
    for d in sorted(designs.values(), key=lambda d: (d.nside, d.h, d.l)):
        for b in d.r_bins:
            rel = b["dd_se"] / b["dd_mape"]
            over += not rel <= REL_MAX
            x = d.gamma * b["r_mid"] / (2 * d.h)
            lines.append(
                f"| {d.h:g} | {d.l:g} | {d.nside} | {d.all['n']} | {b['lo']:.0f}-{b['hi']:.0f} "
                f"| {b['count']} | {with_error(b['dd_mape'], b['dd_se'])} | {100 * rel:.1f} %"
                f"{'' if rel <= REL_MAX else ' *'} | {b['dd_mape'] / 100 / x:.4f} |"
            )
        al = d.all
        rel = al["dd_se"] / al["dd_mape"]
        over += not rel <= REL_MAX
        lines.append(
            f"| {d.h:g} | {d.l:g} | {d.nside} | {al['n']} | all | {al['count']} | "
            f"{with_error(al['dd_mape'], al['dd_se'])} | {100 * rel:.1f} %"
            f"{'' if rel <= REL_MAX else ' *'} | |"
        )
    return lines, over


def law_md(designs: dict) -> str:
    """The law fitted on the bands (:func:`~eyeviz.reports.study_law.law_points3d`'s rule)
    with its bootstrap error, in one line."""
    points = law_points3d(designs)
    fit = fit_law(points, x_max=math.inf)
    if fit.C is None:
        return f"the law: fewer than 2 bands qualify ({fit.n})"
    u = law_uncertainty(points)
    se = f" ×÷ {u['C_factor_se']:.3f} (bootstrap over the bands)" if u else ""
    slope = "" if fit.slope is None else f"; free slope {fit.slope:.2f}"
    if u and fit.slope is not None:
        slope += f" ± {u['free_slope_se']:.2f}"
    return (
        f"the law over {fit.n} bands: DD = C γr/(2h), C = {fit.C:.4f}{se}; a band within "
        f"×÷ {fit.factor:.2f} of it (1 s.d.){slope}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("table")
    ap.add_argument("--band", type=float, default=1000.0)
    ap.add_argument("--estimator", default=None)
    a = ap.parse_args()
    rows = read_study3d(a.table)
    est = a.estimator or choose_estimator(rows)
    designs = band_designs(designs3d(rows, est, "single"), a.band)
    print(f"{est}: DD (MAPE, %) per {a.band:g}-wide distance band, ± the bootstrap "
          f"standard error over the band's balls; * marks a relative error above "
          f"{REL_MAX:.0%}\n")  # fmt: skip
    print("| h | l | nside | balls | r | balls in band | DD % | rel. error | "
          "DD / (γ r / 2h) |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|")
    lines, over = rows_md(designs)
    print("\n".join(lines))
    print(f"\n{over} row(s) with a relative error above {REL_MAX:.0%}")
    print(law_md(designs))


if __name__ == "__main__":
    main()
