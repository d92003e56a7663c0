"""Training of the compact networks: data (generated or given), Adam + one-cycle with early
stopping, staged output (:mod:`eyeviz.estimators.store`), and :func:`fit`, the registry's
one training shape. Imports torch."""

from __future__ import annotations

import functools
import json
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import torch

from eyeviz import EyevizError
from eyeviz.core.bounds import MAX_THREADS
from eyeviz.core.validation import check_int, check_real, num
from eyeviz.estimators import metrics
from eyeviz.estimators.base import PAPER_DOMAIN, Domain, bitmaps_to_intervals
from eyeviz.estimators.compact_net import (
    AD_SCALE,
    N_FEATURES,
    CompactEstimator,
    CompactNet,
    features,
    save_net,
    write_atomic,
)
from eyeviz.estimators.fit_checks import COMPACT_BATCH, check_compact_rows
from eyeviz.estimators.fit_loop import fit_one_cycle
from eyeviz.estimators.store import staged, user_models_dir
from eyeviz.files import limits

if TYPE_CHECKING:
    from eyeviz.dataset import Dataset

__all__ = ["train", "fit"]


def _generate(n: int, domain: Domain, seed: int, mode: str = "single") -> dict[str, np.ndarray]:
    from eyeviz import dataset

    p = dataset.make_params(domain.eyes, domain.r_min, domain.r_max, domain.g_max, mode, seed)
    chunks = list(dataset.iter_chunks(n, p, chunk=1 << 17))
    return {
        k: np.concatenate([getattr(c, k) for c in chunks])
        for k in ("r", "phi", "la", "ra", "lb", "rb")
    }


def _fit(
    net: CompactNet,
    x: torch.Tensor,
    y: torch.Tensor,
    xv: torch.Tensor,
    yv: torch.Tensor,
    predict: Callable[[torch.Tensor, torch.Tensor], torch.Tensor],
    epochs: int,
    batch: int,
    lr: float,
    patience: int,
    seed: int,
    ckpt: Callable[[CompactNet], None],
    progress: Callable[[str, int, int, float], None] | None,
    label: str,
) -> dict:
    """Adam with a one-cycle schedule on the relative error; early stopping on validation
    (the loop: :func:`eyeviz.estimators.fit_loop.fit_one_cycle`)."""
    history, best = fit_one_cycle(
        net,
        x.shape[0],
        x.shape[0] // batch,
        batch,
        lambda idx: predict(net(x[idx]), y[idx]),
        lambda: float(predict(net(xv), yv)),
        epochs=epochs,
        lr=lr,
        patience=patience,
        min_delta=1e-7,
        generator=torch.Generator().manual_seed(seed),
        on_best=lambda: ckpt(net),
        progress=progress,
        label=label,
    )
    return {"epochs": len(history), "val_history": [round(v, 7) for v in history], "best_val": best}


