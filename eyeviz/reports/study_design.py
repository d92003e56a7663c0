"""The eye designs of the study table (:mod:`eyeviz.reports.study`): grouping and lookups.

Rows grouped per design (h, l, m; Table 3), the l drawn for each h, the bin holding a
distance, the table behind the heatmap and the fewest ommatidia reaching a target error.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from eyeviz import EyevizError
from eyeviz.core import paper
from eyeviz.reports.study_table import Row

PAPER = (paper.H, paper.L, paper.M)  # the paper's eyes (Table 3)
MIN_COUNT = 30  # fewest test elements in a bin for it to be drawn / fitted


@dataclass
class Design:
    """One design point's rows: the overall row and its bins (sorted by distance)."""

    h: float
    l: float  # noqa: E741
    m: int
    all: Row
    bins: list[Row]

    @property
    def key(self) -> tuple[float, float, int]:
        return (self.h, self.l, self.m)

    @property
    def is_paper(self) -> bool:
        return self.key == PAPER


def designs_of(rows: Sequence[Row], prior: str) -> dict[tuple[float, float, int], Design]:
    """Rows of ``prior`` grouped per design; of several runs (n, seed) the largest n."""
    mine = [r for r in rows if r.prior == prior]
    if not mine:
        have = sorted({r.prior for r in rows})
        raise EyevizError(f"the study table has no rows of prior {prior!r} (it has {have})")
    runs: dict[tuple, list[Row]] = {}
    for r in mine:
        runs.setdefault(r.run, []).append(r)
    best: dict[tuple[float, float, int], list[Row]] = {}
    for run_rows in runs.values():
        d = run_rows[0].design
        if d not in best or run_rows[0].n > best[d][0].n:
            best[d] = run_rows
    out = {}
    for d, rr in best.items():
        alls = [r for r in rr if r.bin == "all"]
        bins = sorted((r for r in rr if r.bin != "all"), key=lambda r: r.r_lo)
        if not alls:
            raise EyevizError(
                f"line {rr[0].line}: design h={d[0]:g} l={d[1]:g} m={d[2]} has "
                "no overall row (bin all)"
            )
        if not bins:
            raise EyevizError(
                f"line {alls[0].line}: design h={d[0]:g} l={d[1]:g} m={d[2]} has no distance bins"
            )
        out[d] = Design(d[0], d[1], d[2], alls[0], bins)
    return dict(sorted(out.items()))


def l_per_h(designs: dict, l_wanted: float) -> dict[float, float]:
    """For each h, ``l_wanted`` if the table has it, else the l nearest to it (larger on ties)."""
    out = {}
    for h in sorted({k[0] for k in designs}):
        ls = sorted({k[1] for k in designs if k[0] == h})
        out[h] = l_wanted if l_wanted in ls else min(ls, key=lambda v: (abs(v - l_wanted), -v))
    return out


def bin_at(d: Design, at: float) -> Row | None:
    """The bin holding distance ``at`` ([r_lo, r_hi), the last bin closed)."""
    for i, b in enumerate(d.bins):
        if b.r_lo <= at < b.r_hi or (i == len(d.bins) - 1 and at == b.r_hi):
            return b
    return None


def heatmap_table(designs: dict, l_of: dict[float, float], at: float) -> list[dict]:
    """Rows (h, l, m, bin, DD and AD MAPE) behind the heatmap: one per (h, m)."""
    out = []
    for (h, l_, m), d in designs.items():
        if l_of[h] != l_:
            continue
        b = bin_at(d, at)
        if b is None:
            continue
        out.append(
            {
                "h": h,
                "l": l_,
                "m": m,
                "gamma": d.all.gamma,
                "at": at,
                "r_lo": b.r_lo,
                "r_hi": b.r_hi,
                "count": b.count,
                "dd_mape": b.dd_mape,
                "ad_mape": b.ad_mape,
                "paper_design": d.is_paper,
            }
        )
    if not out:
        lo = min(d.all.r_min for d in designs.values())
        hi = max(d.all.r_max for d in designs.values())
        raise EyevizError(f"--at {at:g} lies outside the study's distances [{lo:g}, {hi:g}]")
    return out


def smallest_m(designs: dict, l_of: dict, at: float, target: float) -> dict[float, int | None]:
    """For each h (at its l): the fewest ommatidia whose DD MAPE at ``at`` is <= target %."""
    out: dict[float, int | None] = {}
    for h, l_ in l_of.items():
        ok = [
            m
            for (hh, ll, m), d in designs.items()
            if hh == h and ll == l_ and (b := bin_at(d, at)) is not None and b.dd_mape <= target
        ]
        out[h] = min(ok) if ok else None
    return out
