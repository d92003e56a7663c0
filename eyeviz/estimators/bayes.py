"""The information limit: the empirical posterior of (r, phi) per interval key.

A bitmap pair is fully described by its key (LA, RA, LB, RB) (Prop. 2). Among all
estimators that see only the bitmaps, the one with the least expected absolute error
returns the posterior median of the target given the key, and the one with the least
expected MAPE (Eq. 34) returns the 1/x-weighted posterior median (minimising
E|y - x| / x over y). This module estimates both from a large sample of Algorithm 1
(:mod:`eyeviz.dataset`, single pass, the training domain's parameters), doubled by the
model's mirror symmetry x -> -x, which maps key (LA, RA, LB, RB) to
(w-1-RB, w-1-LB, w-1-RA, w-1-LA) (w = m/2) and phi to pi - phi while keeping r.

Unseen keys (rare: 0.04 % of a fresh test set with the shipped 3*10^7-row table) fall
back to the analytic triangulation; ``predict`` exposes them as ``seen`` on the estimator
(:meth:`BayesEstimator.lookup`).

The table is stored compactly (``assets/models/bayes.npz``): sorted keys as uint32
differences, and per key the log-ratio of r and the difference of phi to the analytic
estimate as float16 (a relative rounding of 5e-4 on r and 5e-7 rad on phi, far below
the errors measured). ``eyeviz train bayes`` rebuilds it.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np

from eyeviz import EyevizError
from eyeviz.estimators import analytic
from eyeviz.estimators.base import PAPER_DOMAIN, Domain, Estimator
from eyeviz.files.atomic import atomic_output
from eyeviz.resources import models_dir

__all__ = ["BayesEstimator", "build_table", "load", "default_path", "TARGETS"]

TARGETS = ("mape", "mae")
_VALUE_BITS = 24  # quantisation of a value inside its key for the one-pass sort


def default_path() -> Path:
    return models_dir() / "bayes.npz"


def _encode(LA, RA, LB, RB, w: int) -> np.ndarray:
    return ((LA * w + RA) * w + LB) * w + RB


def _decode(key: np.ndarray, w: int):
    RB = key % w
    key = key // w
    LB = key % w
    key = key // w
    return key // w, key % w, LB, RB


def _group_medians(key: np.ndarray, value: np.ndarray, lo: float, hi: float, weighted: bool):
    """Per distinct key: (keys, median of value) with weights 1/value if ``weighted``.

    One integer sort of key * 2^24 + quantised value (a precision of (hi - lo) / 2^24).
    """
    q = np.clip(
        ((value - lo) / (hi - lo) * (1 << _VALUE_BITS)).astype(np.int64), 0, (1 << _VALUE_BITS) - 1
    )
    comb = np.sort((key << _VALUE_BITS) | q)
    k = comb >> _VALUE_BITS
    v = lo + ((comb & ((1 << _VALUE_BITS) - 1)) + 0.5) * ((hi - lo) / (1 << _VALUE_BITS))
    del comb
    starts = np.flatnonzero(np.r_[True, k[1:] != k[:-1]])
    w = 1.0 / v if weighted else np.ones_like(v)
    cw = np.cumsum(w)
    total = np.add.reduceat(w, starts)
    before = np.r_[0.0, cw[:-1]][starts]
    idx = np.searchsorted(cw, before + 0.5 * total)
    idx = np.minimum(idx, np.r_[starts[1:], k.size] - 1)
    return k[starts], v[idx], np.diff(np.r_[starts, k.size])


def build_table(n: int, domain: Domain = PAPER_DOMAIN, seed: int = 12345, progress=None) -> dict:
    """Sample n elements (single pass) and return the posterior tables as arrays.

    ``progress(done, total)`` is called after each generated chunk.
    """
    from eyeviz import dataset

    t0 = time.perf_counter()
    eyes = domain.eyes
    w = domain.width
    p = dataset.make_params(eyes, domain.r_min, domain.r_max, domain.g_max, "single", seed)
    keys, rs, phis = [], [], []
    done = 0
    for c in dataset.iter_chunks(n, p, chunk=1 << 17):
        for k, r, phi in (
            (_encode(c.la, c.ra, c.lb, c.rb, w), c.r, c.phi),
            (
                _encode(w - 1 - c.rb, w - 1 - c.lb, w - 1 - c.ra, w - 1 - c.la, w),
                c.r,
                math.pi - c.phi,
            ),
        ):
            keys.append(k)
            rs.append(r)
            phis.append(phi)
        done += len(c)
        if progress is not None:
            progress(done, n)
    key = np.concatenate(keys)
    del keys
    out = {}
    for name, vals, lo, hi in (
        ("r", np.concatenate(rs), domain.r_min, domain.r_max),
        ("phi", np.concatenate(phis), 0.0, math.pi),
    ):
        for target, weighted in (("mape", True), ("mae", False)):
            k, med, cnt = _group_medians(key, vals, lo, hi, weighted)
            out[f"{name}_{target}"] = med
        del vals
    out["key"] = k
    out["count"] = cnt
    out["meta"] = {
        "n": int(n),
        "seed": int(seed),
        "domain": domain.to_dict(),
        "mode": "single",
        "symmetrised": True,
        "keys": int(k.size),
        "build_seconds": time.perf_counter() - t0,
    }
    return out


def _analytic(key: np.ndarray, domain: Domain):
    LA, RA, LB, RB = _decode(key, domain.width)
    return analytic.estimate(LA, RA, LB, RB, domain)


def save_table(table: dict, path) -> None:
    """Write the compact npz atomically (temporary file + rename)."""
    path = Path(path)
    domain = Domain.from_dict(table["meta"]["domain"])
    key = table["key"]
    ra, pa = _analytic(key, domain)
    arrays = {
        "key0": np.array([key[0]], np.int64),
        "dkey": np.diff(key).astype(np.uint32),
        "count": np.minimum(table["count"], np.iinfo(np.uint32).max).astype(np.uint32),
        "meta": np.array(json.dumps({**table["meta"], "keys_sha256": _keys_digest(key)})),
    }
    for t in TARGETS:
        arrays[f"logr_{t}"] = np.log(table[f"r_{t}"] / ra).astype(np.float16)
        arrays[f"dphi_{t}"] = (table[f"phi_{t}"] - pa).astype(np.float16)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(path) as tmp:
        np.savez_compressed(tmp, **arrays)


#: Largest m of a table: every key (LA, RA, LB, RB) packs into w^4 <= 2^62 (w = m/2).
MAX_TABLE_M = 2 * 46340
#: Slack around [r_min, r_max] and [0, pi] for the float16 rounding of stored medians.
_STORED_TOL = 2e-3


def _keys_digest(key: np.ndarray) -> str:
    import hashlib

    return hashlib.sha256(np.ascontiguousarray(key, np.int64).tobytes()).hexdigest()


# long: every member of an untrusted file checked in turn before use, each with its own one-line
# error
def load_table(path) -> dict:
    """The table of ``path``, every member bounded and checked before use: one
    EyevizError line naming the file and the problem for anything else (never unpickles).

    Checked: the file size; each member's dtype and declared shape (before reading it);
    the meta (a JSON object with a valid domain, ``n`` and ``keys``); keys strictly
    increasing inside [0, w^4) and each a pair of valid intervals (LA <= RA, LB <= RB,
    Prop. 2); every stored median inside the domain ([r_min, r_max], [0, pi]), which is
    what a corrupted ``key0`` or value breaks; the keys' SHA-256 when the meta has one."""
    from eyeviz.core.validation import check_int
    from eyeviz.files import limits
    from eyeviz.files.npz import NpzReader, one_line

    path = Path(path)
    what = f"bayes table {str(path)!r}"
    limits.check_file_size(path, limits.MAX_MODEL_FILE_BYTES, "bayes table")
    K = limits.MAX_TABLE_KEYS
    with NpzReader(path, what) as z:
        meta_arr = z.read_member("meta", 1, ("U",), ndim=0, max_bytes=limits.MAX_MODEL_META_BYTES)
        try:
            meta = json.loads(str(meta_arr[()]))
            if not isinstance(meta, dict) or not isinstance(meta.get("domain"), dict):
                raise TypeError("meta is not an object with a 'domain' object")
            domain = Domain.from_dict(meta["domain"])
            n = check_int("n", meta.get("n"), ge=0, le=10**15)
            nkeys = check_int("keys", meta.get("keys"), ge=1, le=K)
            seconds = float(meta.get("build_seconds", 0.0))
        except Exception as exc:  # noqa: BLE001 - any bad meta is one message
            raise z.fail(f"bad meta ({one_line(exc)})") from None
        if domain.m > MAX_TABLE_M:
            raise z.fail(f"domain m = {domain.m} exceeds {MAX_TABLE_M} (keys would overflow)")
        key0 = z.read_member("key0", 1, ("int64",), ndim=1)
        dkey = z.read_member("dkey", K, ("uint32",), ndim=1)
        count = z.read_member("count", K, ("uint32",), ndim=1)
        stored = {
            f"{v}_{t}": z.read_member(f"{v}_{t}", K, ("float16",), ndim=1)
            for t in TARGETS
            for v in ("logr", "dphi")
        }
    sizes = {"key0 + dkey": key0.size + dkey.size, "count": count.size}
    sizes.update({k: v.size for k, v in stored.items()})
    for name, size in sizes.items():
        if size != nkeys:
            raise EyevizError(f"{what}: {name} has {size} entries, meta says keys = {nkeys}")
    w = domain.width
    if not 0 <= int(key0[0]) < w**4:
        raise EyevizError(f"{what}: key0 = {int(key0[0])} outside [0, {w**4})")
    if dkey.size and not dkey.min() > 0:
        raise EyevizError(f"{what}: keys not strictly increasing (dkey has 0)")
    key = np.cumsum(np.r_[key0, dkey.astype(np.int64)])
    if int(key[-1]) >= w**4:
        raise EyevizError(f"{what}: last key {int(key[-1])} outside [0, {w**4})")
    digest = meta.get("keys_sha256")
    if digest is not None and digest != _keys_digest(key):
        raise EyevizError(f"{what}: keys do not match the meta's keys_sha256 (corrupted)")
    LA, RA, LB, RB = _decode(key, w)
    bad = np.flatnonzero((LA > RA) | (LB > RB))
    if bad.size:
        i = int(bad[0])
        raise EyevizError(
            f"{what}: key {i} = {(int(LA[i]), int(RA[i]), int(LB[i]), int(RB[i]))} is not a "
            "pair of intervals (LA <= RA, LB <= RB); the keys are corrupted"
        )
    with np.errstate(all="ignore"):
        ra, pa = analytic.estimate(LA, RA, LB, RB, domain)
        values: dict[str, np.ndarray] = {}
        for t in TARGETS:
            values[f"r_{t}"] = ra * np.exp(stored[f"logr_{t}"].astype(np.float64))
            values[f"phi_{t}"] = pa + stored[f"dphi_{t}"].astype(np.float64)
    lo, hi = domain.r_min * (1 - _STORED_TOL), domain.r_max * (1 + _STORED_TOL)
    tol = _STORED_TOL
    for t in TARGETS:
        for name, vlo, vhi in ((f"r_{t}", lo, hi), (f"phi_{t}", -tol, math.pi + tol)):
            v = values[name]
            out = np.flatnonzero(~((v >= vlo) & (v <= vhi)))
            if out.size:
                i = int(out[0])
                raise EyevizError(
                    f"{what}: {name} of key {i} is {v[i]:.6g}, outside [{vlo:.6g}, {vhi:.6g}] "
                    "(corrupted keys or values)"
                )
    meta["build_seconds"] = seconds
    meta["n"] = n
    return {"key": key, "count": count.astype(np.int64), "meta": meta, **values}