def train(
    out_dir: str | os.PathLike | None = None,
    n_train: int = 1_000_000,
    n_val: int = 100_000,
    seed: int = 0,
    epochs: int = 12,
    hidden: int = 32,
    hidden_ad: int = 8,
    batch: int = COMPACT_BATCH,
    lr: float = 4e-3,
    patience: int = 3,
    domain: Domain = PAPER_DOMAIN,
    threads: int = 2,
    command: str | None = None,
    progress: Callable[[str, int, int, float], None] | None = None,
    data: Dataset | None = None,
) -> dict:
    """Generate data (single pass, seeds ``seed`` and ``seed + 1``), train both nets, save.

    ``data`` (a :class:`eyeviz.dataset.Dataset`) replaces the generated data: its single
    feature rows are split 90 % / 10 % (seeded) into training and validation. Every file
    (checkpoints, final weights, ``compact.json``) is written into a staging directory and
    moved into ``out_dir`` (default: the user models directory, never the shipped assets
    unless named) only at the end, so an interruption leaves the previous model intact.
    Returns the metadata.
    """
    batch = check_int("batch", batch, ge=1)
    n_train = check_int("n_train", n_train, ge=1, le=limits.MAX_ROWS)
    # R^2 (Eq. 35, standard form) of the validation set needs two values at least
    n_val = check_int("n_val", n_val, ge=2, le=limits.MAX_ROWS)
    epochs = check_int("epochs", epochs, ge=1)
    lr = check_real("lr", lr, gt=0)
    threads = check_int("threads", threads, ge=1, le=MAX_THREADS)
    t0 = time.perf_counter()
    if data is None:
        check_compact_rows(n_train, batch)
        tr = _generate(n_train, domain, seed)
        va = _generate(n_val, domain, seed + 1)
    else:
        tr, va = _split(data, seed, domain)
        n_train, n_val = len(tr["r"]), len(va["r"])
        if n_train < batch:
            raise EyevizError(
                f"need >= {batch} training rows (one batch), the data has {n_train} usable"
            )
    t_gen = time.perf_counter() - t0
    out = Path(out_dir) if out_dir is not None else user_models_dir()
    with staged(out) as stage:
        return _train_into(
            stage,
            tr,
            va,
            t0,
            t_gen,
            n_train,
            n_val,
            seed,
            epochs,
            hidden,
            hidden_ad,
            batch,
            lr,
            patience,
            domain,
            threads,
            command,
            progress,
            "single" if data is None else "given data set (90/10 split)",
        )


