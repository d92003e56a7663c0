"""Algorithm 1 in 3D: the sparse data set of the spherical eyes, single- and multi-pass.

An element is a ball of radius g centred at (r, azimuth, elevation) about the origin
(x = r cos(el) cos(az), y = r cos(el) sin(az), z = r sin(el)) and, per eye, the RING
indices of the HEALPix facets it lights (:class:`eyeviz.core.geometry3d.EyePair3D`,
exact). The rules are the planar generator's (:mod:`eyeviz.dataset.algorithm1`, the
paper's Algorithm 1), with the elevation added:

``mode="single"``: for every pending element draw r uniform in [r_min, r_max] (step 7),
g uniform in [g_min, g_max] with g_min = r sin(gamma/2) (steps 8-10; gamma = 2 pi / m,
m = 4 nside the equatorial facet count), the elevation uniform in [-el_max, el_max], and
the azimuth uniform over the field's azimuth range at that (r, el, g) (step 12: the
azimuths where the ball is outside both tangent cones from the origin, half-angle
psi = asin(l/h) about the x-axis, i.e. |cos(el) cos(az)| <= cos(psi + asin(g/r)), in
front: 0 < az < pi). Reject it on step 9 (g_min > g_max), step 11 (g > r), an empty
azimuth range, or when the exact geometry says the ball is not in the 3D binocular field
(``EyePair3D.in_bfv``: outside both cones and in front, y >= g; the azimuth range above
is the cones' part, y >= g only cuts near az = 0 and pi at the top of the band) or is not
visible to both eyes (Definition 1 in 3D: at least two facets lit per eye, counted on the
lit lists written out); rejected elements are drawn again until every slot is filled.

``field="both-eyes"`` (:data:`FIELDS`; HEALPix eyes) replaces the wedge by what both eyes
see: the azimuth is uniform in front, [0, pi], and a ball is kept when it touches neither
eye, neither eye hides its centre from the other (the lit sets do not model occlusion),
and it lights at least two facets of each eye. The wedge stays the default: it reduces to
the paper's field at z = 0. It is not "seen by both eyes": balls above and below the
plane can light facets of both eyes outside it (docs/spherical.md, "Which field").

``mode="multi"``: uniform density over the field's volume. The range of r is cut into
segments (of length :data:`SEGMENT_WIDTH`, as the planar multi-pass) whose counts are
proportional to their volume, b^3 - a^3, apportioned exactly to n; within a segment r has
density proportional to r^2; the elevation has density proportional to cos(el) on
[-el_max, el_max] and the azimuth is uniform over the field's widest azimuth range in the
band (the one at |el| = el_max), the exact field test rejecting the rest. So, for given
r and g, a centre is uniform over the solid angle of the field in the band; rejected
elements are redrawn in their own segment, which keeps the r histogram proportional to
r^2. Segments are interleaved in a random order, as in the planar generator.

**Measured eyes** (a :class:`Domain3D` of kind "measured", docs/measured.md) follow the
same steps with the pair's own geometry: gamma is the interommatidial angle
(:attr:`Domain3D.gamma`), and r, azimuth and elevation are about the midpoint of the two
lens centroids (:attr:`Domain3D.origin`; x = o_x + r cos(el) cos(az), ...), measured in
eyeviz's frame as for the HEALPix eyes. No cone bounds the azimuth (a real pair's field
has no closed form): the azimuth is uniform on [0, pi] (in front) and the exact field
test ``in_bfv`` (lights >= 2 facets of each eye, contains no lens) rejects the rest.

Chunks of :func:`chunk_rows` elements (fewer at large balls and fine facets, so that a
chunk's lit lists stay within :data:`LIT_BUDGET` indices per eye) are generated one after
another from one seeded ``numpy.random.Generator``: the same parameters and seed give the
same elements and the same file bytes. Imports numpy only.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.bounds import check_r_min, check_segments
from eyeviz.core.domain import Domain3D
from eyeviz.core.validation import check_choice, check_int, num
from eyeviz.dataset.algorithm1 import SEGMENT_WIDTH, segment_labels
from eyeviz.dataset.records import Dataset3D, index_dtype, spherical_to_xyz
from eyeviz.files import limits

__all__ = [
    "CHUNK3D",
    "FIELDS",
    "LIT_BUDGET",
    "MODES",
    "Gen3DParams",
    "chunk_rows",
    "generate3d",
    "iter_chunks3d",
    "make_params3d",
    "segment_plan3d",
]

MODES = ("single", "multi")
#: The binocular field a ball must lie in (docs/spherical.md, "Which field"): ``wedge``,
#: the paper's wedge rotated about the baseline (outside both tangent cones from the
#: origin, in front: ``EyePair3D.in_bfv``; the HEALPix default, the paper at z = 0), or
#: ``both-eyes``: in front, touching neither eye, at least two facets lit in each (the
#: only field of a measured pair, whose eyes have no cones).
FIELDS = ("wedge", "both-eyes")
#: Most elements in one generated chunk.
CHUNK3D = 4096
#: Most lit indices per eye a chunk may hold (at the largest ball the domain allows).
LIT_BUDGET = 1 << 23
# give up after this many redraw rounds and candidates in a row without one accepted element
_MAX_IDLE_ROUNDS = 200
_MAX_IDLE_DRAWS = 200_000


@dataclass(frozen=True)
class Gen3DParams:
    """Validated parameters of Algorithm 1 in 3D (see :func:`make_params3d`)."""

    domain: Domain3D
    mode: str = "single"
    seed: int = 0
    segments: int | None = None  # multi only; default: segments of length SEGMENT_WIDTH
    field: str = "wedge"  # FIELDS; a measured pair's is always "both-eyes"

    def as_dict(self) -> dict:
        """The parameters a data set records (``field`` only where it is not the default
        of its eyes: files of the default field keep their bytes)."""
        d = {**self.domain.to_dict(), "mode": self.mode, "seed": self.seed,
             "segments": self.segments}  # fmt: skip
        if self.field != _default_field(self.domain):
            d["field"] = self.field
        return d


def _default_field(domain: Domain3D) -> str:
    """The eyes' default binocular field (the first they state)."""
    return str(domain.eyes.binocular_fields[0])


