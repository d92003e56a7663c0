"""Measured eyes (eyeviz.core.measured): the seen rule decided exactly, against the
brute-force reference (eyeviz.reference.measured_reference) on random, tangent,
lens-enclosing, tiny and huge balls; the seam's predicates consistent with lit; the
index's candidates a superset; the validation's one-line errors."""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eyeviz import EyevizError
from eyeviz.core import kernels, measured_fast
from eyeviz.core.measured import MeasuredEye, MeasuredEyePair
from eyeviz.core.measured_exact import seen_exact
from eyeviz.files.eye_io import load_eyes, shipped_eye
from eyeviz.reference.measured_reference import reference_lens_in_ball, reference_lit

SHIPPED = ["AM_60185-real.eye", "BT_77973-real.eye", "1000-horizontallyAcute-variableDegree.eye"]
_PAIRS: dict[str, MeasuredEyePair] = {}


def shipped(name: str) -> MeasuredEyePair:
    if name not in _PAIRS:
        _PAIRS[name] = load_eyes(shipped_eye(name))
    return _PAIRS[name]


def hand_eye(seed: int = 0, n: int = 30) -> MeasuredEyePair:
    """Two small eyes of n facets each: lenses on spheres of radius 0.5 about (-+1, 0, 0),
    axes the outward normals tilted and scaled by powers of two, per-facet acceptance."""
    rng = np.random.default_rng(seed)
    eyes = []
    for sx, nm in ((-1.0, "A"), (1.0, "B")):
        nrm = rng.normal(size=(n, 3))
        nrm[:, 0] = np.abs(nrm[:, 0]) * sx + 0.3 * sx
        nrm /= np.linalg.norm(nrm, axis=1)[:, None]
        pos = np.array([sx, 0.0, 0.0]) + 0.5 * nrm
        ax = (nrm + 0.2 * rng.normal(size=(n, 3))) * np.ldexp(1.0, rng.integers(-20, 20, n))[
            :, None
        ]
        acc = rng.uniform(0.05, 1.5, n)
        eyes.append(MeasuredEye(pos, ax, acc, name=nm))
    return MeasuredEyePair(eyes[0], eyes[1], name="hand")


def random_balls(pair: MeasuredEyePair, n: int, seed: int):
    """Balls about the head: distances 0.3 to 300 head widths, angular radii 0.01 to 30 deg."""
    rng = np.random.default_rng(seed)
    scale = max(pair.h, pair.l)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    r = scale * np.exp(rng.uniform(math.log(0.3), math.log(300), n))
    g = r * np.sin(np.radians(np.exp(rng.uniform(math.log(0.01), math.log(30), n))))
    return (*(d * r[:, None]).T, g)


def check_against_reference(pair: MeasuredEyePair, x, y, z, g) -> None:
    (pa, ia), (pb, ib) = pair.lit_csr(x, y, z, g)
    for k in range(len(x)):
        c = (float(x[k]), float(y[k]), float(z[k]))
        for eye, (p, ix) in zip("AB", ((pa, ia), (pb, ib)), strict=True):
            want = reference_lit(*pair.facets(eye), c, float(g[k]))
            got = ix[p[k] : p[k + 1]]
            assert np.array_equal(got, want), (eye, c, float(g[k]))


@pytest.fixture(params=["jit", "numpy"])
def path(request, monkeypatch):
    """Both implementations of the fast path and the index: the compiled one (numba) and
    the numpy reference (cKDTree, EYEVIZ_JIT=0)."""
    monkeypatch.setenv("EYEVIZ_JIT", "1" if request.param == "jit" else "0")
    if request.param == "jit":
        kernels.warm()  # compiles or loads them: used for calls of any size
    assert measured_fast.use_jit(1) == (request.param == "jit")
    return request.param


# --- the rule against the reference -----------------------------------------------------
@pytest.mark.parametrize("name", SHIPPED)
def test_random_balls_equal_the_reference(name, path):
    pair = shipped(name)
    check_against_reference(pair, *random_balls(pair, 40, seed=len(name)))


