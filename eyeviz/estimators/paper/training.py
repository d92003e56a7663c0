"""The training loop of the paper's nets for a wall-clock budget, and :func:`fit`, the
registry's one training shape (staged, then swapped in; see :mod:`eyeviz.estimators.store`).
"""

from __future__ import annotations

import math
import os
import platform
import sys
import time
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from eyeviz.core.bounds import MAX_LR, MAX_THREADS
from eyeviz.core.validation import check_int, check_real
from eyeviz.estimators.paper.data import _columns, _metrics, _resolve_device, predict_net
from eyeviz.estimators.paper.nets import (
    SPECS,
    NetSpec,
    _optimizer_detail,
    _with,
    build,
    count_weights,
    make_optimizer,
)
from eyeviz.estimators.paper.weights import _atomic_write, _save_json, _sha256, default_out_dir
from eyeviz.estimators.store import staged


# long: one training loop with its budget, early stop and logging, sharing the run's locals
def train_net(
    spec: NetSpec,
    x: np.ndarray,
    y: np.ndarray,
    *,
    budget_seconds: float,
    device: str = "cpu",
    seed: int = 0,
    lr: float | None = None,
    max_epochs: int | None = None,
    val: tuple[np.ndarray, np.ndarray] | None = None,
    eval_max: int = 20000,
    checkpoint: Path | None = None,
    progress: bool = True,
) -> tuple[nn.Module, dict]:
    """Train one net on (x, y) until the wall-clock budget or ``max_epochs`` runs out.

    The budget covers the optimisation steps only (data shuffling, forward, backward,
    update); the held-out evaluation and the checkpoint writes are timed separately.
    Returns (net, info) where info records epochs reached (fractional), steps, samples
    seen, seconds, the learning rate and the held-out metrics.
    """
    device = _resolve_device(device)
    torch.manual_seed(seed)
    net = build(spec).to(device)
    opt, sched = make_optimizer(spec, net.parameters(), lr)
    loss_fn = nn.L1Loss()  # loss='mae'
    max_epochs = spec.paper_epochs if max_epochs is None else max_epochs
    n, bs = len(x), spec.batch_size
    steps_per_epoch = math.ceil(n / bs)
    gen = torch.Generator().manual_seed(seed)
    xt = torch.as_tensor(x)  # uint8, converted per batch
    yt = torch.as_tensor(np.asarray(y, dtype=np.float32)).reshape(-1, 1)

    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(
            total=int(budget_seconds),
            unit="s",
            desc=f"paper {spec.name}",
            leave=False,
            bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.0f}/{total} s {postfix}",
        )
    steps = 0
    epoch = 0
    seen = 0
    loss_ema = float("nan")
    elapsed = 0.0
    ckpt_seconds = 0.0
    t0 = time.perf_counter()
    out_of_time = False
    net.train()
    while epoch < max_epochs and not out_of_time:
        order = torch.randperm(n, generator=gen)  # Keras fit(shuffle=True)
        done_in_epoch = 0
        for i in range(0, n, bs):
            idx = order[i : i + bs]
            xb = xt[idx].to(device=device, dtype=torch.float32)
            yb = yt[idx].to(device)
            opt.zero_grad(set_to_none=True)
            loss = loss_fn(net(xb), yb)
            loss.backward()
            opt.step()
            if sched is not None:
                sched.step()
            steps += 1
            seen += len(idx)
            done_in_epoch += len(idx)
            lv = loss.item()
            loss_ema = lv if math.isnan(loss_ema) else 0.98 * loss_ema + 0.02 * lv
            elapsed = time.perf_counter() - t0 - ckpt_seconds
            if bar is not None and (steps % 5 == 0 or elapsed >= budget_seconds):
                bar.n = min(elapsed, budget_seconds)
                bar.set_postfix_str(f"epoch {seen / n:.2f} loss {loss_ema:.4g}", refresh=False)
                bar.refresh()
            if elapsed >= budget_seconds:
                out_of_time = True
                break
        if done_in_epoch == n:
            epoch += 1
            if checkpoint is not None and not out_of_time and epoch < max_epochs:
                tc = time.perf_counter()
                _atomic_write(checkpoint, lambda tmp: torch.save({"model": net.state_dict()}, tmp))
                ckpt_seconds += time.perf_counter() - tc
    if bar is not None:
        bar.close()
    info: dict[str, Any] = {
        "train_seconds": round(elapsed, 2),
        "epochs_reached": round(seen / n, 4),
        "full_epochs": epoch,
        "steps": steps,
        "steps_per_epoch": steps_per_epoch,
        "samples_seen": seen,
        "stopped_by": "budget" if out_of_time else "epochs",
        "final_train_loss_ema": loss_ema,
        "lr": spec.lr if lr is None else lr,
        "lr_final": float(opt.param_groups[0]["lr"]),
    }
    if val is not None:
        xv, yv = val
        xv, yv = xv[:eval_max], np.asarray(yv[:eval_max], dtype=np.float64)
        te = time.perf_counter()
        pred = predict_net(net, xv, device)
        info["eval_seconds"] = round(time.perf_counter() - te, 2)
        info["heldout"] = {"n": int(len(yv)), **_metrics(yv, pred)}
    return net, info