class BayesEstimator(Estimator):
    """Posterior (weighted) median per key; the analytic estimate for unseen keys."""

    name = "bayes"

    def __init__(self, table: dict, target: str = "mape") -> None:
        if target not in TARGETS:
            raise EyevizError(f"target must be one of {TARGETS}, got {target!r}")
        meta = table["meta"]
        domain = Domain.from_dict(meta["domain"])
        super().__init__(
            domain,
            {
                "n_weights": 0,
                "train_seconds": meta.get("build_seconds", 0.0),
                "sample_size": meta["n"],
                "keys": meta["keys"],
                "target": target,
            },
        )
        self.target = target
        self._key = table["key"]
        self._r = table[f"r_{target}"]
        self._phi = table[f"phi_{target}"]

    def lookup(self, LA, RA, LB, RB):
        """(r, phi, seen) for valid interval arrays; seen is False where the key is new."""
        key = _encode(
            np.asarray(LA), np.asarray(RA), np.asarray(LB), np.asarray(RB), self.domain.width
        )
        i = np.minimum(np.searchsorted(self._key, key), self._key.size - 1)
        seen = self._key[i] == key
        r = self._r[i]
        phi = self._phi[i]
        if not seen.all():
            miss = np.flatnonzero(~seen)
            r = r.copy()
            phi = phi.copy()
            r[miss], phi[miss] = analytic.estimate(
                LA[miss], RA[miss], LB[miss], RB[miss], self.domain
            )
        return r, phi, seen

    def _predict_intervals(self, LA, RA, LB, RB):
        r, phi, _ = self.lookup(LA, RA, LB, RB)
        return r, phi


