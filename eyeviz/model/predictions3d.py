"""The predictions layer of the 3D view (issue 23 item 4, docs/spherical.md): each chosen
estimator's answer for one ball of a spherical scene, as the VTK view, the vector figure
and the readout draw it. No Qt, no VTK, no matplotlib.

**Which ball.** The layer answers for one ball: the selected one in the app (a scene opens
with its first ball selected), the first ball in ``eyeviz snapshot`` (a scene file keeps
no selection). The limit costs tens of milliseconds a key and its posterior cloud as much
again; three ghosts and a cloud per ball would also bury a scene of several balls.

**What an answer is.** The estimators of the spherical eyes (``kind="spherical"`` in
:mod:`eyeviz.estimators.registry`: analytic3d, learned3d, limit3d) take the ball's two lit
sets (the 3D Proposition 2) and answer ``(r, azimuth, elevation)`` about the origin midway
between the eyes; the ghost is a ball of the true radius g at that answer's centre
(:func:`eyeviz.dataset.records.spherical_to_xyz`: x = r cos el cos az, y = r cos el
sin az, z = r sin el). The errors are against the true ball: r relative (in %), azimuth
(wrapped to (-180, 180]) and elevation absolute, in degrees. Every estimator is loaded for
the scene's design (h, l, nside) with Table 4's ranges of r and g and the elevation band
of :class:`eyeviz.core.domain.Domain3D`; learned3d's weights answer only for the design
they were trained for, and for other eyes its answer is the registry's one line (never an
answer for the wrong eyes).

**The domain.** As in the planar layer, a ball is answered only when it is in the 3D
binocular field and visible to both eyes (Definition 1: at least two facets lit); a ball
outside Table 4's ranges is answered with a note (the limit's prior has no mass there:
it falls back to analytic3d and flags the answer).

**Staleness** (:class:`LatestOnly`). The fast estimators answer on every drag frame; the
limit and its posterior run off the GUI thread when a drag ends (the app's job runner,
one job at a time). A result is shown only if its key (the design and the two lit sets)
is still the one wanted when it arrives: a result for a ball that has moved since is kept
in the cache but never drawn over a newer answer.

**Why apart from** :mod:`eyeviz.model.predictor` (issue 37.2 keeps the two): the planar
layer asks every estimator for every feature's bitmaps at each frame, against designs
(h, l, m) an estimator may or may not be trained for; this one answers one ball's lit
sets in space with (r, azimuth, elevation), runs the limit and its posterior cloud off the
GUI thread keyed by the lit sets, and shows only the latest. The answers, their errors
and their staleness differ, not just the eye model.
"""

from __future__ import annotations

import hashlib
import math
import re
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from eyeviz.core.domain import Domain3D
from eyeviz.model.palette import estimator_color
from eyeviz.model.scene import SPHERICAL_ESTIMATORS, Scene
from eyeviz.model.state3d import SceneState3D

__all__ = [
    "DEFAULT_ESTIMATORS3D",
    "LIMIT",
    "MAX_CLOUD",
    "SLOW",
    "Answer3D",
    "Cloud",
    "LatestOnly",
    "Predictions3D",
    "Predictor3D",
    "answer_from",
    "ball_key",
    "check_estimators",
    "cloud_of",
    "domain_of",
    "errors3d",
    "estimator_color3d",
    "estimators3d",
    "in_domain",
    "outside_reason",
    "prediction_rows",
    "range_note",
    "scene_predictions3d",
]

#: The estimators a spherical scene shows when its file names none of the spherical ones
#: (a scene's ``[predictions] estimators`` defaults to the planar ``compact``).
DEFAULT_ESTIMATORS3D = SPHERICAL_ESTIMATORS
LIMIT = "limit3d"
#: Estimators too slow for a drag frame: answered off the GUI thread, after a drag.
SLOW = frozenset({LIMIT})
#: At most this many posterior samples are drawn (the heaviest).
MAX_CLOUD = 2000
#: Each spherical estimator takes the colour of its planar counterpart (fixed by name,
#: :mod:`eyeviz.model.palette`; learned3d is the learned network, as compact is).
_TWIN = {"analytic3d": "analytic", "limit3d": "limit", "learned3d": "compact"}


def estimator_color3d(name: str) -> str:
    """The fixed colour of spherical estimator ``name`` (its planar twin's)."""
    return estimator_color(_TWIN.get(name, name))


def _spherical_names() -> list[str]:
    from eyeviz.estimators import registry

    return registry.available("spherical")