def make_params3d(
    domain: Domain3D | None = None,
    mode: str = "single",
    seed: int = 0,
    segments: int | None = None,
    field: str | None = None,
) -> Gen3DParams:
    """Check every parameter at the boundary (one-line :class:`EyevizError` naming it).

    ``field`` (:data:`FIELDS`; None: the eyes' default, ``wedge`` for HEALPix eyes and
    ``both-eyes`` for a measured pair, which has no wedge).

    Besides the domain's own checks, refuse ranges where no ball can be both in the field
    and visible: steps 8-9 need r sin(gamma/2) <= g_max for some r >= r_min, and a ball
    of angular radius a = asin(g/r) >= gamma/2 fits between the cones only if
    psi + a < pi/2.
    """
    domain = Domain3D() if domain is None else domain
    if not isinstance(domain, Domain3D):
        raise EyevizError(f"domain must be a Domain3D, got {type(domain).__name__}")
    check_choice("mode", mode, MODES)
    field = _default_field(domain) if field is None else field
    check_choice("field", field, FIELDS)
    if field not in domain.eyes.binocular_fields:  # a measured pair has no wedge
        raise EyevizError(
            "field 'wedge' is the HEALPix eyes' (their tangent cones); a measured pair's "
            "binocular field is 'both-eyes'"
        )
    seed = check_int("seed", seed, ge=0)
    check_r_min(domain.r_min, domain.h)
    s = math.sin(domain.gamma / 2)
    if domain.g_max <= domain.r_min * s:
        raise EyevizError(
            f"no feature can be visible: g_max={num(domain.g_max)} <= r_min*sin(gamma/2)="
            f"{domain.r_min * s:.6g} (Algorithm 1 step 9 rejects every r >= r_min)"
        )
    if field == "both-eyes":  # a measured pair's only field (checked above)
        pass  # no cones: the exact field test decides (module docstring)
    elif domain.gamma / 2 + domain.psi >= math.pi / 2:
        raise EyevizError(
            f"no visible feature fits in the binocular field: gamma/2 + psi >= pi/2 "
            f"(nside={domain.nside} too small for h={num(domain.h)}, l={num(domain.l)})"
        )
    if segments is not None:
        segments = check_segments(segments)
    return Gen3DParams(domain, mode, int(seed), segments, field)