def test_hand_eye_random_balls_equal_the_reference(path):
    pair = hand_eye(1)
    check_against_reference(pair, *random_balls(pair, 200, seed=2))


@pytest.mark.parametrize("count", [1, 2, 3])
def test_calls_of_one_two_and_three_balls_equal_the_reference(path, count):
    # the index's candidate search has a branch of its own for a single ball: calls of
    # a few balls must give every ball its own facets, not only the first
    pair = hand_eye(1)
    check_against_reference(pair, *(v[:count] for v in random_balls(pair, 3, seed=5)))


@settings(max_examples=150, deadline=None, derandomize=True)
@given(
    st.tuples(*[st.floats(-30, 30, allow_nan=False, allow_subnormal=False)] * 3),
    st.floats(1e-6, 40),
    st.integers(0, 3),
)
def test_hand_eye_hypothesis(c, g, seed):
    check_against_reference(hand_eye(seed), [c[0]], [c[1]], [c[2]], [g])


def _tangent_ball(p, a, dr, rng):
    """A centre c outside the cone of (p, a, dr) on the side (alpha < theta < alpha + pi/2)
    and its exact distance from the cone (mpmath, 50 digits)."""
    a = np.asarray(a, dtype=np.float64)
    u = a / np.linalg.norm(a)
    w = np.cross(u, rng.normal(size=3))
    w /= np.linalg.norm(w)
    theta = dr / 2 + rng.uniform(0.05, 1.4)
    c = np.asarray(p) + rng.uniform(0.5, 20) * (math.cos(theta) * u + math.sin(theta) * w)
    with mpmath.workdps(50):
        v = [mpmath.mpf(float(ci)) - mpmath.mpf(float(pi)) for ci, pi in zip(c, p, strict=True)]
        am = [mpmath.mpf(float(x)) for x in a]
        dot = sum(x * y for x, y in zip(v, am, strict=True))
        vn = mpmath.sqrt(sum(x * x for x in v))
        th = mpmath.acos(dot / (vn * mpmath.sqrt(sum(x * x for x in am))))
        dist = vn * mpmath.sin(th - mpmath.mpf(float(dr)) / 2)
    return c, float(dist)


@pytest.mark.parametrize("name", SHIPPED + ["hand"])
def test_tangent_balls_up_to_the_last_bit(name, path):
    pair = hand_eye(5) if name == "hand" else shipped(name)
    rng = np.random.default_rng(7)
    for eye in "AB":
        pos, ax, acc = pair.facets(eye)
        for i in rng.choice(pos.shape[0], 6, replace=False).tolist():
            c, g0 = _tangent_ball(pos[i], ax[i], float(acc[i]), rng)
            gs = [np.nextafter(g0, 0.0), g0, np.nextafter(g0, np.inf)]
            lits = []
            for g in gs:
                la, lb = pair.lit(*c, g)
                lits.append(la if eye == "A" else lb)
            # g0 is dist rounded to nearest: one below is < dist, one above > dist
            assert i not in lits[0] and i in lits[2]
            check_against_reference(pair, *([v] * 3 for v in c), gs)