def load(
    path=None,
    target: str = "mape",
    n: int | None = None,
    seed: int = 12345,
    domain: Domain = PAPER_DOMAIN,
) -> BayesEstimator:
    """The shipped table (or ``path``); with ``n``, build a fresh table in memory instead."""
    if n is not None:
        return BayesEstimator(build_table(n, domain, seed), target)
    path = Path(path) if path is not None else default_path()
    if not path.is_file():
        raise EyevizError(
            f"bayes table {path} not found; build it with `eyeviz train bayes -o {path}`"
        )
    return BayesEstimator(load_table(path), target)


def fit(
    data=None,
    out_dir=None,
    *,
    domain: Domain | None = None,
    n: int = 30_000_000,
    seed: int = 12345,
    filename: str = "bayes.npz",
    command: str | None = None,
    progress=None,
) -> Path:
    """The registry's training shape: sample ``n`` elements of ``domain`` (the information
    limit needs its own large single-pass sample, so ``data`` must be None), build the
    posterior table and write ``out_dir/filename`` (default the user models directory),
    staged then swapped in. Returns the .npz path for ``load(path=...)``."""
    from eyeviz.core.validation import check_int
    from eyeviz.estimators.store import staged, user_models_dir
    from eyeviz.files import limits

    if data is not None:
        raise EyevizError(
            "bayes builds its table from its own Algorithm 1 sample; give -n, not a data file"
        )
    if not filename.endswith(".npz") or "/" in filename:
        raise EyevizError(f"bayes output must be a .npz file name, got {filename!r}")
    n = check_int("n", n, ge=1, le=limits.MAX_ROWS)
    dom = PAPER_DOMAIN if domain is None else domain
    out = Path(out_dir) if out_dir is not None else user_models_dir()
    table = build_table(n, dom, seed, progress)
    table["meta"]["command"] = command
    with staged(out) as stage:
        save_table(table, stage / filename)
    return out / filename
