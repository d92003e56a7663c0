"""The learned estimator of the spherical eyes: a small network on summaries of the lit sets.

Each eye's lit set is summarised in one vectorised pass over its CSR row
(:mod:`eyeviz.estimators.learned3d_features`): the solid-angle-weighted mean direction of
the lit facets, the cap's angular radius from the facet count, the west and east edge
longitudes, the z-extent and bounds on the cap centre's longitude from every ring's run
ends (a set-membership cue: each ring pins the centre to a cell, many rings to a
fraction of one). The two mean directions are triangulated (the closest
approach of the rays from A and B, docs/spherical.md) and one multilayer perceptron
(SiLU, two hidden layers) corrects the triangulation, as the planar compact networks do
(:mod:`eyeviz.estimators.compact`):

- log r = log r0 + f_0(x): trained on the relative error |r_hat / r - 1| (the MAPE of
  Eq. 34), so it learns the 1/r-weighted posterior median;
- azimuth = azimuth0 + 1e-4 f_1(x), trained on |az_hat / az - 1|;
- elevation = elevation0 + 1e-4 f_2(x), trained on |el_hat - el| (an elevation crosses 0,
  where a relative error is undefined).

The last layer starts at zero, so training starts from the triangulation.

Why summaries and not a spherical convolution on the HEALPix grid (DeepSphere): one
convolution layer over both eyes' 2 x 388,800 facets at nside 180 with 8 channels and
9-cell neighbourhoods is about 5.6e7 multiply-adds per row, some 10^3 times this
network's 2.1e4, which rules out 10^5 rows/s on a CPU; and the information is in the
cap's boundary, which the summaries read exactly. Measured at nside 180 (single pass,
the shipped weights, a fresh 10^5-row test set, seed 31337; ± the bootstrap standard error
over the rows, ``eyeviz report estimators --nside 180 --n-test 100000 --seed 31337``): DD
MAPE 0.9647 ± 0.0045 % against the triangulation's 1.4916 ± 0.0057 %, AD MAPE 0.007864 ±
0.000043 % (0.013167 ± 0.000057 %), elevation mean absolute error 0.007618 ± 0.000026
degrees (0.010823 ± 0.000031). A network on the summaries without the per-ring bounds
did little better than the triangulation in the design's single run (its error not
recorded).

Weights: ``assets/models/learned3d/learned3d.npz``, plain arrays read without unpickling
by :class:`eyeviz.files.npz.NpzReader` (every shape checked against the declared widths
before anything is built), with ``learned3d.json`` (the design the weights were trained
for, the training and validation seeds, metrics, time, command). Inference is numpy
(float32 matrix products), so loading and predicting need no torch; training does
(:mod:`eyeviz.estimators.learned3d_training`). ``predict`` checks the indices on the runs
the summaries find (one pass over them, not two) and, on two cores or more, summarises
the two eyes in two threads (``threads``); ``scripts/bench_learned3d.py`` times it.
"""

from __future__ import annotations

import json
import math
import os
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from eyeviz import EyevizError
from eyeviz.core.domain import Domain3D
from eyeviz.core.validation import check_int, num
from eyeviz.estimators.base import Estimator3D, LitCSR, Prediction3D
from eyeviz.estimators.learned3d_features import (
    N_FEATURES,
    EyeSummary,
    eye_summaries,
    features,
)
from eyeviz.files import limits
from eyeviz.files.atomic import atomic_output
from eyeviz.files.npz import NpzReader, one_line
from eyeviz.resources import models_dir

__all__ = [
    "AZ_SCALE",
    "EL_SCALE",
    "FORMAT",
    "META_FILE",
    "WEIGHTS_FILE",
    "Learned3DEstimator",
    "Prediction3D",
    "default_dir",
    "load",
    "read_weights",
    "write_weights",
]