@pytest.mark.parametrize("name", ["AM_60185-real.eye", "hand"])
def test_apex_ties_are_seen(name, path):
    """|c - p| = g exactly with c behind the lens: the distance is |c - p| = g (seen);
    one float less is not seen by that facet, and the lens leaves the closed ball."""
    pair = hand_eye(3) if name == "hand" else shipped(name)
    pos, ax, acc = pair.facets("B")
    unit = ax / np.linalg.norm(ax, axis=1)[:, None]
    done = 0
    for q, r in (((1, 2, 2), 3), ((2, 3, 6), 7), ((-4, 4, 7), 9), ((6, -6, 7), 11)):
        w = np.array(q, dtype=np.float64) / r
        i = int(np.argmin(unit @ w))  # the facet looking most away from w
        assert math.acos(float(unit[i] @ w)) > float(acc[i]) / 2 + math.pi / 2
        v = np.array(q, dtype=np.float64) * 2.0**-9
        c = pos[i] + v
        if any(
            Fraction(float(c[k])) - Fraction(float(pos[i, k])) != Fraction(v[k]) for k in range(3)
        ):
            continue
        g = r * 2.0**-9
        assert i in pair.lit(*c, g)[1]
        assert i not in pair.lit(*c, np.nextafter(g, 0.0))[1]
        assert pair.overlaps_eye(*c, g)[1]
        assert pair.overlaps_eye(*c, np.nextafter(g, 0.0))[1] == reference_lens_in_ball(
            pos, c, np.nextafter(g, 0.0)
        )
        check_against_reference(pair, *([v] * 2 for v in c), [g, np.nextafter(g, 0.0)])
        done += 1
    assert done >= 2


@pytest.mark.parametrize("name", SHIPPED)
def test_lens_enclosing_balls(name):
    pair = shipped(name)
    rng = np.random.default_rng(11)
    pos, _, _ = pair.facets("A")
    x, y, z, g = [], [], [], []
    for i in rng.choice(pos.shape[0], 8, replace=False).tolist():
        c = pos[i] + rng.normal(size=3) * pair.l * 0.05
        for gg in (pair.l * 0.01, pair.l * 0.3, pair.l * 3):
            x.append(c[0])
            y.append(c[1])
            z.append(c[2])
            g.append(gg)
    check_against_reference(pair, x, y, z, g)
    oa, ob = pair.overlaps_eye(x, y, z, g)
    for k in range(len(x)):
        c = (x[k], y[k], z[k])
        assert oa[k] == reference_lens_in_ball(pair.facets("A")[0], c, g[k])
        assert ob[k] == reference_lens_in_ball(pair.facets("B")[0], c, g[k])
    assert not pair.in_bfv(x, y, z, g)[oa | ob].any()


def test_balls_enclosing_lenses_of_inward_looking_facets(path):
    """Facets looking into the head (axes towards the eye's centre) whose lens a ball holds:
    seen through |c - p| <= g alone, whatever the axis; the index must not drop them."""
    hand = hand_eye(9)
    eyes = [
        MeasuredEye(e.positions, -e.axes, e.acceptance, name=e.name)
        for e in (hand.eye_a, hand.eye_b)
    ]
    pair = MeasuredEyePair(*eyes)
    pos = pair.facets("B")[0]
    out = (pos - np.array([1.0, 0.0, 0.0])) / 0.5  # outward unit normals of eye B
    x, y, z, g = [], [], [], []
    for k in range(0, pos.shape[0], 3):
        for off, gg in ((0.3, 0.35), (0.6, 0.7), (1.0, 1.2)):
            c = pos[k] + off * out[k]
            x.append(c[0])
            y.append(c[1])
            z.append(c[2])
            g.append(gg)
    check_against_reference(pair, x, y, z, g)


@pytest.mark.parametrize("name", ["AM_60185-real.eye", "1000-horizontallyAcute-variableDegree.eye"])
def test_tiny_balls(name):
    pair = shipped(name)
    pos, ax, _ = pair.facets("B")
    rng = np.random.default_rng(13)
    x, y, z, g = [], [], [], []
    for i in rng.choice(pos.shape[0], 5, replace=False).tolist():
        u = ax[i] / np.linalg.norm(ax[i])
        for off, gg in ((0.0, 5e-324), (1e-200, 1e-200), (1e-9, 1e-12), (2.0, 1e-9)):
            c = pos[i] + off * u
            x.append(c[0])
            y.append(c[1])
            z.append(c[2])
            g.append(gg)
    check_against_reference(pair, x, y, z, g)
    # a ball centred on a lens is seen by that facet however small
    assert 0 in pair.lit(*pos[0], 5e-324)[1]