def estimators3d(scene: Scene, known: list[str] | None = None) -> list[str]:
    """The scene's spherical estimators, in the scene's order (``[predictions]
    estimators``, the key the planar layer uses); :data:`DEFAULT_ESTIMATORS3D` (those
    installed) when it names none of them. ``known``: the registry's spherical names."""
    names = _spherical_names() if known is None else list(known)
    chosen = list(dict.fromkeys(n for n in scene.estimators if n in names))  # once each
    return chosen if chosen else [n for n in DEFAULT_ESTIMATORS3D if n in names]


def check_estimators(scene: Scene) -> None:
    """EyevizError (one line) when ``scene`` shows predictions and its ``[predictions]
    estimators`` names an estimator the registry does not know at all (a typo: drawing
    the defaults instead would hide it), or one of the planar eyes (issue 36: ``compact``
    silently drew the three spherical ones). A scene file naming none gets
    :data:`~eyeviz.model.scene.SPHERICAL_ESTIMATORS` when it is read."""
    if not scene.shows("predictions"):
        return
    from eyeviz import EyevizError
    from eyeviz.estimators import registry

    known = set(registry.available(None))
    spherical = registry.available("spherical")
    for name in scene.estimators:
        shown = name if len(name) <= 40 else name[:39] + "\u2026"
        if name not in known:
            raise EyevizError(
                f"predictions.estimators: unknown estimator {shown!r}; available: "
                f"{', '.join(registry.available(None))}"
            )
        if name not in spherical:
            raise EyevizError(
                f"predictions.estimators: {shown!r} is an estimator of the planar eyes; a "
                f"spherical scene's are {', '.join(spherical)}"
            )


#: A local path in an estimator's reason (a weights folder under the user's home): the
#: readout and the exported figure show its last component only.
_PATH = re.compile(r"(?<![~\w.])(?:[A-Za-z]:)?(?:[\\/][^\s\\/:'\"()\[\],]+){2,}[\\/]?")


def _no_paths(text: str) -> str:
    """``text`` with each local path reduced to its file name (in quotes)."""
    return _PATH.sub(
        lambda m: "\u2018" + re.split(r"[\\/]", m.group(0).rstrip("\\/"))[-1] + "\u2019", text
    )


def domain_of(scene: Scene) -> Domain3D:
    """The estimators' domain: the scene's eyes (h, l, nside), Table 4's ranges."""
    e = scene.eyes
    assert e.nside is not None, "a spherical scene has an nside"
    return Domain3D(h=float(e.h), l=float(e.l), nside=int(e.nside))


def in_domain(state: SceneState3D, i: int) -> bool:
    """Ball ``i`` is in the 3D binocular field and visible to both eyes (Definition 1)."""
    if state.in_bfv is None or state.vis_a is None or state.vis_b is None:
        raise ValueError("this state has no BFV or visibility (no layer needed them)")
    return bool(state.in_bfv[i] and state.vis_a[i] and state.vis_b[i])


def outside_reason(state: SceneState3D, i: int) -> str:
    """Why ball ``i`` is outside the domain, in one short line (the readout's cell, the
    figure's table): not in the 3D binocular field, and each eye on which it lights
    fewer facets than Definition 1's two."""
    parts = []
    if state.in_bfv is not None and not state.in_bfv[i]:
        parts.append("not in the 3D binocular field")
    for eye, n in (("A", state.facets_a), ("B", state.facets_b)):
        k = int(n[i]) if n is not None else 2
        if k < 2:
            parts.append(f"eye {eye}: {'1 facet' if k == 1 else 'no facet'} lit (needs 2)")
    return "; ".join(parts) if parts else "not seen by both eyes"


def range_note(domain: Domain3D, state: SceneState3D, i: int) -> str | None:
    """Why ball ``i`` lies outside the domain's ranges (r, g, elevation), or None."""
    r, g, el = float(state.r[i]), float(state.g[i]), float(state.elevation[i])
    out = []
    if not domain.r_min <= r <= domain.r_max:
        out.append(f"r outside [{domain.r_min:g}, {domain.r_max:g}]")
    if g > domain.g_max:
        out.append(f"g > {domain.g_max:g}")
    if abs(el) > domain.el_max:
        out.append(f"|el| > {math.degrees(domain.el_max):g}°")
    return "outside Table 4's ranges: " + ", ".join(out) if out else None


