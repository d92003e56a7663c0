"""The eye designs of the study table (:mod:`eyeviz.reports.study`): grouping and lookups.

Planar eyes: rows grouped per design (h, l, m; Table 3), the l drawn for each h, the bin
holding a distance, the table behind the heatmap and the fewest ommatidia reaching a
target error. Spherical eyes (a 3D table, ``eyeviz study --nside``): its rows read and
grouped per design (h, l, nside) of one estimator, the estimator drawn, distance bins
merged into bands (:func:`merge_bins`) and every bin's sampling error.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

from eyeviz import EyevizError
from eyeviz.core import paper
from eyeviz.reports.study_table import Row
from eyeviz.study.point import BIN_WIDTH
from eyeviz.study.table import iter_rows3d

PAPER = (paper.H, paper.L, paper.M)  # the paper's eyes (Table 3)
MIN_COUNT = 30  # fewest test elements in a bin for it to be drawn / fitted
#: The paper's eyes in 3D: h = 40, l = 20 and nside 180 (m = 720 on the equator).
PAPER3D = (paper.H, paper.L, paper.NSIDE)
#: Names of the accuracy limit (the posterior) in the estimator registry.
LIMITS = ("limit3d", "limit")


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


# The spherical eyes (a 3D study table)


@dataclass
class Design3D:
    """One 3D design point's rows: overall, distance bins (by r), elevation bins (by el)."""

    h: float
    l: float  # noqa: E741
    nside: int
    gamma: float
    all: dict
    r_bins: list[dict]
    el_bins: list[dict]

    @property
    def key(self) -> tuple[float, float, int]:
        return (self.h, self.l, self.nside)


def choose_estimator(rows: list[dict]) -> str:
    """The limit (:data:`LIMITS`) when the table has it, else the estimator measured on
    the most designs (of those, the first by name)."""
    designs: dict[str, set] = {}
    for r in rows:
        designs.setdefault(r["estimator"], set()).add((r["h"], r["l"], r["nside"]))
    return min(designs, key=lambda e: (e not in LIMITS, -len(designs[e]), e))


def read_study3d(path) -> list[dict]:
    """The rows of a 3D study table, read by the study tables' one parser (the runner's
    checks and one-line errors naming the file and the first bad line,
    :mod:`eyeviz.study.table`); the report adds only: at least one row."""
    rows = [row for _, row in iter_rows3d(path)]
    if not rows:
        raise EyevizError(f"{path}: the 3D study table has no rows")
    return rows


def designs3d(rows: list[dict], estimator: str, prior: str) -> dict[tuple, Design3D]:
    """The rows of ``estimator`` and ``prior`` per design; of several runs the largest n."""
    runs: dict[tuple, list[dict]] = {}
    for r in rows:
        if r["estimator"] == estimator and r["prior"] == prior:
            runs.setdefault(r["_key"], []).append(r)
    if not runs:
        raise EyevizError(
            f"the 3D study table has no rows of estimator {estimator!r} and prior {prior!r}"
        )
    best: dict[tuple, list[dict]] = {}
    for rr in runs.values():
        k = (rr[0]["h"], rr[0]["l"], rr[0]["nside"])
        if k not in best or rr[0]["n"] > best[k][0]["n"]:
            best[k] = rr
    out = {}
    for k, rr in best.items():
        alls = [r for r in rr if r["bin"] == "all"]
        rb = sorted((r for r in rr if r["bin"].startswith("r")), key=lambda r: r["lo"])
        eb = sorted((r for r in rr if r["bin"].startswith("e")), key=lambda r: r["lo"])
        out[k] = Design3D(k[0], k[1], k[2], alls[0]["gamma"], alls[0], rb, eb)
    return out


_MERGED_MEANS = ("dd_mape", "ad_mape", "el_mae_deg", "az_mae_deg")


def merge_bins(bins: list[dict], width: float) -> list[dict]:
    """Consecutive distance bins (of :data:`~eyeviz.study.point.BIN_WIDTH`, in order of r)
    merged into bands ``width`` wide, a whole multiple of the bin width; empty bands are
    left out. The bins are disjoint sets of balls, so a band's mean errors (DD and AD
    MAPE, elevation and azimuth mean |error|) are its bins' means weighted by their
    counts, exactly the means over the band's balls, and a band's sampling error the
    stratified one: se = sqrt(sum (count_i se_i)^2) / sum count_i (``dd_se``, ``el_se``).
    ``r_mid`` is the mean of the bins' mid-distances weighted by their counts: the law's
    r for the band (its predicted DD is the mean of C gamma r / (2h) over the balls)."""
    k = width / BIN_WIDTH
    if not (math.isfinite(k) and k >= 1 and abs(k - round(k)) < 1e-9):
        raise EyevizError(
            f"--band must be a whole multiple of the table's {BIN_WIDTH:g}-wide bins, got {width!r}"
        )
    per = round(k)
    out = []
    for j, i in enumerate(range(0, len(bins), per)):
        part = [b for b in bins[i : i + per] if b["count"] > 0]
        n = sum(b["count"] for b in part)
        if not n:
            continue
        band = {"bin": f"r{j}", "lo": bins[i]["lo"], "hi": bins[min(i + per, len(bins)) - 1]["hi"]}
        band["count"], band["flagged"] = n, sum(b["flagged"] for b in part)
        for key in _MERGED_MEANS:
            band[key] = sum(b["count"] * b.get(key, math.nan) for b in part) / n
        for key in ("dd_se", "el_se"):
            band[key] = math.sqrt(sum((b["count"] * b.get(key, math.nan)) ** 2 for b in part)) / n
        band["r_mid"] = sum(b["count"] * 0.5 * (b["lo"] + b["hi"]) for b in part) / n
        out.append(band)
    return out


def band_designs(designs: dict[tuple, Design3D], width: float) -> dict[tuple, Design3D]:
    """The designs with their distance bins merged into bands ``width`` wide
    (:func:`merge_bins`); the overall and elevation rows as they are."""
    return {k: replace(d, r_bins=merge_bins(d.r_bins, width)) for k, d in designs.items()}


def bin_errors(designs: dict[tuple, Design3D]) -> list[dict]:
    """Every distance bin of every design with its DD, its sampling error (``dd_se``,
    bootstrap over the bin's rows) and that error relative to the DD."""
    out = []
    for d in sorted(designs.values(), key=lambda d: d.key):
        for b in d.r_bins:
            se = b.get("dd_se", math.nan)
            out.append({
                "h": d.h, "l": d.l, "nside": d.nside, "bin": b["bin"], "lo": b["lo"],
                "hi": b["hi"], "count": b["count"], "dd_mape": b["dd_mape"], "dd_se": se,
                "rel_se": se / b["dd_mape"] if b["dd_mape"] > 0 else math.nan,
            })  # fmt: skip
    return out


def _nearest(values, want: float) -> float:
    return min(values, key=lambda v: (abs(math.log(v / want)), v))