@pytest.mark.slow
def test_huge_and_tiny_scales(path):
    """Magnitudes where float64 squares overflow or underflow: the exact path decides."""
    hand = hand_eye(4)
    for k in (-200, 200):
        s = 10.0**k
        eyes = [
            MeasuredEye(e.positions * s, e.axes, e.acceptance, name=e.name)
            for e in (hand.eye_a, hand.eye_b)
        ]
        scaled = MeasuredEyePair(*eyes)
        x, y, z, g = (v * s for v in random_balls(hand, 12, seed=5))
        check_against_reference(scaled, x, y, z, g)
        # the same balls at scale 1: the same lit sets (the rule is scale-free)
        assert (
            all(
                np.array_equal(a[1], b[1])
                for a, b in zip(
                    scaled.lit_csr(x, y, z, g),
                    hand.lit_csr(x / s, y / s, z / s, g / s),
                    strict=True,
                )
            )
            or k == 200
        )  # 1e200 * x / 1e200 need not give x back: equality only at -200
    rng = np.random.default_rng(8)
    eyes = [
        MeasuredEye(
            e.positions,
            e.axes * 10.0 ** rng.choice([-300, -200, 200, 300], (e.n, 1)),
            e.acceptance,
            name=e.name,
        )
        for e in (hand.eye_a, hand.eye_b)
    ]
    extreme_axes = MeasuredEyePair(*eyes)
    balls = random_balls(hand, 20, seed=6)
    check_against_reference(extreme_axes, *balls)
    assert all(
        np.array_equal(a[k], b[k])
        for a, b in zip(extreme_axes.lit_csr(*balls), hand.lit_csr(*balls), strict=True)
        for k in range(2)
    )
    pair = hand
    xs = [1e140, -3e100, 1e200, 0.0, 1e300]
    ys = [2e140, 1e101, 1e200, 1e-300, -1e300]
    zs = [0.0, 5e99, -1e199, 1e300, 1e300]
    gs = [1e139, 1e100, 1e200, 1e299, 1e308]
    check_against_reference(pair, xs, ys, zs, gs)
    big = shipped("AM_60185-real.eye")
    check_against_reference(big, [1e140, 3.0], [2e140, 1e120], [0.0, 0.0], [3e139, 1e119])


# --- the seam's predicates ------------------------------------------------------------------
@pytest.mark.parametrize("name", ["AM_60185-real.eye", "hand"])
def test_predicates_are_consistent_with_lit(name):
    pair = hand_eye(6) if name == "hand" else shipped(name)
    x, y, z, g = random_balls(pair, 40, seed=3)
    r = np.linspace(2, 40, 10) * pair.l  # ahead of the head: the binocular field's side
    x[:10], y[:10], z[:10], g[:10] = 0.0, r, 0.1 * r, 0.1 * r
    x, y, z, g = (v.reshape(5, 8) for v in (x, y, z, g))
    (pa, ia), (pb, ib) = pair.lit_csr(x, y, z, g)
    wa, wb = pair.bitmaps(x, y, z, g)
    assert wa.shape == (5, 8, pair.facet_counts[0]) and wb.shape == (5, 8, pair.facet_counts[1])
    va, vb = pair.visible(x, y, z, g)
    oa, ob = pair.overlaps_eye(x, y, z, g)
    bfv = pair.in_bfv(x, y, z, g)
    for k in range(40):
        r, s = divmod(k, 8)
        la, lb = pair.lit(x[r, s], y[r, s], z[r, s], g[r, s])
        assert np.array_equal(la, ia[pa[k] : pa[k + 1]]) and np.array_equal(
            lb, ib[pb[k] : pb[k + 1]]
        )
        assert np.array_equal(np.flatnonzero(wa[r, s]), la)
        assert np.array_equal(np.flatnonzero(wb[r, s]), lb)
        assert va[r, s] == (la.size >= 2) and vb[r, s] == (lb.size >= 2)
        c = (x[r, s], y[r, s], z[r, s])
        assert oa[r, s] == reference_lens_in_ball(pair.facets("A")[0], c, g[r, s])
        assert ob[r, s] == reference_lens_in_ball(pair.facets("B")[0], c, g[r, s])
        assert bfv[r, s] == (la.size >= 2 and lb.size >= 2 and not oa[r, s] and not ob[r, s])
    assert bfv.any() and not bfv.all()
    assert pa.dtype == np.int64 and ia.dtype == np.int64