def train(
    data,
    budget_seconds: float,
    device: str = "cpu",
    out_dir: str | os.PathLike | None = None,
    seed: int = 0,
    *,
    nets: tuple[str, ...] = ("ad", "dd"),
    ad_lr: float | None = None,
    dd_momentum: float | None = None,
    tag: str = "",
    max_epochs: int | None = None,
    eval_max: int = 20000,
    data_params: dict | None = None,
    command: str | None = None,
    progress: bool = True,
) -> dict[str, dict]:
    """Train the paper's nets, each for ``budget_seconds`` of wall clock, and save them.

    Writes ``<net><tag>.pt`` (weights; never commit them) and ``<net><tag>.json``
    (metadata: budget, epochs reached, held-out metrics, hyper-parameters, data, command)
    into ``out_dir`` (default: $EYEVIZ_PAPER_DIR, else <user models>/paper; never the
    shipped assets unless ``out_dir`` names them). Everything is written into a staging
    directory first and moved into ``out_dir`` only at the end (:func:`staged`), so an
    interruption leaves the previous nets and their metadata as they were.
    Returns the metadata per net.
    """
    if ad_lr is not None:
        ad_lr = check_real("ad_lr", ad_lr, gt=0, le=MAX_LR)
    if dd_momentum is not None:
        dd_momentum = check_real("dd_momentum", dd_momentum, ge=0, lt=1)
    try:
        budget_seconds = float(budget_seconds)
    except (TypeError, ValueError):
        raise ValueError(f"budget must be a number of seconds, got {budget_seconds!r}") from None
    if not math.isfinite(budget_seconds) or budget_seconds <= 0:
        raise ValueError(f"budget must be > 0 seconds, got {budget_seconds!r}")
    bad = [k for k in nets if k not in SPECS]
    if bad or not nets:
        raise ValueError(f"nets must be a subset of ('ad', 'dd'), got {nets!r}")
    device = _resolve_device(device)
    out = Path(out_dir) if out_dir is not None else default_out_dir()
    x, r, phi, g = _columns(data)
    if len(x) < 10:
        raise ValueError(f"need at least 10 samples to train, got {len(x)}")
    with staged(out) as stage:
        return _train_into(
            stage,
            x,
            r,
            phi,
            budget_seconds,
            device,
            seed,
            nets,
            ad_lr,
            dd_momentum,
            tag,
            max_epochs,
            eval_max,
            data_params,
            command,
            progress,
        )


