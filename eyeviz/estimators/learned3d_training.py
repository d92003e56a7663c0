"""Training of the learned 3D estimator (:mod:`eyeviz.estimators.learned3d`): features of
generated or given 3D data, Adam + one-cycle on the three relative / absolute errors,
early stopping, staged output (:mod:`eyeviz.estimators.store`), and :func:`fit`, the
registry's training shape. Imports torch.

Generated data are Algorithm 1 in 3D, single pass (:mod:`eyeviz.dataset.algorithm1_3d`):
the training set from ``seed``, the validation set from ``seed + 1``; both seeds are
recorded in ``learned3d.json`` so a test set can avoid them. The lit sets are reduced to
features chunk by chunk and dropped (a row holds thousands of indices).
"""

from __future__ import annotations

import json
import math
import os
import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from eyeviz import EyevizError
from eyeviz.core.bounds import MAX_THREADS
from eyeviz.core.domain import DEFAULT_EL_MAX, Domain, Domain3D
from eyeviz.core.validation import check_int, check_real, num
from eyeviz.dataset.records import Dataset3D
from eyeviz.estimators import metrics
from eyeviz.estimators.fit_loop import fit_one_cycle
from eyeviz.estimators.learned3d import (
    AZ_SCALE,
    EL_SCALE,
    FORMAT,
    META_FILE,
    N_OUT,
    VERSION,
    WEIGHTS_FILE,
    Learned3DEstimator,
    write_weights,
)
from eyeviz.estimators.learned3d_features import N_FEATURES, eye_summaries, features
from eyeviz.estimators.store import staged, user_models_dir
from eyeviz.files import limits

__all__ = ["Learned3DNet", "featurise", "fit", "generated_features", "train"]

_COLS = ("x", "log_r0", "az0", "el0", "r", "azimuth", "elevation")


class Learned3DNet(nn.Module):
    """Standardise - Linear(N_FEATURES, H) - SiLU - Linear(H, H) - SiLU - Linear(H, 3),
    the last layer zero at the start (the triangulation)."""

    def __init__(self, hidden: int, x_mean: np.ndarray, x_scale: np.ndarray) -> None:
        super().__init__()
        self.register_buffer("x_mean", torch.as_tensor(x_mean, dtype=torch.float32))
        self.register_buffer("x_scale", torch.as_tensor(x_scale, dtype=torch.float32))
        self.net = nn.Sequential(
            nn.Linear(N_FEATURES, hidden),
            nn.SiLU(),
            nn.Linear(hidden, hidden),
            nn.SiLU(),
            nn.Linear(hidden, N_OUT),
        )
        last = self.net[-1]
        assert isinstance(last, nn.Linear)
        nn.init.zeros_(last.weight)
        nn.init.zeros_(last.bias)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        mean, scale = self.get_buffer("x_mean"), self.get_buffer("x_scale")
        return self.net((x - mean) / scale)

    def arrays(self) -> dict[str, np.ndarray]:
        """The state as numpy arrays, named as :func:`learned3d.expected_shapes`."""
        return {k: v.detach().cpu().numpy().copy() for k, v in self.state_dict().items()}


def featurise(chunks: Iterable[Dataset3D], domain: Domain3D) -> dict[str, np.ndarray]:
    """The network's inputs, the triangulation and the labels of every row of ``chunks``
    whose eyes both lit a facet (columns of ``_COLS``)."""
    parts: dict[str, list[np.ndarray]] = {k: [] for k in _COLS}
    for c in chunks:
        if c.domain.design != domain.design:
            raise EyevizError(
                f"data design h={num(c.domain.h)}, l={num(c.domain.l)}, nside={c.domain.nside} "
                f"differs from the domain's h={num(domain.h)}, l={num(domain.l)}, "
                f"nside={domain.nside}"
            )
        sa = eye_summaries(domain.nside, c.indptr_a, c.indices_a)
        sb = eye_summaries(domain.nside, c.indptr_b, c.indices_b)
        x, log_r0, az0, el0, ok, _ = features(
            sa, sb, domain.h, domain.nside, domain.r_min, domain.r_max
        )
        for k, v in zip(_COLS, (x, log_r0, az0, el0, c.r, c.azimuth, c.elevation), strict=True):
            parts[k].append(np.asarray(v)[ok])
    if not parts["r"]:
        raise EyevizError("the data hold no rows")
    return {k: np.concatenate(v) for k, v in parts.items()}