def test_index_agrees_with_the_brute_force_pass(path):
    pair = shipped("BT_77973-real.eye")
    balls = pair._flat_balls(*random_balls(pair, 300, seed=9))[1]
    for eye in "AB":
        fast = pair._lit_eye(eye, balls)
        brute = pair._lit_eye(eye, balls, index=False)
        assert np.array_equal(fast[0], brute[0]) and np.array_equal(fast[1], brute[1])


def test_compiled_and_numpy_decisions_agree(monkeypatch):
    """The kernel's (seen, sure) equal the numpy reference's on the same pairs, tangent
    and extreme ones included; both leave the near-ties to the exact path."""
    pair = hand_eye(2)
    tables, _ = pair._prepared("A")
    rng = np.random.default_rng(21)
    pos, ax, acc = pair.facets("A")
    cs = [_tangent_ball(pos[i], ax[i], float(acc[i]), rng) for i in range(pos.shape[0])]
    # graded near-ties: tangent balls grown and shrunk by 2^-52 .. 2^-40, where the
    # certificate's bound (its scale: |v| |a|) decides which pairs are sure
    k = np.ldexp(1.0, np.arange(-52, -39))
    cs += [(c, d * (1 + s * e)) for c, d in cs[:8] for e in k for s in (-1, 1)]
    x, y, z, g = random_balls(pair, 300, seed=4)
    x = np.concatenate([x, [c[0] for c, _ in cs], [1e200, 1e-300, pos[0, 0]]])
    y = np.concatenate([y, [c[1] for c, _ in cs], [0.0, 0.0, pos[0, 1]]])
    z = np.concatenate([z, [c[2] for c, _ in cs], [0.0, 0.0, pos[0, 2]]])
    g = np.concatenate([g, [d for _, d in cs], [1e199, 1e-300, 1e-300]])
    balls = (x, y, z, g)
    bi = np.repeat(np.arange(x.size), pos.shape[0])
    fi = np.tile(np.arange(pos.shape[0]), x.size)
    seen_k, sure_k = measured_fast._certified_jit(tables, balls, bi, fi)
    with np.errstate(all="ignore"):
        seen_n, sure_n = measured_fast._certified(tables, x[bi], y[bi], z[bi], g[bi], fi)
    assert np.array_equal(sure_k, sure_n)
    assert np.array_equal(seen_k[sure_k], seen_n[sure_n])
    assert 0 < (~sure_k).sum() < bi.size // 10


def _near_tie_balls(p, a, acc, rng):
    """Balls packed about two near-ties of facet (p, a, acc), every offset a multiple of
    2^-52 of the distance r: the lens on the ball's sphere (c behind the lens, g = r (1 + j
    2^-52)), and the apex corner (c at r from the cone's edge line, its foot moved along
    the line by i 2^-52 r, g = r (1 + j 2^-52)), where the lens test's margin and both edge
    margins decide which pairs are sure."""
    u = np.asarray(a, dtype=np.float64) / np.linalg.norm(a)
    w = np.cross(u, rng.normal(size=3))
    w /= np.linalg.norm(w)
    half = float(acc) / 2
    t = math.cos(half) * u + math.sin(half) * w  # the cone's edge line
    n = -math.sin(half) * u + math.cos(half) * w  # outward, normal to it
    r = rng.uniform(0.5, 20)
    k = np.ldexp(np.arange(-48.0, 49.0), -52)
    behind = p - r * u
    cs = [(behind, r * (1 + j)) for j in k]
    cs += [(p + r * n + i * r * t, r * (1 + j)) for i in k for j in k[::4]]
    return cs