def ball_key(state: SceneState3D, i: int) -> bytes:
    """What an estimator's answer for ball ``i`` depends on: the design and the ball's
    two lit sets (a digest)."""
    pair = state.healpix
    h = hashlib.blake2b(digest_size=16)
    h.update(np.array([pair.h, pair.l, pair.nside], np.float64).tobytes())
    for eye in "AB":
        lit = np.ascontiguousarray(state.lit(i, eye), dtype=np.int64)
        h.update(np.int64(lit.size).tobytes())
        h.update(lit.tobytes())
    return h.digest()


@dataclass(frozen=True)
class Answer3D:
    """One estimator's answer for one ball: the centre and its errors against the truth.

    ``x, y, z`` come from (r, azimuth, elevation) by :func:`spherical_to_xyz`; ``dr_pct``
    is 100 (r_hat - r) / r, ``daz`` and ``del_`` are degrees (azimuth wrapped to
    (-180, 180]). ``mc_error`` is the limit's relative Monte-Carlo error of r (NaN for
    the others; undefined from fewer than two accepted draws, ``n_accepted``); ``valid``
    False when an eye lit nothing (NaN answers)."""

    name: str
    r: float
    azimuth: float
    elevation: float
    x: float
    y: float
    z: float
    valid: bool
    flagged: bool
    mc_error: float = math.nan
    n_accepted: int = -1  # the limit's accepted posterior draws (-1: not the limit)
    dr_pct: float = math.nan
    daz: float = math.nan
    del_: float = math.nan


def errors3d(
    truth: tuple[float, float, float], answer: tuple[float, float, float]
) -> tuple[float, float, float]:
    """(relative error of r in %, azimuth error in degrees wrapped to (-180, 180],
    elevation error in degrees) of ``answer`` (r, az, el) against ``truth``."""
    r, az, el = truth
    rh, ah, eh = answer
    return (
        100.0 * (rh - r) / r,
        math.degrees(math.remainder(ah - az, 2.0 * math.pi)),
        math.degrees(eh - el),
    )


def answer_from(name: str, p: Any, truth: tuple[float, float, float]) -> Answer3D:
    """An :class:`Answer3D` from a one-row :class:`~eyeviz.estimators.base.Prediction3D`
    ``p`` (arrays of length 1 or scalars) for a ball at ``truth`` = (r, az, el)."""

    def one(v) -> float:
        return float(np.asarray(v, dtype=np.float64).reshape(-1)[0])

    r, az, el = one(p[0]), one(p[1]), one(p[2])
    valid = bool(np.asarray(p.valid).reshape(-1)[0]) and math.isfinite(r)
    flagged = bool(np.asarray(p.flagged).reshape(-1)[0])
    mc = one(p.mc_error) if hasattr(p, "mc_error") else math.nan
    acc = int(one(p.n_accepted)) if hasattr(p, "n_accepted") else -1
    if not valid:
        nan = math.nan
        return Answer3D(name, nan, nan, nan, nan, nan, nan, False, flagged, mc, acc)
    # here: the package eyeviz.dataset (sparse files, Algorithm 1) is not a start's cost
    from eyeviz.dataset.records import spherical_to_xyz

    xyz = spherical_to_xyz(np.array([r]), np.array([az]), np.array([el]))
    x, y, z = (float(v[0]) for v in xyz)
    dr, daz, de = errors3d(truth, (r, az, el))
    return Answer3D(name, r, az, el, x, y, z, True, flagged, mc, acc, dr, daz, de)


@dataclass(frozen=True)
class Cloud:
    """The limit's posterior for one key, as drawn: (k, 3) ball centres and an opacity
    per point in (0, 1] (the weight over the largest weight), at most MAX_CLOUD."""

    points: np.ndarray
    alpha: np.ndarray
    n_samples: int  # samples before the cap


def cloud_of(samples: dict[str, np.ndarray], cap: int = MAX_CLOUD) -> Cloud:
    """The drawn cloud of :func:`eyeviz.estimators.limit3d.posterior_samples3d`'s samples:
    the ``cap`` heaviest, each as opaque as its weight over the heaviest's (at least 0.15,
    so a light sample still shows)."""
    w = np.asarray(samples.get("weight", np.zeros(0)), np.float64)
    pts = np.column_stack(
        [np.asarray(samples.get(k, np.zeros(0)), np.float64) for k in ("x", "y", "z")]
    ).reshape(-1, 3)
    n = int(w.size)
    if n > cap:
        keep = np.argsort(-w, kind="stable")[:cap]
        w, pts = w[keep], pts[keep]
    top = float(w.max()) if w.size else 0.0
    alpha = 0.15 + 0.85 * (w / top) if top > 0 else np.ones_like(w)
    return Cloud(pts, alpha, n)