FORMAT = "eyeviz.learned3d"
VERSION = 1
WEIGHTS_FILE = "learned3d.npz"
META_FILE = "learned3d.json"
#: radians per unit of the network's azimuth and elevation outputs
AZ_SCALE = 1e-4
EL_SCALE = 1e-4
N_OUT = 3
#: rows per batch through the network (keeps the temporaries in cache; the batches of
#: predict are those of its former blocks of 16,384 rows)
_BLOCK = 1 << 14
#: blocks of at most this many rows are summarised in one thread
_THREAD_ROWS = 1024
_LAYERS = ("0", "2", "4")  # Linear layers of nn.Sequential(Linear, SiLU, Linear, SiLU, Linear)
#: How far past the trained ranges an answer may lie and still be the trained network's
#: (a fraction of r_min, r_max, el_max and pi): on 2,000 test rows at nside 180 the shipped
#: weights answer within 1.1 % past r_max and 0.07 % below r_min, |el| <= el_max. A row
#: answered beyond it is outside the training domain (balls over the poles: r = 1.97e38,
#: el = 2.74 rad, issue 35): flagged, and answered by the triangulation where that lies
#: inside, else NaN (:func:`inside_domain`).
DOMAIN_SLACK = 0.1


def default_dir() -> Path:
    return models_dir() / "learned3d"


def expected_shapes(hidden: int) -> dict[str, tuple[int, ...]]:
    """Member name -> shape of the weights of a network of width ``hidden``."""
    return {
        "x_mean": (N_FEATURES,),
        "x_scale": (N_FEATURES,),
        "net.0.weight": (hidden, N_FEATURES),
        "net.0.bias": (hidden,),
        "net.2.weight": (hidden, hidden),
        "net.2.bias": (hidden,),
        "net.4.weight": (N_OUT, hidden),
        "net.4.bias": (N_OUT,),
    }


def write_weights(path: str | os.PathLike, hidden: int, arrays: dict[str, np.ndarray]) -> None:
    """The weights as an uncompressed NPZ of float32 arrays plus ``hidden`` (int64),
    written atomically. ``arrays`` must have exactly :func:`expected_shapes`."""
    want = expected_shapes(hidden)
    if set(arrays) != set(want):
        raise ValueError(f"weights need {sorted(want)}, got {sorted(arrays)}")
    out = {k: np.ascontiguousarray(arrays[k], np.float32) for k in want}
    for k, shape in want.items():
        if out[k].shape != shape:
            raise ValueError(f"{k} has shape {out[k].shape}, expected {shape}")
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(p) as tmp, open(tmp, "wb") as f:
        members: dict[str, np.ndarray] = {"hidden": np.array(hidden, np.int64), **out}
        np.savez(f, allow_pickle=False, **members)


def read_weights(path: str | os.PathLike) -> tuple[int, dict[str, np.ndarray]]:
    """(hidden, arrays) from a weights file, every problem one EyevizError line naming the
    file: a bounded regular file, an NPZ read without unpickling, ``hidden`` an integer in
    [1, MAX_HIDDEN], exactly the members of :func:`expected_shapes` with those shapes,
    float32 and finite."""
    p = Path(path)
    limits.check_file_size(p, limits.MAX_MODEL_FILE_BYTES, "learned3d weights file")
    what = f"{str(p)!r}"
    with NpzReader(p, what) as z:
        h = z.read_member("hidden", 1, ("int64",), ndim=0)
        hidden = limits.check_hidden(p.name, int(h))
        want = expected_shapes(hidden)
        extra = sorted(set(z.names) - set(want) - {"hidden"})
        if extra:
            raise EyevizError(f"{what}: unexpected members {extra[:8]}")
        arrays: dict[str, np.ndarray] = {}
        for k, shape in want.items():
            a = z.read_member(k, math.prod(shape), ("float32",), ndim=len(shape))
            if a.shape != shape:
                raise EyevizError(
                    f"{what}: {k} has shape {a.shape}, expected {shape} for hidden = {hidden}"
                )
            if not np.isfinite(a).all():
                raise EyevizError(f"{what}: {k} holds NaN or infinite weights")
            arrays[k] = a
    if not (arrays["x_scale"] > 0).all():
        raise EyevizError(f"{what}: x_scale must be > 0")
    return hidden, arrays


def _silu(x: np.ndarray) -> np.ndarray:
    """x / (1 + exp(-x)), in place."""
    t = np.negative(x)
    with np.errstate(over="ignore"):
        np.exp(t, out=t)
    t += 1.0
    return np.divide(x, t, out=x)