def test_compiled_and_numpy_margins_agree_on_dense_near_ties():
    """The kernel's rounding margins are the reference's to the bit: on balls packed
    about the lens and apex near-ties (offsets 2^-52 apart) both leave the same pairs
    to the exact path and agree on the rest (halving any one margin of ``_certify``
    moves some pair across)."""
    pair = hand_eye(3)
    tables, _ = pair._prepared("A")
    rng = np.random.default_rng(33)
    pos, ax, acc = pair.facets("A")
    xs, ys, zs, gs, fs = [], [], [], [], []
    for i in rng.choice(pos.shape[0], 4, replace=False).tolist():
        for c, g in _near_tie_balls(pos[i], ax[i], acc[i], rng):
            xs.append(c[0])
            ys.append(c[1])
            zs.append(c[2])
            gs.append(g)
            fs.append(i)
    x, y, z, g = (np.array(v, dtype=np.float64) for v in (xs, ys, zs, gs))
    fi = np.array(fs, dtype=np.int64)
    bi = np.arange(x.size, dtype=np.int64)
    seen_k, sure_k = measured_fast._certified_jit(tables, (x, y, z, g), bi, fi)
    with np.errstate(all="ignore"):
        seen_n, sure_n = measured_fast._certified(tables, x, y, z, g, fi)
    assert np.array_equal(sure_k, sure_n)
    assert np.array_equal(seen_k[sure_k], seen_n[sure_n])
    # both kinds of answer and the undecided band are all present
    assert seen_k[sure_k].any() and not seen_k[sure_k].all()
    assert 0 < (~sure_k).sum() < bi.size


def test_an_axis_the_scaling_would_round_is_decided_exactly(path):
    """An axis whose components are 2^1080 apart cannot be scaled to [1, 2) exactly: its
    facet skips the fast path and goes to the exact one, and the answer stays right."""
    ax = np.array([[2.0**1000, 3 * 2.0**-80, 0.0], [0.0, 1.0, 0.0]])
    eye = MeasuredEye(np.zeros((2, 3)), ax, [0.5, 0.5], name="A")
    pair = MeasuredEyePair(eye, MeasuredEye(np.ones((1, 3)), [[0.0, 1.0, 0.0]], [0.5], name="B"))
    assert measured_fast.eye_tables(
        eye.positions, eye.axes, eye.acceptance
    ).exact_only.tolist() == [True, False]
    before = measured_fast.FALLBACK_COUNTS["exact"]
    check_against_reference(
        pair, [10.0, 10.0, -3.0], [2.6, 0.0, 0.0], [0.0, 1.0, 0.0], [0.1, 0.1, 1.0]
    )
    assert measured_fast.FALLBACK_COUNTS["exact"] >= before + 2


def test_exact_path_decides_what_the_fast_path_leaves():
    pair = shipped("AM_60185-real.eye")
    rng = np.random.default_rng(17)
    pos, ax, acc = pair.facets("A")
    before = measured_fast.FALLBACK_COUNTS["exact"]
    c, g0 = _tangent_ball(pos[5], ax[5], float(acc[5]), rng)
    pair.lit(*c, g0)
    assert measured_fast.FALLBACK_COUNTS["exact"] > before
    assert seen_exact(c, np.nextafter(g0, np.inf), pos[5], ax[5], float(acc[5]))
    assert not seen_exact(c, np.nextafter(g0, 0.0), pos[5], ax[5], float(acc[5]))