@dataclass
class Predictions3D:
    """The layer's content for one ball: per estimator an :class:`Answer3D` or a one-line
    reason (unavailable, outside the domain, waiting for the limit), the limit's cloud."""

    ball: int
    g: float
    truth: tuple[float, float, float]  # (x, y, z) of the true centre
    answers: dict[str, Answer3D | str] = field(default_factory=dict)
    cloud: Cloud | None = None
    note: str | None = None  # a range note for the whole ball

    def ghosts(self) -> list[Answer3D]:
        """The valid answers, in the estimators' order (what the views draw)."""
        return [a for a in self.answers.values() if isinstance(a, Answer3D) and a.valid]


class Predictor3D:
    """Loads each spherical estimator once per design and caches answers by key.

    ``answer(name, state, i)`` is a cached one-row prediction; ``limit_job(state, i)``
    returns the function a worker runs for the limit (the prediction and the posterior
    cloud), and ``store_limit(key, result)`` keeps what it returned."""

    CACHE_MAX = 256  # keys per estimator

    def __init__(self) -> None:
        self._est: dict[tuple[str, tuple], object] = {}
        self._cache: dict[str, OrderedDict[bytes, Any]] = {}

    def estimator(self, name: str, domain: Domain3D):
        """The estimator for ``domain``, or a one-line reason it is unavailable."""
        key = (name, (domain.h, domain.l, domain.nside))
        if key not in self._est:
            from eyeviz.estimators import registry

            try:
                self._est[key] = registry.load(name, domain=domain)
            except Exception as exc:  # noqa: BLE001  (shown as a line, never raised)
                text = str(exc).strip().splitlines()[0] if str(exc).strip() else repr(exc)
                self._est[key] = f"unavailable: {_no_paths(text)}"
        return self._est[key]

    def cached(self, name: str, key: bytes):
        """The cached answer of ``name`` for ``key``, or None."""
        c = self._cache.get(name)
        return None if c is None else c.get(key)

    def _keep(self, name: str, key: bytes, value) -> None:
        c = self._cache.setdefault(name, OrderedDict())
        c[key] = value
        c.move_to_end(key)
        while len(c) > self.CACHE_MAX:
            c.popitem(last=False)

    def answer(self, name: str, domain: Domain3D, state: SceneState3D, i: int, key: bytes):
        """The Prediction3D of ``name`` for ball ``i`` (cached by ``key``), or a reason."""
        hit = self.cached(name, key)
        if hit is not None:
            return hit
        est = self.estimator(name, domain)
        if isinstance(est, str):
            return est
        lit_a, lit_b = _one_row(state, i)
        try:
            p = est.predict(lit_a, lit_b)
        except (ValueError, RuntimeError) as exc:
            return f"cannot answer: {str(exc).splitlines()[0]}"
        self._keep(name, key, p)
        return p

    def limit_job(
        self, domain: Domain3D, state: SceneState3D, i: int
    ) -> Callable[[], tuple[Any, Cloud | None]] | str:
        """A function computing the limit's (Prediction3D, Cloud) for ball ``i`` on a
        worker: it holds copies of the lit sets, never the live state. A str when the
        limit is unavailable."""
        est = self.estimator(LIMIT, domain)
        if isinstance(est, str):
            return est
        lit_a, lit_b = _one_row(state, i)

        def work() -> tuple[Any, Cloud | None]:
            from eyeviz.estimators.limit3d import posterior_samples3d

            p = est.predict(lit_a, lit_b)
            samples = posterior_samples3d(est, lit_a[1], lit_b[1])
            return p, cloud_of(samples)

        return work

    def store_limit(self, key: bytes, result: tuple[Any, Cloud | None]) -> None:
        self._keep(LIMIT, key, result)


def _one_row(state: SceneState3D, i: int):
    """Ball ``i``'s lit sets as one-row CSR pairs (copies)."""
    out = []
    for eye in "AB":
        lit = np.array(state.lit(i, eye), dtype=np.int64)
        out.append((np.array([0, lit.size], np.int64), lit))
    return out[0], out[1]