class Learned3DEstimator(Estimator3D):
    """Corrects the triangulation of the two eyes' mean lit directions with an MLP.

    ``flagged`` marks rows whose mean directions do not meet in front of both eyes (the
    triangulation is then r_max along their mean, which the network corrects), and rows
    whose answer lies outside the training domain (:func:`inside_domain`): those are
    answered by the triangulation where it lies inside, else NaN (issue 35)."""

    name = "learned3d"
    checks_indices = True  # on the runs of the summaries (healpix_summaries._check_runs)
    #: the summaries of 32,768 rows at a time (both eyes side by side with two threads),
    #: the network still in the batches of 16,384 rows it always had (:meth:`_predict_csr`)
    block_rows = 2 * _BLOCK

    def __init__(
        self,
        hidden: int,
        arrays: dict[str, np.ndarray],
        domain: Domain3D | None = None,
        metadata: dict | None = None,
    ) -> None:
        meta = dict(metadata or {})
        meta["n_weights"] = int(sum(v.size for k, v in arrays.items() if k.startswith("net.")))
        super().__init__(Domain3D() if domain is None else domain, meta)
        self.hidden = hidden
        self._w = {k: np.asarray(v, np.float32) for k, v in arrays.items()}
        #: 2 (the default where there are two cores or more): summarise the two eyes in
        #: two threads (:meth:`_summaries`); 1: in turn. The same floats either way.
        #: An integer >= 1 (more than 2 is 2), checked by :meth:`predict`.
        self.threads = min(2, os.cpu_count() or 1)

    def predict(self, lit_a, lit_b) -> Prediction3D:
        """:meth:`Estimator3D.predict`; ``threads`` must be an integer >= 1."""
        self.threads = check_int("threads", self.threads, ge=1)
        return super().predict(lit_a, lit_b)

    def network(self, x: np.ndarray) -> np.ndarray:
        """The network's raw outputs (n, 3) for feature rows x (n, N_FEATURES)."""
        w = self._w
        out = np.empty((x.shape[0], N_OUT), np.float32)
        for s in range(0, x.shape[0], _BLOCK):
            h = (x[s : s + _BLOCK] - w["x_mean"]) / w["x_scale"]
            for i, layer in enumerate(_LAYERS):
                h = h @ w[f"net.{layer}.weight"].T
                h += w[f"net.{layer}.bias"]
                if i < len(_LAYERS) - 1:
                    _silu(h)
            out[s : s + _BLOCK] = h
        return out

    def _predict_csr(
        self, lit_a: LitCSR, lit_b: LitCSR
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        d = self.domain
        sa, sb = self._summaries(lit_a, lit_b)
        x, log_r0, az0, el0, ok, flagged = features(sa, sb, d.h, d.nside, d.r_min, d.r_max)
        n = x.shape[0]
        r = np.full(n, np.nan)
        az = np.full(n, np.nan)
        el = np.full(n, np.nan)
        # the network's batches: each _BLOCK rows handed over, less those with non-finite
        # features (float32 products may round differently in another batch)
        for s in range(0, n, _BLOCK):
            sel = np.flatnonzero(ok[s : s + _BLOCK]) + s
            if sel.size:
                out = self.network(x[sel]).astype(np.float64)
                r[sel] = np.exp(log_r0[sel] + out[:, 0])
                az[sel] = az0[sel] + AZ_SCALE * out[:, 1]
                el[sel] = el0[sel] + EL_SCALE * out[:, 2]
        # outside the training domain: the triangulation where it lies inside, else NaN
        out_ = ~inside_domain(d, r, az, el)
        if out_.any():
            r0 = np.exp(log_r0)
            back = out_ & inside_domain(d, r0, az0, el0)
            r, az, el = (np.where(back, f, np.where(out_, np.nan, v))
                         for v, f in ((r, r0), (az, az0), (el, el0)))  # fmt: skip
        return r, az, el, flagged | out_

    def _summaries(self, lit_a: LitCSR, lit_b: LitCSR) -> tuple[EyeSummary, EyeSummary]:
        """Both eyes' summaries; with ``threads`` >= 2 and more than ``_THREAD_ROWS`` rows
        side by side (numpy releases the GIL in its loops; the same floats either way).
        lit_a's error, if any, comes first."""
        nside = self.domain.nside
        if self.threads < 2 or lit_a[0].size <= _THREAD_ROWS:
            return (
                eye_summaries(nside, lit_a[0], lit_a[1], name="lit_a"),
                eye_summaries(nside, lit_b[0], lit_b[1], name="lit_b"),
            )
        with ThreadPoolExecutor(1, thread_name_prefix="eyeviz-learned3d") as pool:
            fut = pool.submit(eye_summaries, nside, lit_a[0], lit_a[1], name="lit_a")
            try:
                sb = eye_summaries(nside, lit_b[0], lit_b[1], name="lit_b")
            except ValueError:
                fut.result()  # lit_a's error first
                raise
            return fut.result(), sb

    def __repr__(self) -> str:
        return f"<Learned3DEstimator hidden={self.hidden} nside={self.domain.nside}>"


def inside_domain(d: Domain3D, r, az, el) -> np.ndarray:
    """Whether each answer lies in the ranges the network was trained on, widened by
    :data:`DOMAIN_SLACK`: r in [r_min, r_max], azimuth in [0, pi], |elevation| <= el_max
    (finite; the data set's convention, :mod:`eyeviz.estimators.base`)."""
    s = DOMAIN_SLACK
    with np.errstate(invalid="ignore"):
        ok = (r >= d.r_min * (1 - s)) & (r <= d.r_max * (1 + s))
        ok &= (az >= -s * math.pi) & (az <= (1 + s) * math.pi)
        ok &= np.abs(el) <= d.el_max * (1 + s)
    return ok


def _read_meta(d: Path) -> dict:
    meta_f = d / META_FILE
    if not meta_f.is_file():
        raise EyevizError(
            f"learned3d weights not found in {d} (no {META_FILE}); "
            f"train them with `eyeviz train learned3d -o {d}`"
        )
    raw = limits.read_bounded(meta_f, limits.MAX_MODEL_META_BYTES, "model metadata")
    try:
        meta = json.loads(raw)
    except (ValueError, RecursionError) as exc:
        raise EyevizError(f"{str(meta_f)!r}: not valid JSON ({one_line(exc, 120)})") from None
    if not isinstance(meta, dict):
        raise EyevizError(f"{str(meta_f)!r}: expected a JSON object, got {type(meta).__name__}")
    if meta.get("format") != FORMAT or meta.get("version") != VERSION:
        raise EyevizError(
            f"{str(meta_f)!r}: format {meta.get('format')!r} version {meta.get('version')!r}, "
            f"expected {FORMAT!r} version {VERSION}"
        )
    return meta


def load(
    path: str | os.PathLike | None = None, domain: Domain3D | None = None
) -> Learned3DEstimator:
    """The weights in directory ``path`` (default the shipped ``assets/models/learned3d``).

    The weights answer for the design they were trained for: ``domain`` (default: the
    design in ``learned3d.json``) must have the same h, l and nside and lie inside the
    trained ranges of r, g and elevation, else one EyevizError line says which differs.
    Every problem with the files is one EyevizError line naming the file."""
    d = Path(path) if path is not None else default_dir()
    meta = _read_meta(d)
    meta_f = d / META_FILE
    data = meta.get("data")
    if not isinstance(data, dict):
        raise EyevizError(f"{str(meta_f)!r}: 'data' must be an object with the domain")
    try:
        trained = Domain3D.from_dict(data)
    except (EyevizError, ValueError, TypeError, OverflowError) as exc:
        raise EyevizError(f"{str(meta_f)!r}: bad data ({one_line(exc, 160)})") from None
    hidden, arrays = read_weights(d / WEIGHTS_FILE)
    if domain is None:
        domain = trained
    elif not isinstance(domain, Domain3D):
        raise EyevizError(f"domain must be a Domain3D, got {type(domain).__name__}")
    else:
        check_design(domain, trained, str(d))
    return Learned3DEstimator(hidden, arrays, domain, meta)


def check_design(domain: Domain3D, trained: Domain3D, where: str) -> None:
    """EyevizError unless ``domain`` has the trained eyes (h, l, nside) and ranges inside
    the trained ones (the network was never shown anything else)."""
    if domain.design != trained.design:
        raise EyevizError(
            f"learned3d weights in {where} are for h={num(trained.h)}, l={num(trained.l)}, "
            f"nside={trained.nside}; the domain has h={num(domain.h)}, l={num(domain.l)}, "
            f"nside={domain.nside} (train them for it with `eyeviz train learned3d`)"
        )
    for name, lo in (("r_min", True), ("r_max", False), ("g_max", False), ("el_max", False)):
        have, was = getattr(domain, name), getattr(trained, name)
        if (have < was * (1 - 1e-12)) if lo else (have > was * (1 + 1e-12)):
            raise EyevizError(
                f"learned3d weights in {where} were trained for {name}={num(was)}; the domain's "
                f"{name}={num(have)} lies outside the trained range"
            )