def check_n(n) -> int:
    return limits.check_rows(n)


def effective_r_max(d: Domain3D) -> float:
    """Largest r step 9 can accept: r sin(gamma/2) <= g_max."""
    return min(d.r_max, d.g_max / math.sin(d.gamma / 2))


def max_lit(d: Domain3D) -> int:
    """An upper estimate of the facets one eye sees of any ball of the domain.

    A ball seen from an eye centre at distance >= r_min - h subtends at most
    a = asin(g_max / (r_min - h)); its cap covers the fraction (1 - cos a)/2 of the
    sphere, plus a rim of cells along its border (each about sqrt(4 pi / npix) wide).
    """
    if d.kind == "measured":  # every facet, at worst
        return max(d.facet_counts)
    npix = d.npix
    near = d.r_min - d.h
    if near <= d.g_max:
        return npix
    a = math.asin(d.g_max / near)
    cell = math.sqrt(4 * math.pi / npix)
    est = npix * (1 - math.cos(a)) / 2 + 4 * (2 * math.pi * math.sin(a) + 4 * cell) / cell + 16
    return min(npix, int(est))


def chunk_rows(d: Domain3D) -> int:
    """Elements per chunk: CHUNK3D, fewer when LIT_BUDGET indices per eye would not hold
    CHUNK3D of the largest balls (at least 1). Fixed by the domain, so the output never
    depends on anything else."""
    return max(1, min(CHUNK3D, LIT_BUDGET // max_lit(d)))


# --- multi-pass plan -----------------------------------------------------------------


def segment_plan3d(n: int, p: Gen3DParams) -> tuple[np.ndarray, np.ndarray]:
    """Segment edges (K+1,) and counts (K,) summing to n, counts proportional to each
    segment's volume b^3 - a^3 (largest remainders, deterministic)."""
    d = p.domain
    hi = effective_r_max(d)
    k = p.segments or max(1, math.ceil((hi - d.r_min) / SEGMENT_WIDTH - 1e-9))
    edges = np.linspace(d.r_min, hi, k + 1)
    w = edges[1:] ** 3 - edges[:-1] ** 3
    quota = n * w / w.sum()
    counts = np.floor(quota).astype(np.int64)
    short = n - int(counts.sum())
    if short:
        order = np.argsort(-(quota - counts), kind="stable")
        counts[order[:short]] += 1
    return edges, counts


# --- sampling ------------------------------------------------------------------------


def _take_rows(indptr: np.ndarray, indices: np.ndarray, rows: np.ndarray):
    """CSR rows ``rows`` (in that order) of (indptr, indices)."""
    lens = (indptr[1:] - indptr[:-1])[rows]
    out_ptr = np.zeros(rows.size + 1, np.int64)
    np.cumsum(lens, out=out_ptr[1:])
    total = int(out_ptr[-1])
    # position j of the output comes from indptr[row] + (j - out_ptr[row's slot])
    src = np.repeat(indptr[rows] - out_ptr[:-1], lens) + np.arange(total, dtype=np.int64)
    return out_ptr, indices[src]


class _Sampler3D:
    """Fills slots with accepted elements; slot i draws r in [lo_i, hi_i]."""

    def __init__(self, p: Gen3DParams, rng: np.random.Generator):
        d = p.domain
        self.p = p
        self.d = d
        self.eyes = d.eyes
        self.rng = rng
        self.sin_half = math.sin(d.gamma / 2)
        self.measured = d.kind == "measured"
        self.free = p.field == "both-eyes"  # no cones bound the azimuth
        self.psi = 0.0 if self.free else d.psi
        self.origin = np.asarray(d.origin) if self.measured else None
        self.multi = p.mode == "multi"
        self.dtype = index_dtype(max(d.facet_counts))

    def _candidates(self, k: int, lo, hi):
        """k candidates (r, az, el, g) and the mask of those steps 7-12 keep."""
        d, u = self.d, self.rng.random((4, k))
        if self.multi:  # density proportional to r^2 within the segment
            lo3 = lo**3
            r = np.cbrt(lo3 + (hi**3 - lo3) * u[0])
            r = np.clip(r, lo, hi)
        else:
            r = lo + (hi - lo) * u[0]  # step 7
        g_min = r * self.sin_half  # step 8
        ok = g_min <= d.g_max  # step 9
        g = g_min + (d.g_max - g_min) * u[1]  # step 10
        ok &= g <= r  # step 11
        if self.free:  # no cones: azimuth uniform in front, the field test decides
            cone = np.zeros_like(r)
        else:
            a = np.arcsin(np.minimum(g / r, 1.0))
            cone = self.psi + a  # the ball's centre must be >= cone from the x-axis
            ok &= cone < math.pi / 2
        if self.multi:  # density proportional to cos(el): uniform in solid angle
            el = np.arcsin(math.sin(d.el_max) * (2 * u[2] - 1))
            c_el = math.cos(d.el_max)
        else:
            el = d.el_max * (2 * u[2] - 1)
            c_el = np.cos(el)
        with np.errstate(invalid="ignore"):
            az0 = np.arccos(np.minimum(np.cos(cone) / c_el, 1.0))  # step 12's range
        az = az0 + (math.pi - 2 * az0) * u[3]
        return r, az, el, g, ok

    def _in_field(self, x, y, z, g) -> np.ndarray:
        """The field test before the facet counts: the wedge (``in_bfv``), a measured
        pair's own ``in_bfv``, or for HEALPix eyes' ``both-eyes`` touching neither eye
        (the >= 2 facets per eye are counted on the lit lists, as for every field)."""
        if self.measured or not self.free:
            return np.asarray(self.eyes.in_bfv(x, y, z, g), bool)
        touch_a, touch_b = self.eyes.overlaps_eye(x, y, z, g)
        ok = ~(np.asarray(touch_a, bool) | np.asarray(touch_b, bool))
        h, l_ = float(self.d.h), float(self.d.l)
        return ok & _sight_clear(x, y, z, -h, h, l_) & _sight_clear(x, y, z, h, -h, l_)

    def fill(self, n: int, lo, hi) -> Dataset3D:
        """n accepted elements; slot i draws r in [lo_i, hi_i] (scalars: every slot)."""
        lo_a, hi_a = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
        per_slot = lo_a.ndim > 0
        out = np.empty((7, n))
        got_slots: list[np.ndarray] = []
        got_a: list[tuple[np.ndarray, np.ndarray]] = []
        got_b: list[tuple[np.ndarray, np.ndarray]] = []
        pending = np.arange(n)
        idle = idle_draws = 0
        while pending.size:
            k = pending.size
            lo_p, hi_p = (lo_a[pending], hi_a[pending]) if per_slot else (lo_a, hi_a)
            r, az, el, g, ok = self._candidates(k, lo_p, hi_p)
            idx = np.flatnonzero(ok)
            good = idx[:0]
            if idx.size:
                x, y, z = spherical_to_xyz(r[idx], az[idx], el[idx])
                if self.origin is not None:
                    x, y, z = x + self.origin[0], y + self.origin[1], z + self.origin[2]
                inb = np.flatnonzero(self._in_field(x, y, z, g[idx]))
                idx, x, y, z = idx[inb], x[inb], y[inb], z[inb]
            if idx.size:
                (pa, ia), (pb, ib) = self.eyes.lit_csr(x, y, z, g[idx])
                # Definition 1 in 3D, both eyes: at least two facets lit
                good = np.flatnonzero((np.diff(pa) >= 2) & (np.diff(pb) >= 2))
            if good.size == 0:
                idle += 1
                idle_draws += k
                if idle >= _MAX_IDLE_ROUNDS and idle_draws >= _MAX_IDLE_DRAWS:
                    raise EyevizError(
                        f"no element was accepted in {_MAX_IDLE_DRAWS} candidates in a row: "
                        "(almost) no ball in this range is visible inside the binocular field"
                    )
                continue
            idle = idle_draws = 0
            sel = idx[good]
            dst = pending[sel]
            out[:, dst] = r[sel], az[sel], el[sel], g[sel], x[good], y[good], z[good]
            got_slots.append(dst)
            for got, ptr, ind in ((got_a, pa, ia), (got_b, pb, ib)):
                ind = ind.astype(self.dtype, copy=False)
                got.append((ptr, ind) if good.size == ptr.size - 1 else _take_rows(ptr, ind, good))
            keep = np.ones(k, bool)
            keep[sel] = False
            pending = pending[keep]
        # rows were accepted round by round: put them in slot order
        slots = np.concatenate(got_slots)
        if np.all(slots[1:] > slots[:-1]):  # one round took every slot
            csr = [_concat_csr(parts) for parts in (got_a, got_b)]
        else:
            order = np.argsort(slots, kind="stable")
            csr = [_take_rows(*_concat_csr(parts), order) for parts in (got_a, got_b)]
        r, az, el, g, x, y, z = out
        (pa, ia), (pb, ib) = csr
        return Dataset3D(pa, ia, pb, ib, r, az, el, g, x, y, z, self.d, self.p.as_dict())


def _sight_clear(x, y, z, from_x: float, other_x: float, l_: float) -> np.ndarray:
    """The segment from the eye centre (from_x, 0, 0) to the ball centre (x, y, z) passes
    farther than l from the other eye's centre (other_x, 0, 0): the other eye does not
    hide the ball's centre (the lit sets do not model occlusion; the field does)."""
    dx = np.asarray(x, float) - from_x
    y_, z_ = np.asarray(y, float), np.asarray(z, float)
    n2 = dx * dx + y_ * y_ + z_ * z_
    t = np.clip((other_x - from_x) * dx / n2, 0.0, 1.0)
    ex = from_x + t * dx - other_x
    return ex * ex + (t * y_) ** 2 + (t * z_) ** 2 > l_ * l_


def _concat_csr(parts: list) -> tuple[np.ndarray, np.ndarray]:
    if len(parts) == 1:
        return parts[0]
    ptrs, base = [np.zeros(1, np.int64)], 0
    for ptr, _ in parts:
        ptrs.append(ptr[1:] + base)
        base += int(ptr[-1])
    return np.concatenate(ptrs), np.concatenate([ind for _, ind in parts])


def iter_chunks3d(n: int, p: Gen3DParams) -> Iterator[Dataset3D]:
    """Generate n elements as :class:`Dataset3D` chunks of <= :func:`chunk_rows` rows."""
    rng = np.random.default_rng(p.seed)
    sampler = _Sampler3D(p, rng)
    chunk = chunk_rows(p.domain)
    d = p.domain
    if p.mode == "single":
        for start in range(0, n, chunk):
            yield sampler.fill(min(chunk, n - start), d.r_min, d.r_max)
        return
    edges, remaining = segment_plan3d(n, p)
    for labels in segment_labels(remaining, chunk, rng):
        yield sampler.fill(labels.size, edges[labels], edges[labels + 1])


def generate3d(
    n: int,
    domain: Domain3D | None = None,
    mode: str = "single",
    seed: int = 0,
    segments: int | None = None,
    field: str | None = None,
) -> Dataset3D:
    """n elements of Algorithm 1 in 3D, in memory (:func:`eyeviz.dataset.sparse3d.write3d`
    streams them to a file instead)."""
    n = check_n(n)
    p = make_params3d(domain, mode, seed, segments, field)
    return Dataset3D.concat(list(iter_chunks3d(n, p)))


def chunks_domain3d(n: int, domain: Domain3D, mode: str = "single", seed: int = 0):
    """:func:`iter_chunks3d` of ``domain`` (the sparse rows of :mod:`eyeviz.dataset.kinds`)."""
    return iter_chunks3d(n, make_params3d(domain, mode, seed))
