"""Training data sets of the paper's Algorithm 1, single- and multi-pass, vectorised.

An element is (Omega_A, Omega_B, r, phi, g): a circular feature of radius g centred at
polar (r, phi) about the origin, and the bitmaps of ommatidia 0..m/2-1 of the left (A)
and right (B) eye that see it (Section 4; docs/contract.md).

``mode="single"`` is Algorithm 1 as written, run on whole batches: for every pending
element, draw r (step 7), g in [r sin(gamma/2), g_max] (steps 8-10) and phi in the
angular range that keeps the disc in the BFV (step 12, Prop. 4); reject it on step 9
(g_min > g_max), step 11 (g > r), an empty phi range, or when the exact geometry core
says the disc is not in the BFV or is not visible (Def. 1) to both eyes (docs/conventions.md);
rejected elements are drawn again (the repeat/until loop) until every slot is filled.

``mode="multi"`` is the paper's multi-pass generation (Section 5, Figure 11): the range of
r is cut into equal segments and each segment gets a number of elements proportional to
its mean radius, hence to its area, so that centres are (nearly) uniform over the BFV
area and the histogram of r grows linearly with r. The paper's own counts do not add up
(docs/conventions.md): here they are apportioned exactly to the requested n. The segments are
interleaved in a random order (a streamed uniform shuffle), not written one after another.

Coordinates: x = r cos(phi), y = r sin(phi) (numpy float64); the bitmaps are those of the
geometry core (:class:`eyeviz.core.geometry.EyePair`) at that (x, y, g), which is exact.
The same parameters and seed give the same elements (and the same file bytes).

Generation is streamed in chunks of :data:`CHUNK` elements, so a data set of any size is
written without holding it in memory (:func:`write`). Imports numpy only.

It is just over 400 lines because the rejection sampler (steps 7-12), the multi-pass
segment plan and the streamed generator are one algorithm, and this docstring maps each
step to the paper.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.bounds import check_r_min, check_segments
from eyeviz.core.domain import DEFAULTS, Domain
from eyeviz.core.geometry import EyePair
from eyeviz.core.validation import check_choice, check_int, check_real, num
from eyeviz.dataset import io as dataset_io
from eyeviz.dataset.records import CHUNK, PAPER_EYES, Chunk, Dataset
from eyeviz.files import limits

__all__ = [
    "CHUNK",
    "Dataset",
    "GenParams",
    "PAPER_EYES",
    "generate",
    "iter_generate",
    "load",
    "save",
    "write",
]

SEGMENT_WIDTH = 5.0  # the paper's multi-pass segment length (Section 5)
# give up after this many redraw rounds and candidates in a row without one accepted element
_MAX_IDLE_ROUNDS = 200
_MAX_IDLE_DRAWS = 200_000
MODES = ("single", "multi")


@dataclass(frozen=True)
class GenParams:
    """Validated parameters of Algorithm 1 (Tables 3, 4) and of the multi-pass plan."""

    eyes: EyePair = PAPER_EYES
    r_min: float = DEFAULTS["r_min"]
    r_max: float = DEFAULTS["r_max"]
    g_max: float = DEFAULTS["g_max"]
    mode: str = "single"
    seed: int = 0
    unique_bitmaps: bool = False
    segments: int | None = None  # multi only; default: segments of length SEGMENT_WIDTH

    @property
    def domain(self) -> Domain:
        """The design and ranges as the one parameter record, a :class:`Domain`."""
        return Domain.from_eyes(self.eyes, r_min=self.r_min, r_max=self.r_max, g_max=self.g_max)

    @classmethod
    def from_domain(cls, domain: Domain, mode: str = "single", seed: int = 0, **kw) -> GenParams:
        """Checked parameters of Algorithm 1 for ``domain`` (see :func:`make_params`)."""
        return make_params(domain, mode=mode, seed=seed, **kw)

    def as_dict(self) -> dict:
        e = self.eyes
        return {
            "h": e.h,
            "l": e.l,
            "m": e.m,
            "r_min": self.r_min,
            "r_max": self.r_max,
            "g_max": self.g_max,
            "mode": self.mode,
            "seed": self.seed,
            "unique_bitmaps": self.unique_bitmaps,
            "segments": self.segments,
        }


# --- parameters ----------------------------------------------------------------------


def effective_r_max(p: GenParams) -> float:
    """Largest r step 9 can accept: r sin(gamma/2) <= g_max."""
    return min(p.r_max, p.g_max / math.sin(p.eyes.gamma / 2))


def make_params(
    eyes: EyePair | Domain | None = None,
    r_min=None,
    r_max=None,
    g_max=None,
    mode: str = "single",
    seed: int = 0,
    unique_bitmaps: bool = False,
    segments: int | None = None,
) -> GenParams:
    """Check every parameter at the boundary (one-line :class:`EyevizError` naming it).

    Besides r_min < r_max and g_max > 0, refuse ranges where no feature can be both in the
    BFV and visible: step 8-9 needs g >= r sin(gamma/2) <= g_max for some r >= r_min, and a
    disc fits in the BFV only if g < r cos(psi) (Prop. 4: asin(g/r) <= pi/2 - psi).
    """
    if isinstance(eyes, Domain):  # the one parameter record; explicit ranges still win
        dom = eyes
        eyes = dom.eyes
        r_min = dom.r_min if r_min is None else r_min
        r_max = dom.r_max if r_max is None else r_max
        g_max = dom.g_max if g_max is None else g_max
    eyes = PAPER_EYES if eyes is None else eyes
    if not isinstance(eyes, EyePair):
        raise EyevizError(f"eyes must be an EyePair or a Domain, got {type(eyes).__name__}")
    r_min = check_real("r_min", DEFAULTS["r_min"] if r_min is None else r_min, gt=0)
    r_max = check_real("r_max", DEFAULTS["r_max"] if r_max is None else r_max, gt=0)
    g_max = check_real("g_max", DEFAULTS["g_max"] if g_max is None else g_max, gt=0)
    check_r_min(r_min, eyes.h)
    if r_min >= r_max:
        raise EyevizError(f"r_min must be < r_max, got r_min={r_min!r}, r_max={r_max!r}")
    check_choice("mode", mode, MODES)
    seed = check_int("seed", seed, ge=0)
    s = math.sin(eyes.gamma / 2)
    c = math.cos(eyes.psi)
    if g_max <= r_min * s:
        raise EyevizError(
            f"no feature can be visible: g_max={num(g_max)} <= r_min*sin(gamma/2)="
            f"{r_min * s:.6g} (Algorithm 1 step 9 rejects every r >= r_min)"
        )
    if s >= c:
        raise EyevizError(
            f"no visible feature fits in the BFV: sin(gamma/2)={s:.6g} >= cos(psi)={c:.6g} "
            f"(m={eyes.m} too small for h={num(eyes.h)}, l={num(eyes.l)})"
        )
    if segments is not None:
        segments = check_segments(segments)
    return GenParams(eyes, r_min, r_max, g_max, mode, int(seed), bool(unique_bitmaps), segments)


def check_n(n) -> int:
    return limits.check_rows(n)


# --- multi-pass plan -----------------------------------------------------------------


def segment_plan(n: int, p: GenParams) -> tuple[np.ndarray, np.ndarray]:
    """Segment edges (K+1,) and counts (K,) summing to n, counts proportional to mid radius.

    Equal-width segments of r over [r_min, r_max'] (r_max' = the largest r step 9 accepts),
    so a segment's share of the BFV annulus area is proportional to its mid radius.
    Counts are apportioned by largest remainders (deterministic).
    """
    hi = effective_r_max(p)
    k = p.segments or max(1, math.ceil((hi - p.r_min) / SEGMENT_WIDTH - 1e-9))
    edges = np.linspace(p.r_min, hi, k + 1)
    w = 0.5 * (edges[:-1] + edges[1:])
    quota = n * w / w.sum()
    counts = np.floor(quota).astype(np.int64)
    short = n - int(counts.sum())
    if short:
        order = np.argsort(-(quota - counts), kind="stable")
        counts[order[:short]] += 1
    return edges, counts


# --- Algorithm 1 on a batch ----------------------------------------------------------


class _Sampler:
    """Fills slots with accepted elements; slot i draws r in [lo_i, hi_i)."""

    def __init__(self, p: GenParams, rng: np.random.Generator):
        self.p = p
        self.rng = rng
        self.sin_half = math.sin(p.eyes.gamma / 2)
        self.psi = p.eyes.psi
        self.half = p.eyes.m // 2
        self.seen: set[int] | None = set() if p.unique_bitmaps else None
        self.drawn = 0  # candidates drawn (for the acceptance rate)

    def _keys(self, la, ra, lb, rb) -> list[int]:
        h = self.half
        if h**4 < 2**62:
            return (((la * h + ra) * h + lb) * h + rb).tolist()
        return [
            ((a * h + b) * h + c) * h + d
            for a, b, c, d in zip(la.tolist(), ra.tolist(), lb.tolist(), rb.tolist(), strict=True)
        ]

    def fill(self, n: int, lo: float | np.ndarray, hi: float | np.ndarray) -> Chunk:
        """n accepted elements; slot i draws r in [lo_i, hi_i] (scalars: every slot)."""
        p, rng, eyes = self.p, self.rng, self.p.eyes
        lo_a, hi_a = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
        per_slot = lo_a.ndim > 0
        out_r = np.empty(n)
        out_phi = np.empty(n)
        out_g = np.empty(n)
        ivs = [np.empty(n, np.int64) for _ in range(4)]
        pending = np.arange(n)
        idle = idle_draws = 0
        while pending.size:
            k = pending.size
            self.drawn += k
            u = rng.random((3, k))
            lo_p, hi_p = (lo_a[pending], hi_a[pending]) if per_slot else (lo_a, hi_a)
            r = lo_p + (hi_p - lo_p) * u[0]  # step 7
            g_min = r * self.sin_half  # step 8
            ok = g_min <= p.g_max  # step 9
            g = g_min + (p.g_max - g_min) * u[1]  # step 10
            ok &= g <= r  # step 11
            a = np.arcsin(np.minimum(g / r, 1.0))
            ph_lo = self.psi + a
            ph_hi = (math.pi - self.psi) - a
            ok &= ph_lo <= ph_hi
            phi = ph_lo + (ph_hi - ph_lo) * u[2]  # step 12
            idx = np.flatnonzero(ok)
            r, g, phi = r[idx], g[idx], phi[idx]
            x = r * np.cos(phi)
            y = r * np.sin(phi)
            la, ra, lb, rb = eyes.intervals(x, y, g)  # steps 13-16 (Prop. 2)
            good = eyes.in_bfv(x, y, g)  # Prop. 4, exact
            good &= (ra > la) & (rb > lb)  # Def. 1, both eyes
            good &= (rb < self.half) & (ra < self.half)  # Property 3 (always true)
            sel = np.flatnonzero(good)
            if self.seen is not None and sel.size:
                sel = self._new_only(sel, la, ra, lb, rb)
            if sel.size == 0:
                idle += 1
                idle_draws += k
                if idle >= _MAX_IDLE_ROUNDS and idle_draws >= _MAX_IDLE_DRAWS:
                    self._give_up(float(np.min(lo_p)), float(np.max(hi_p)))
                continue
            idle = idle_draws = 0
            dst = pending[idx[sel]]
            out_r[dst], out_phi[dst], out_g[dst] = r[sel], phi[sel], g[sel]
            for o, v in zip(ivs, (la, ra, lb, rb), strict=True):
                o[dst] = v[sel]
            keep = np.ones(k, bool)
            keep[idx[sel]] = False
            pending = pending[keep]
        return Chunk(out_r, out_phi, out_g, *ivs)

    def _new_only(self, sel, la, ra, lb, rb) -> np.ndarray:
        keys = self._keys(la[sel], ra[sel], lb[sel], rb[sel])
        seen = self.seen
        assert seen is not None  # only called with unique_bitmaps
        keep = []
        for i, key in zip(sel.tolist(), keys, strict=True):
            if key not in seen:
                seen.add(key)
                keep.append(i)
        return np.asarray(keep, dtype=np.int64)

    def _give_up(self, r_lo: float, r_hi: float) -> None:
        if self.seen is not None:
            where = f" with r in [{r_lo:.6g}, {r_hi:.6g}]" if self.p.mode == "multi" else ""
            raise EyevizError(
                f"only {len(self.seen)} distinct bitmap pairs were found after drawing "
                f"{self.drawn} candidates; no new pair{where} turns up: ask for fewer "
                "elements, or drop --unique-bitmaps"
            )
        raise EyevizError(
            f"no element was accepted in {_MAX_IDLE_DRAWS} candidates in a row: "
            "(almost) no feature in this range is visible inside the BFV"
        )


def iter_chunks(n: int, p: GenParams, chunk: int = CHUNK) -> Iterator[Chunk]:
    """Generate n elements of Algorithm 1 as :class:`Chunk` objects of <= chunk elements."""
    rng = np.random.default_rng(p.seed)
    sampler = _Sampler(p, rng)
    if p.mode == "single":
        for start in range(0, n, chunk):
            c = min(chunk, n - start)
            yield sampler.fill(c, p.r_min, p.r_max)
        return
    edges, remaining = segment_plan(n, p)
    for labels in segment_labels(remaining, chunk, rng):
        yield sampler.fill(labels.size, edges[labels], edges[labels + 1])


def segment_labels(
    counts: np.ndarray, chunk: int, rng: np.random.Generator
) -> Iterator[np.ndarray]:
    """Multi-pass chunks: each chunk's segment index per element, shuffled, drawn without
    replacement from the plan's ``counts`` (a multivariate hypergeometric share per chunk,
    the rest in the last), so the chunks together hold exactly ``counts``."""
    remaining = counts
    left = int(counts.sum())
    for _ in range(0, left, chunk):
        c = min(chunk, left)
        if c == left:
            comp = remaining
        else:
            comp = rng.multivariate_hypergeometric(remaining, c, method="marginals")
        remaining = remaining - comp
        left -= c
        labels = np.repeat(np.arange(comp.size), comp)
        rng.shuffle(labels)
        yield labels


# --- public API ----------------------------------------------------------------------


def iter_generate(
    n: int,
    eyes: EyePair | Domain | None = None,
    r_min=None,
    r_max=None,
    g_max=None,
    mode: str = "single",
    seed: int = 0,
    unique_bitmaps: bool = False,
    segments: int | None = None,
    chunk: int = CHUNK,
) -> Iterator[Dataset]:
    """Like :func:`generate`, yielding :class:`Dataset` chunks (bounded memory)."""
    n = check_n(n)
    p = make_params(eyes, r_min, r_max, g_max, mode, seed, unique_bitmaps, segments)
    for c in iter_chunks(n, p, chunk):
        yield c.to_dataset(p)


def generate(
    n: int,
    eyes: EyePair | Domain | None = None,
    r_min=None,
    r_max=None,
    g_max=None,
    mode: str = "single",
    seed: int = 0,
    unique_bitmaps: bool = False,
    segments: int | None = None,
) -> Dataset:
    """n elements of the paper's Algorithm 1 (Section 4), in memory.

    Defaults are Tables 3 and 4 (h=40, l=20, m=720; r in [1000, 5000], g_max=500).
    ``mode``: "single" (one pass, Figures 8, 10) or "multi" (segments of r with counts
    proportional to their radius, Figures 9, 11). ``unique_bitmaps``: redraw an element
    whose (Omega_A, Omega_B) pair was already produced, as the authors' published set
    has one element per pair; this thins out far, small features (few distinct bitmaps)
    and so shifts the distribution towards near and large ones.
    """
    return Dataset.concat(
        list(iter_generate(n, eyes, r_min, r_max, g_max, mode, seed, unique_bitmaps, segments))
    )


def write(
    path,
    n: int,
    eyes: EyePair | Domain | None = None,
    r_min=None,
    r_max=None,
    g_max=None,
    mode: str = "single",
    seed: int = 0,
    unique_bitmaps: bool = False,
    segments: int | None = None,
    progress: Callable[[int], None] | None = None,
) -> None:
    """Generate n elements straight into ``path`` (.csv or .npz), streamed and atomic.

    Every parameter is checked before the file is touched; ``progress(k)`` is called
    after each chunk of k elements.
    """
    n = check_n(n)
    p = make_params(eyes, r_min, r_max, g_max, mode, seed, unique_bitmaps, segments)
    fmt = dataset_io.format_of(path)
    dataset_io.write_chunks(path, fmt, n, p.eyes.m, p.as_dict(), iter_chunks(n, p), progress)


def sample_domain(n: int, domain: Domain, mode: str = "single", seed: int = 0) -> Dataset:
    """:func:`generate` of ``domain`` (the planar row of :mod:`eyeviz.dataset.kinds`)."""
    return generate(n, domain, mode=mode, seed=seed)


def chunks_domain(n: int, domain: Domain, mode: str = "single", seed: int = 0):
    """:func:`iter_chunks` of ``domain`` (the planar row of :mod:`eyeviz.dataset.kinds`)."""
    return iter_chunks(n, make_params(domain, mode=mode, seed=seed))


def save(ds: Dataset, path) -> None:
    """Write an in-memory data set to ``path`` (.csv or .npz), atomically."""
    dataset_io.save(ds, path)


def load(path, eyes: EyePair | None = None) -> Dataset:
    """Read a data set written by :func:`save`/:func:`write` (or any CSV of docs/contract.md).

    A CSV does not record h and l: ``eyes`` defaults to Table 3's with m from the number
    of columns (m + 3 with g, m + 2 without). A malformed CSV raises an error naming the
    line and column.
    """
    return dataset_io.load(path, eyes)