# long: one training run in order (data, networks, loop, files), sharing the run's locals
def _train_into(
    out: Path,
    x,
    r,
    phi,
    budget_seconds,
    device,
    seed,
    nets,
    ad_lr,
    dd_momentum,
    tag,
    max_epochs,
    eval_max,
    data_params,
    command,
    progress,
) -> dict[str, dict]:
    """The body of :func:`train`, writing into the staging directory ``out``."""
    rng = np.random.default_rng(seed)
    perm = rng.permutation(len(x))
    n_val = max(1, int(round(0.2 * len(x))))  # train_test_split(test_size=0.2)
    tr, va = perm[n_val:], perm[:n_val]
    targets = {"r": r, "phi": phi}
    results = {}
    for name in nets:
        spec = SPECS[name]
        if name == "dd" and dd_momentum is not None:
            spec = _with(spec, momentum=float(dd_momentum))
        y = targets[spec.target]
        wfile = out / f"{name}{tag}.pt"
        net, info = train_net(
            spec,
            x[tr],
            y[tr],
            budget_seconds=budget_seconds,
            device=device,
            seed=seed,
            lr=ad_lr if name == "ad" else None,
            max_epochs=max_epochs,
            val=(x[va], y[va]),
            eval_max=eval_max,
            checkpoint=wfile,
            progress=progress,
        )
        label = (
            f"paper {name.upper()} after {info['epochs_reached']:.2f} of "
            f"{spec.paper_epochs} epochs ({budget_seconds:.0f} s budget on {device})"
        )
        cpu_state = {k: v.detach().cpu() for k, v in net.state_dict().items()}
        tagged = {
            "model": cpu_state,
            "label": label,
            "budget_seconds": budget_seconds,
            "epochs_reached": info["epochs_reached"],
        }
        _atomic_write(wfile, lambda tmp, t=tagged: torch.save(t, tmp))
        meta = {
            "estimator": "paper",
            "net": name,
            "target": spec.target,
            "label": label,
            "budget_seconds": budget_seconds,
            **info,
            "paper_epochs": spec.paper_epochs,
            "weights_file": wfile.name,
            "weights_bytes": wfile.stat().st_size,
            "weights_sha256": _sha256(wfile),
            "weight_count": count_weights(net),
            "spec": {k: v for k, v in asdict(spec).items()},
            "loss": "mae",
            "init": "glorot_uniform kernels, zero biases (Keras Dense defaults)",
            "optimizer_detail": _optimizer_detail(spec, info["lr"]),
            "split": {"train": int(len(tr)), "heldout": int(len(va)), "seed": seed},
            "data": data_params or {},
            "seed": seed,
            "device": device,
            "torch_threads": torch.get_num_threads(),
            "torch": torch.__version__,
            "python": sys.version.split()[0],
            "machine": platform.machine(),
            "command": command,
            "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        }
        _save_json(out / f"{name}{tag}.json", meta)
        results[name] = meta
    return results


def fit(
    data=None,
    out_dir: str | os.PathLike | None = None,
    *,
    domain=None,
    n: int = 100_000,
    mode: str = "single",
    seed: int = 0,
    budget: float = 600.0,
    device: str = "cpu",
    nets: tuple[str, ...] | str = ("ad", "dd"),
    ad_lr: float | None = None,
    dd_momentum: float | None = None,
    tag: str = "",
    threads: int | None = None,
    max_epochs: int | None = None,
    command: str | None = None,
    progress: bool = True,
) -> Path:
    """The registry's training shape: train on ``data`` (a Dataset or a .csv/.npz path;
    None: generate ``n`` elements of Algorithm 1 in ``domain``) into ``out_dir``, staged
    then swapped in. Returns the directory to pass to ``load(path=...)``."""
    from eyeviz import dataset
    from eyeviz.core.domain import PAPER_DOMAIN

    dom = PAPER_DOMAIN if domain is None else domain
    if isinstance(nets, str):
        nets = tuple(s.strip() for s in nets.split(",") if s.strip())
    if ad_lr is not None:
        ad_lr = check_real("ad_lr", ad_lr, gt=0, le=MAX_LR)
    budget = check_real("budget", budget, gt=0)
    if threads is not None:
        torch.set_num_threads(check_int("threads", threads, ge=1, le=MAX_THREADS))
    if data is None:
        n = check_int("n", n, ge=10)
        data = dataset.generate(n, dom.eyes, dom.r_min, dom.r_max, dom.g_max, mode, seed)
        params = {**dom.to_dict(), "n": n, "mode": mode, "seed": seed}
    elif isinstance(data, str | os.PathLike):
        params = {"file": str(data)}
        data = dataset.load(data, dom.eyes)
    else:
        params = dict(getattr(data, "params", {}) or {})
    out = Path(out_dir) if out_dir is not None else default_out_dir()
    train(
        data,
        budget,
        device,
        out,
        seed,
        nets=tuple(nets),
        ad_lr=ad_lr,
        dd_momentum=dd_momentum,
        tag=tag,
        max_epochs=max_epochs,
        data_params=params,
        command=command,
        progress=progress,
    )
    return out