# --- validation --------------------------------------------------------------------------
def _eye(**kw):
    args = {"positions": np.zeros((2, 3)), "axes": np.ones((2, 3)), "acceptance": [0.1, 0.2]}
    args.update(kw)
    return MeasuredEye(**args)


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"positions": [[0, 0, 0], [np.nan, 0, 0]]}, "ommatidium 1: lens position is not finite"),
        ({"axes": [[1, 0, 0], [0, 0, 0]]}, "ommatidium 1: axis is zero"),
        ({"axes": [[1, 0, np.inf], [0, 1, 0]]}, "ommatidium 0: axis is not finite"),
        ({"acceptance": [0.0, 0.1]}, "ommatidium 0: acceptance angle must be in (0, pi)"),
        ({"acceptance": [0.1, math.pi]}, "ommatidium 1: acceptance angle must be in (0, pi)"),
        ({"acceptance": [0.1, -1.0]}, "ommatidium 1: acceptance angle must be in (0, pi)"),
        ({"acceptance": [0.1]}, "acceptance angles must have shape (2,)"),
    ],
)
def test_eye_validation_one_line(kw, message):
    with pytest.raises(EyevizError) as err:
        _eye(**kw)
    assert message in str(err.value) and "\n" not in str(err.value)


@pytest.mark.parametrize(
    ("ball", "message"),
    [
        ((np.nan, 0.0, 0.0, 1.0), "x has 1 non-finite"),
        ((0.0, 0.0, 0.0, 0.0), "g (feature radius) must be > 0"),
        ((0.0, 0.0, 0.0, -1.0), "g (feature radius) must be > 0"),
        ((0.0, np.inf, 0.0, 1.0), "y has 1 non-finite"),
    ],
)
def test_ball_validation_one_line(ball, message):
    pair = hand_eye(0, n=4)
    for call in (pair.lit_csr, pair.lit, pair.overlaps_eye, pair.in_bfv):
        with pytest.raises(ValueError) as err:
            call(*ball)
        assert message in str(err.value) and "\n" not in str(err.value)


def test_h_l_and_centres_are_the_lens_centroids_half_distance_and_reach():
    """h is half the distance of the two lens centroids (not of their sum: both lie off
    the x axis here), l the largest lens distance from its eye's centroid."""
    a = MeasuredEye([[-3.0, 4.0, 1.0], [-1.0, 4.0, 1.0]], [[0, 1, 0]] * 2, [0.2, 0.2])
    b = MeasuredEye([[1.0, 5.0, 1.0], [3.0, 5.0, 1.0], [2.0, 2.0, 1.0]], [[0, 1, 0]] * 3, [0.2] * 3)
    pair = MeasuredEyePair(a, b)
    assert pair.centers == ((-2.0, 4.0, 1.0), (2.0, 4.0, 1.0))
    assert pair.h == 2.0 and pair.l == 2.0  # b's third lens is 2 from its centroid (2, 4, 1)


def test_the_exact_signs_error_scale_bounds_the_terms(monkeypatch):
    """_sign's ``scale`` must bound the sum of the terms' absolute values (its docstring),
    or a sign is certified at a precision that cannot tell it: for each edge test of
    seen_exact, scale >= |fun(1, 0)| + |fun(0, 1)| (the C terms, the S terms)."""
    from eyeviz.core import measured_exact

    calls = []
    real = measured_exact._sign

    def checked(fun, scale, half_dr):
        with mpmath.workprec(200):  # the slack of the scale over the terms, relative
            terms = abs(fun(1, 0)) + abs(fun(0, 1))
            calls.append(float((scale() - terms) / terms))
        return real(fun, scale, half_dr)

    monkeypatch.setattr(measured_exact, "_sign", checked)
    rng = np.random.default_rng(3)
    for _ in range(40):  # balls behind and in front of a lens looking along +y
        c = rng.normal(size=3) * 5
        seen_exact(c.tolist(), float(rng.uniform(0.1, 2)), [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.4)
    assert len(calls) > 40
    assert min(calls) > -1e-50  # 200-bit rounding only