def _split(data: Dataset, seed: int, domain: Domain) -> tuple[dict, dict]:
    """Single-feature rows of a data set as interval columns, split 90/10 (seeded)."""
    if (data.eyes.h, data.eyes.l, data.eyes.m) != domain.design:
        raise EyevizError(
            f"data design h={num(data.eyes.h)}, l={num(data.eyes.l)}, m={data.eyes.m} differs from "
            f"the domain's h={num(domain.h)}, l={num(domain.l)}, m={domain.m}"
        )
    la, ra, lb, rb, ok = bitmaps_to_intervals(data.omega_a, data.omega_b, domain.width)
    cols = {"r": data.r, "phi": data.phi, "la": la, "ra": ra, "lb": lb, "rb": rb}
    cols = {k: np.asarray(v)[ok] for k, v in cols.items()}
    perm = np.random.default_rng(seed).permutation(len(cols["r"]))
    n_val = max(1, len(perm) // 10)
    return (
        {k: v[perm[n_val:]] for k, v in cols.items()},
        {k: v[perm[:n_val]] for k, v in cols.items()},
    )


# long: one training run in order (data, networks, loop, files), sharing the run's locals
def _train_into(
    out: Path,
    tr: dict[str, np.ndarray],
    va: dict[str, np.ndarray],
    t0: float,
    t_gen: float,
    n_train: int,
    n_val: int,
    seed: int,
    epochs: int,
    hidden: int,
    hidden_ad: int,
    batch: int,
    lr: float,
    patience: int,
    domain: Domain,
    threads: int,
    command: str | None,
    progress: Callable[[str, int, int, float], None] | None,
    source: str,
) -> dict:
    """The body of :func:`train`, writing into the staging directory ``out``."""
    torch.set_num_threads(threads)
    torch.manual_seed(seed)

    def prep(
        d: dict[str, np.ndarray],
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
        x, log_r0, p0 = features(d["la"], d["ra"], d["lb"], d["rb"], domain)
        return (
            torch.from_numpy(x),
            torch.from_numpy((np.log(d["r"]) - log_r0).astype(np.float32)),
            torch.from_numpy(((d["phi"] - p0) / AD_SCALE).astype(np.float32)),
            torch.from_numpy((d["phi"] / AD_SCALE).astype(np.float32)),
        )

    x, yd, ya, sa = prep(tr)
    xv, ydv, yav, sav = prep(va)

    def dd_loss(out: torch.Tensor, y: torch.Tensor) -> torch.Tensor:
        return (torch.exp(out - y) - 1.0).abs().mean()

    # AD: |phi_hat - phi| / phi with phi_hat - phi = AD_SCALE * (out - y)
    ya_pair = torch.stack([ya, sa], 1)
    yav_pair = torch.stack([yav, sav], 1)

    def ad_loss(out: torch.Tensor, y: torch.Tensor) -> torch.Tensor:
        return ((out - y[:, 0]).abs() / y[:, 1]).mean()

    files = {"dd": "compact_dd.pt", "ad": "compact_ad.pt"}
    info = {}
    nets = {}
    for name, y, yv, loss, zero, width in (
        ("dd", yd, ydv, dd_loss, False, hidden),
        ("ad", ya_pair, yav_pair, ad_loss, True, hidden_ad),
    ):
        torch.manual_seed(seed)
        net = CompactNet(width, zero_last=zero)
        ts = time.perf_counter()
        path = out / files[name]
        info[name] = _fit(
            net,
            x,
            y,
            xv,
            yv,
            loss,
            epochs,
            batch,
            lr,
            patience,
            seed,
            functools.partial(save_net, hidden=width, path=path),
            progress,
            name.upper(),
        )
        info[name]["seconds"] = round(time.perf_counter() - ts, 1)
        save_net(net, width, path)
        nets[name] = net
    est = CompactEstimator(nets["dd"], nets["ad"], domain)
    pv = est.predict_intervals(va["la"], va["ra"], va["lb"], va["rb"])
    meta = {
        "estimator": "compact",
        "files": files,
        "architecture": f"DD {N_FEATURES}-{hidden}-{hidden}-1, "
        f"AD {N_FEATURES}-{hidden_ad}-{hidden_ad}-1, SiLU MLPs",
        "n_weights": est.n_weights,
        "data": {
            **domain.to_dict(),
            "mode": source,
            "n_train": n_train,
            "n_val": n_val,
            "train_seed": seed,
            "val_seed": seed + 1,
        },
        "training": {
            "epochs_max": epochs,
            "batch": batch,
            "lr": lr,
            "patience": patience,
            "optimizer": "Adam + one-cycle",
            "threads": threads,
            "dd_loss": "mean |r_hat/r - 1|",
            "ad_loss": "mean |phi_hat/phi - 1|",
            **{name: info[name] for name in info},
        },
        "train_seconds": round(time.perf_counter() - t0, 1),
        "generate_seconds": round(t_gen, 1),
        "val_metrics": {
            "dd": metrics.summary(va["r"], pv.r),
            "ad": metrics.summary(va["phi"], pv.phi),
        },
        "torch": torch.__version__,
        "command": command,
        "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
    }
    text = json.dumps(meta, indent=2)
    write_atomic(out / "compact.json", lambda tmp: Path(tmp).write_text(text))
    return meta


def fit(
    data: Dataset | str | os.PathLike | None = None,
    out_dir: str | os.PathLike | None = None,
    *,
    domain: Domain | None = None,
    n: int = 1_000_000,
    n_val: int = 100_000,
    seed: int = 0,
    epochs: int = 12,
    hidden: int = 32,
    hidden_ad: int = 8,
    patience: int = 3,
    threads: int = 2,
    command: str | None = None,
    progress: Callable[[str, int, int, float], None] | None = None,
) -> Path:
    """The registry's training shape: train on ``data`` (a Dataset or a .csv/.npz path;
    None: generate ``n`` + ``n_val`` elements in ``domain``) into ``out_dir`` (default the
    user models directory), staged then swapped in. Returns the directory for ``load``."""

    for k, v in (("hidden", hidden), ("hidden_ad", hidden_ad)):
        check_int(k, v, ge=1, le=limits.MAX_HIDDEN)  # what load() reads back
    check_int("patience", patience, ge=1)
    threads = check_int("threads", threads, ge=1, le=MAX_THREADS)
    dom = PAPER_DOMAIN if domain is None else domain
    if isinstance(data, str | os.PathLike):
        from eyeviz import dataset

        data = dataset.load(data, dom.eyes)
    out = Path(out_dir) if out_dir is not None else user_models_dir()
    train(
        out,
        n,
        n_val,
        seed,
        epochs,
        hidden,
        hidden_ad,
        patience=patience,
        domain=dom,
        threads=threads,
        command=command,
        progress=progress,
        data=data,
    )
    return out