class LatestOnly:
    """The staleness rule: one job at a time, and only the newest wanted key's result is
    shown.

    ``want(key)`` says which key the view needs now (None: nothing; the caller asks only
    for keys whose result it lacks); it returns True when a job for it should start now
    (none is running). ``finish(key)`` is called when a job for ``key`` returns: it says
    whether the result is for the key wanted now (shown) or stale (kept, not shown).
    ``start_pending()`` then gives the key wanted meanwhile, if any, and marks it
    running."""

    def __init__(self) -> None:
        self.wanted: bytes | None = None
        self.running: bytes | None = None
        self.last: bytes | None = None  # the key of the last job that returned

    def want(self, key: bytes | None) -> bool:
        self.wanted = key
        if key is None or self.running is not None:
            return False
        self.running = key
        return True

    def finish(self, key: bytes) -> bool:
        """The job for ``key`` returned: True if its result is for the key wanted now."""
        self.last = key
        if self.running == key:
            self.running = None
        return key == self.wanted

    def start_pending(self) -> bytes | None:
        """The key wanted while a job ran (not the one that just returned), now running."""
        k = self.wanted
        if k is None or self.running is not None or k == self.last:
            return None
        self.running = k
        return k

    def forget(self) -> None:
        """After a failure or a job not started: nothing runs."""
        self.running = None


def scene_predictions3d(
    scene: Scene,
    state: SceneState3D,
    ball: int | None,
    predictor: Predictor3D,
    *,
    limit: str = "now",
    names: list[str] | None = None,
) -> Predictions3D | None:
    """The layer's content for ``ball`` (None, or a scene without balls: None).

    ``limit``: ``"now"`` runs the limit here (the export, a worker); ``"cached"`` takes it
    from the predictor's cache or answers "computing…" (a drag frame; the app starts the
    job), ``"drag"`` answers "after the drag" unless cached."""
    if ball is None or not 0 <= ball < state.n or state.lit_a is None:
        return None
    if names is None:
        check_estimators(scene)
        names = estimators3d(scene)
    domain = domain_of(scene)
    i = ball
    truth_sph = (float(state.r[i]), float(state.azimuth[i]), float(state.elevation[i]))
    out = Predictions3D(
        i,
        float(state.g[i]),
        (float(state.x[i]), float(state.y[i]), float(state.z[i])),
    )
    if not in_domain(state, i):
        for n in names:
            out.answers[n] = outside_reason(state, i)
        return out
    out.note = range_note(domain, state, i)
    key = ball_key(state, i)
    for n in names:
        if n == LIMIT:
            res = predictor.cached(LIMIT, key)
            if res is None and limit == "now":
                job = predictor.limit_job(domain, state, i)
                if isinstance(job, str):
                    out.answers[n] = job
                    continue
                res = job()
                predictor.store_limit(key, res)
            if res is None:
                out.answers[n] = "computing…" if limit == "cached" else "after the drag"
                continue
            p, cloud = res
            out.answers[n] = answer_from(n, p, truth_sph)
            out.cloud = cloud
            continue
        p = predictor.answer(n, domain, state, i, key)
        out.answers[n] = p if isinstance(p, str) else answer_from(n, p, truth_sph)
    return out


def prediction_rows(preds: Predictions3D | None) -> list[tuple[str, ...]]:
    """The readout's rows (strings): estimator, r, Δr %, az°, Δaz°, el°, Δel°, note
    (the limit's Monte-Carlo error, "flagged", "no answer", or the reason there is none).
    The app's readout and the exported figure's table show these."""
    if preds is None:
        return []
    rows: list[tuple[str, ...]] = []
    for name, a in preds.answers.items():
        if isinstance(a, str):
            rows.append((name, "", "", "", "", "", "", a))
            continue
        if not a.valid:
            rows.append((name, "", "", "", "", "", "", "no answer: an eye lit nothing"))
            continue
        notes = []
        if 0 <= a.n_accepted < 2 and not a.flagged:  # one draw: no error to estimate
            notes.append(f"{a.n_accepted} draw: MC n/a")
        elif math.isfinite(a.mc_error):
            notes.append(f"MC ±{100.0 * a.mc_error:.2g} %")
        if a.flagged:
            notes.append("⚑ flagged")  # answered by a fallback (analytic3d for the limit)
        rows.append(
            (
                name,
                f"{a.r:.0f}" if abs(a.r) >= 100 else f"{a.r:.1f}",
                f"{a.dr_pct:+.2f}",
                f"{math.degrees(a.azimuth):.2f}",
                f"{a.daz:+.3f}",
                f"{math.degrees(a.elevation):.2f}",
                f"{a.del_:+.3f}",
                "; ".join(notes),
            )
        )
    return rows