def generated_features(n: int, domain: Domain3D, seed: int) -> dict[str, np.ndarray]:
    """:func:`featurise` of ``n`` single-pass elements of Algorithm 1 in 3D (``seed``)."""
    from eyeviz.dataset.algorithm1_3d import iter_chunks3d, make_params3d

    return featurise(iter_chunks3d(n, make_params3d(domain, "single", seed)), domain)


def _split(cols: dict[str, np.ndarray], seed: int) -> tuple[dict, dict]:
    perm = np.random.default_rng(seed).permutation(cols["r"].shape[0])
    n_val = max(2, perm.size // 10)
    return ({k: v[perm[n_val:]] for k, v in cols.items()},
            {k: v[perm[:n_val]] for k, v in cols.items()})  # fmt: skip


def _errors(
    out: torch.Tensor, t: dict[str, torch.Tensor]
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Mean relative r error, relative azimuth error and absolute elevation error (rad)."""
    dd = (torch.exp(t["log_r0"] + out[:, 0] - t["log_r"]) - 1.0).abs().mean()
    ad = ((t["az0"] + AZ_SCALE * out[:, 1] - t["azimuth"]) / t["azimuth"]).abs().mean()
    el = (t["el0"] + EL_SCALE * out[:, 2] - t["elevation"]).abs().mean()
    return dd, ad, el


def _tensors(d: dict[str, np.ndarray]) -> dict[str, torch.Tensor]:
    return {
        "x": torch.from_numpy(np.ascontiguousarray(d["x"], np.float32)),
        "log_r0": torch.from_numpy(d["log_r0"]),
        "az0": torch.from_numpy(d["az0"]),
        "el0": torch.from_numpy(d["el0"]),
        "log_r": torch.from_numpy(np.log(d["r"])),
        "azimuth": torch.from_numpy(d["azimuth"]),
        "elevation": torch.from_numpy(d["elevation"]),
    }


def train_net(
    tr: dict[str, np.ndarray],
    va: dict[str, np.ndarray],
    hidden: int = 128,
    epochs: int = 40,
    batch: int = 1024,
    lr: float = 3e-3,
    patience: int = 5,
    seed: int = 0,
    progress: Callable[[str, int, int, float], None] | None = None,
) -> tuple[Learned3DNet, dict[str, Any]]:
    """Adam + one-cycle on dd / dd0 + ad / ad0 + el / el0 (each error over the
    triangulation's on the training set, so the three count alike); the epoch with the
    lowest validation loss is kept."""
    torch.manual_seed(seed)
    g = torch.Generator().manual_seed(seed)
    x = tr["x"]
    mean = x.mean(axis=0, dtype=np.float64)
    scale = x.std(axis=0, dtype=np.float64)
    scale = np.where(scale > 1e-12, scale, 1.0)
    net = Learned3DNet(hidden, mean.astype(np.float32), scale.astype(np.float32))
    t, v = _tensors(tr), _tensors(va)
    zero = torch.zeros(t["x"].shape[0], N_OUT, dtype=torch.float64)
    base = [float(e) for e in _errors(zero, t)]
    base = [b if b > 0 else 1.0 for b in base]
    n = t["x"].shape[0]

    def loss_of(out: torch.Tensor, tt: dict[str, torch.Tensor]) -> torch.Tensor:
        dd, ad, el = _errors(out.double(), tt)
        return dd / base[0] + ad / base[1] + el / base[2]

    raw, best = fit_one_cycle(
        net,
        n,
        max(1, n // batch),
        batch,
        lambda idx: loss_of(net(t["x"][idx]), {k: w[idx] for k, w in t.items()}),
        lambda: float(loss_of(net(v["x"]), v)),
        epochs=epochs,
        lr=lr,
        patience=patience,
        min_delta=1e-6,
        generator=g,
        progress=progress,
        label="learned3d",
    )
    history = [round(val, 6) for val in raw]
    info = {
        "epochs": len(history),
        "val_loss_history": history,
        "best_val_loss": round(best, 6),
        "loss": "mean|r_hat/r-1|/dd0 + mean|az_hat/az-1|/ad0 + mean|el_hat-el|/el0 "
        "(dd0, ad0, el0: the triangulation's on the training set)",
        "triangulation_train_errors": [round(b, 8) for b in base],
    }
    return net, info


def _metrics(est: Learned3DEstimator, va: dict[str, np.ndarray]) -> dict[str, Any]:
    out = est.network(va["x"]).astype(np.float64)
    r = np.exp(va["log_r0"] + out[:, 0])
    az = va["az0"] + AZ_SCALE * out[:, 1]
    el = va["el0"] + EL_SCALE * out[:, 2]
    return {
        "dd": metrics.summary(va["r"], r),
        "ad": metrics.summary(va["azimuth"], az),
        "el_mae_deg": math.degrees(metrics.mae(va["elevation"], el)),
        "el_r2": metrics.r2(va["elevation"], el),
        "triangulation": {
            "dd_mape": metrics.mape(va["r"], np.exp(va["log_r0"])),
            "ad_mape": metrics.mape(va["azimuth"], va["az0"]),
            "el_mae_deg": math.degrees(metrics.mae(va["elevation"], va["el0"])),
        },
    }


# long: one training run in order (data, features, network, loop, files), sharing the run's locals
def train(
    out_dir: str | os.PathLike | None = None,
    n_train: int = 500_000,
    n_val: int = 50_000,
    seed: int = 0,
    epochs: int = 40,
    hidden: int = 128,
    batch: int = 1024,
    lr: float = 3e-3,
    patience: int = 5,
    domain: Domain3D | None = None,
    threads: int = 1,
    command: str | None = None,
    progress: Callable[[str, int, int, float], None] | None = None,
    data: Dataset3D | str | os.PathLike | None = None,
) -> dict:
    """Generate (seeds ``seed``, ``seed + 1``) or read data, train, write the weights and
    ``learned3d.json`` into ``out_dir`` (staged: an interruption leaves the previous
    model intact). ``data`` (a Dataset3D or a sparse 3D .npz) replaces the generated
    data: its rows are split 90 % / 10 % (seeded). Returns the metadata."""
    dom = Domain3D() if domain is None else domain
    n_train = check_int("n_train", n_train, ge=1, le=limits.MAX_ROWS)
    n_val = check_int("n_val", n_val, ge=2, le=limits.MAX_ROWS)
    seed = check_int("seed", seed, ge=0)
    epochs = check_int("epochs", epochs, ge=1)
    hidden = check_int("hidden", hidden, ge=1, le=limits.MAX_HIDDEN)
    batch = check_int("batch", batch, ge=1)
    lr = check_real("lr", lr, gt=0)
    patience = check_int("patience", patience, ge=1)
    threads = check_int("threads", threads, ge=1, le=MAX_THREADS)
    t0 = time.perf_counter()
    if data is None:
        if n_train < batch:
            raise EyevizError(f"n_train must be >= batch = {batch}, got {n_train}")
        tr = generated_features(n_train, dom, seed)
        va = generated_features(n_val, dom, seed + 1)
        source = {"mode": "single", "train_seed": seed, "val_seed": seed + 1}
    else:
        if isinstance(data, str | os.PathLike):
            from eyeviz.dataset.sparse3d import Sparse3DReader

            reader = Sparse3DReader(data)
            params = dict(reader.params)
            tr, va = _split(featurise(reader, dom), seed)
        else:
            params = dict(data.params)
            tr, va = _split(featurise([data], dom), seed)
        if tr["r"].shape[0] < batch:
            raise EyevizError(
                f"need >= {batch} training rows (one batch), the data have {tr['r'].shape[0]}"
            )
        source = {"mode": "given data set (90/10 split)", "data_params": params,
                  "train_seed": params.get("seed"), "split_seed": seed}  # fmt: skip
    t_data = time.perf_counter() - t0
    threads_before = torch.get_num_threads()
    torch.set_num_threads(threads)
    try:
        t1 = time.perf_counter()
        net, info = train_net(tr, va, hidden, epochs, batch, lr, patience, seed, progress)
        t_fit = time.perf_counter() - t1
    finally:
        torch.set_num_threads(threads_before)
    arrays = net.arrays()
    est = Learned3DEstimator(hidden, arrays, dom)
    meta = {
        "format": FORMAT,
        "version": VERSION,
        "estimator": "learned3d",
        "files": {"weights": WEIGHTS_FILE},
        "architecture": f"MLP {N_FEATURES}-{hidden}-{hidden}-{N_OUT} (SiLU) on lit-set "
        "summaries, correcting the triangulation of the mean lit directions",
        "n_weights": est.n_weights,
        "hidden": hidden,
        "data": {
            **dom.to_dict(),
            **source,
            "n_train": int(tr["r"].shape[0]),
            "n_val": int(va["r"].shape[0]),
        },  # fmt: skip
        "training": {
            "batch": batch,
            "lr": lr,
            "epochs_max": epochs,
            "patience": patience,
            "optimizer": "Adam + one-cycle",
            "threads": threads,
            **info,
        },  # fmt: skip
        "data_seconds": round(t_data, 1),
        "fit_seconds": round(t_fit, 1),
        "train_seconds": round(time.perf_counter() - t0, 1),
        "val_metrics": _metrics(est, va),
        "torch": torch.__version__,
        "command": command,
        "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
    }
    out = Path(out_dir) if out_dir is not None else user_models_dir() / "learned3d"
    with staged(out) as stage:
        write_weights(stage / WEIGHTS_FILE, hidden, arrays)
        (stage / META_FILE).write_text(json.dumps(meta, indent=2))
    return meta


def _domain3d(
    domain: Domain | Domain3D | None, nside: int | None, el_max: float | None
) -> Domain3D:
    """The 3D domain of ``eyeviz train learned3d``: a Domain3D as is; a planar Domain
    (the train command's --h --l --r-min --r-max --g-max) with ``nside`` (default m / 4)
    and ``el_max`` (default 30 degrees)."""
    if isinstance(domain, Domain3D):
        if nside is not None or el_max is not None:
            raise EyevizError("give nside and el_max in the Domain3D, not as options")
        return domain
    if domain is None:
        domain = Domain()
    if nside is None:
        if domain.m % 4:
            raise EyevizError(f"--m must be a multiple of 4 (m = 4 nside), got {domain.m}")
        nside = domain.m // 4
    el = DEFAULT_EL_MAX if el_max is None else math.radians(check_real("el_max", el_max, gt=0))
    return Domain3D(domain.h, domain.l, nside, domain.r_min, domain.r_max, domain.g_max, el)


def fit(
    data: Dataset3D | str | os.PathLike | None = None,
    out_dir: str | os.PathLike | None = None,
    *,
    domain: Domain | Domain3D | None = None,
    nside: int | None = None,
    el_max: float | None = None,
    n: int = 500_000,
    n_val: int = 50_000,
    seed: int = 0,
    epochs: int = 40,
    hidden: int = 128,
    patience: int = 5,
    threads: int = 1,
    command: str | None = None,
    progress: Callable[[str, int, int, float], None] | None = None,
) -> Path:
    """The registry's training shape: train on ``data`` (a Dataset3D or a sparse 3D .npz;
    None: generate ``n`` + ``n_val`` elements) into ``out_dir`` (default the user models
    directory's ``learned3d``), staged then swapped in. ``el_max`` in degrees. Returns the
    directory for ``load``."""
    dom = _domain3d(domain, nside, el_max)
    out = Path(out_dir) if out_dir is not None else user_models_dir() / "learned3d"
    train(out, n, n_val, seed, epochs, hidden, patience=patience, domain=dom,
          threads=threads, command=command, progress=progress, data=data)  # fmt: skip
    return out
