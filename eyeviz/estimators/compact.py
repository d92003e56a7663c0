"""Compact networks: two tiny MLPs on features of the four lit-interval integers.

A bitmap pair is fully described by (LA, RA, LB, RB) (Prop. 2), so instead of the
paper's 720 bits (Appendix A/B, 60 M and 33 M weights) each network reads 11 numbers
derived from them: the edge disparities LB - LA and RB - RA (the stereo cue for distance),
the widths and their logs (the size cue), the mean centre angle, and the analytic
triangulation itself (:mod:`eyeviz.estimators.analytic`). Each network predicts a
correction to the triangulation:

- DD: log r = log r_analytic + f(x), trained on the relative error |r_hat / r - 1|
  (the MAPE of Eq. 34), so it learns the 1/r-weighted posterior median;
- AD: phi = phi_analytic + 1e-3 * f(x), trained on |phi_hat / phi - 1|; its last layer
  starts at zero, so training starts from the triangulation.

Weights: ``assets/models/compact_dd.pt`` and ``compact_ad.pt`` (a few kB each) with
``compact.json`` (data parameters, seed, metrics, training time, command).
This is the only estimator module besides ``paper`` that imports torch.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import torch
from torch import nn

from eyeviz import EyevizError
from eyeviz.core.validation import check_int, check_real
from eyeviz.estimators import analytic
from eyeviz.estimators.base import PAPER_DOMAIN, Domain, Estimator
from eyeviz.estimators.store import staged, user_models_dir
from eyeviz.files.atomic import atomic_output
from eyeviz.resources import models_dir

__all__ = ["CompactEstimator", "CompactNet", "features", "load", "train", "default_dir"]

N_FEATURES = 11
AD_SCALE = 1e-3  # radians per unit of the AD network's output


def default_dir() -> Path:
    return models_dir()


def features(LA, RA, LB, RB, domain: Domain = PAPER_DOMAIN):
    """(X float32 (N, 11), log r_analytic, phi_analytic) from interval arrays."""
    la, ra, lb, rb = (np.asarray(v, np.float64) for v in (LA, RA, LB, RB))
    gam = 2.0 * math.pi / domain.m
    wa = ra - la + 1.0
    wb = rb - lb + 1.0
    dl = lb - la
    dr = rb - ra
    c = (la + ra + lb + rb + 2.0) * (0.25 * gam)
    r0, p0 = analytic.estimate(la, ra, lb, rb, domain)
    log_r0 = np.log(r0)
    x = np.empty((la.shape[0], N_FEATURES), np.float32)
    x[:, 0] = dl * 0.25
    x[:, 1] = dr * 0.25
    x[:, 2] = (wb - wa) * 0.5
    x[:, 3] = np.log(wa) - 3.0
    x[:, 4] = np.log(wb) - 3.0
    x[:, 5] = c - 0.5 * math.pi
    x[:, 6] = np.sin(c) - 0.8
    x[:, 7] = log_r0 - math.log(math.sqrt(domain.r_min * domain.r_max))
    x[:, 8] = 1.0 / (0.5 * (dl + dr) + 1.0)
    x[:, 9] = 1.0 / (dl + 1.5)
    x[:, 10] = 1.0 / (dr + 1.5)
    return x, log_r0, p0


class CompactNet(nn.Module):
    """Linear(11, H) - SiLU - Linear(H, H) - SiLU - Linear(H, 1)."""

    def __init__(self, hidden: int = 32, zero_last: bool = False) -> None:
        super().__init__()
        self.net = nn.Sequential(
            nn.Linear(N_FEATURES, hidden),
            nn.SiLU(),
            nn.Linear(hidden, hidden),
            nn.SiLU(),
            nn.Linear(hidden, 1),
        )
        if zero_last:
            nn.init.zeros_(self.net[-1].weight)
            nn.init.zeros_(self.net[-1].bias)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.net(x).squeeze(-1)


def count_weights(net: nn.Module) -> int:
    return sum(p.numel() for p in net.parameters())


class CompactEstimator(Estimator):
    name = "compact"

    def __init__(
        self,
        dd: CompactNet,
        ad: CompactNet,
        domain: Domain = PAPER_DOMAIN,
        metadata: dict | None = None,
    ) -> None:
        meta = dict(metadata or {})
        meta["n_weights"] = count_weights(dd) + count_weights(ad)
        super().__init__(domain, meta)
        self.dd = dd.eval()
        self.ad = ad.eval()

    def _predict_intervals(self, LA, RA, LB, RB):
        x, log_r0, p0 = features(LA, RA, LB, RB, self.domain)
        # Blocks of <= 65536 rows through nets this small run fastest on one thread:
        # the intra-op thread pool costs more in synchronisation than it saves.
        threads = torch.get_num_threads()
        if threads != 1:
            torch.set_num_threads(1)
        try:
            with torch.inference_mode():
                xt = torch.from_numpy(x)
                d = self.dd(xt).numpy()
                a = self.ad(xt).numpy()
        finally:
            if threads != 1:
                torch.set_num_threads(threads)
        return np.exp(log_r0 + d), p0 + AD_SCALE * a


def _atomic(path: Path, write: Callable[[str], None]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(path) as tmp:
        write(str(tmp))


def _save_net(net: CompactNet, hidden: int, path: Path) -> None:
    weights = {k: v.detach().clone() for k, v in net.state_dict().items()}
    state = {"hidden": hidden, "state": weights}
    _atomic(path, lambda tmp: torch.save(state, tmp))


def _load_net(path: Path) -> CompactNet:
    obj = torch.load(path, map_location="cpu", weights_only=True)
    net = CompactNet(int(obj["hidden"]))
    net.load_state_dict(obj["state"])
    return net


def load(path=None, domain: Domain | None = None) -> CompactEstimator:
    """Weights from ``path`` (a directory with compact.json), default assets/models/."""
    d = Path(path) if path is not None else default_dir()
    meta_f = d / "compact.json"
    if not meta_f.is_file():
        raise ValueError(
            f"compact weights not found in {d} (no compact.json); "
            f"train them with `eyeviz train compact -o {d}`"
        )
    meta = json.loads(meta_f.read_text())
    try:
        dd = _load_net(d / meta["files"]["dd"])
        ad = _load_net(d / meta["files"]["ad"])
    except (OSError, KeyError, RuntimeError) as exc:
        raise ValueError(f"cannot load compact weights from {d}: {exc}") from None
    dom = domain or Domain.from_dict(meta["data"])
    return CompactEstimator(dd, ad, dom, meta)


# --- training ------------------------------------------------------------------------------


def _generate(n: int, domain: Domain, seed: int, mode: str = "single"):
    from eyeviz import dataset

    p = dataset.make_params(domain.eyes, domain.r_min, domain.r_max, domain.g_max, mode, seed)
    chunks = list(dataset.iter_chunks(n, p, chunk=1 << 17))
    return {
        k: np.concatenate([getattr(c, k) for c in chunks])
        for k in ("r", "phi", "la", "ra", "lb", "rb")
    }


def _fit(
    net: CompactNet,
    x,
    y,
    xv,
    yv,
    predict: Callable,
    epochs: int,
    batch: int,
    lr: float,
    patience: int,
    seed: int,
    ckpt: Callable[[CompactNet], None],
    progress: Callable[[str, int, int, float], None] | None,
    label: str,
) -> dict:
    """Adam with a one-cycle schedule on the relative error; early stopping on validation."""
    g = torch.Generator().manual_seed(seed)
    n = x.shape[0]
    steps = n // batch
    opt = torch.optim.Adam(net.parameters(), lr=lr)
    sched = torch.optim.lr_scheduler.OneCycleLR(opt, max_lr=lr, total_steps=epochs * steps)
    best, best_state, bad, history = math.inf, None, 0, []
    for ep in range(epochs):
        net.train()
        perm = torch.randperm(n, generator=g)
        for i in range(steps):
            idx = perm[i * batch : (i + 1) * batch]
            opt.zero_grad(set_to_none=True)
            loss = predict(net(x[idx]), y[idx])
            loss.backward()
            opt.step()
            sched.step()
        net.eval()
        with torch.inference_mode():
            val = float(predict(net(xv), yv))
        history.append(val)
        if progress is not None:
            progress(label, ep + 1, epochs, val)
        if val < best - 1e-7:
            best, bad = val, 0
            best_state = {k: v.detach().clone() for k, v in net.state_dict().items()}
            ckpt(net)
        else:
            bad += 1
            if bad >= patience:
                break
    if best_state is not None:
        net.load_state_dict(best_state)
    return {"epochs": len(history), "val_history": [round(v, 7) for v in history], "best_val": best}


def train(
    out_dir=None,
    n_train: int = 1_000_000,
    n_val: int = 100_000,
    seed: int = 0,
    epochs: int = 12,
    hidden: int = 32,
    hidden_ad: int = 8,
    batch: int = 4096,
    lr: float = 4e-3,
    patience: int = 3,
    domain: Domain = PAPER_DOMAIN,
    threads: int = 2,
    command: str | None = None,
    progress: Callable[[str, int, int, float], None] | None = None,
    data=None,
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
    n_train = check_int("n_train", n_train, ge=1)
    n_val = check_int("n_val", n_val, ge=1)
    epochs = check_int("epochs", epochs, ge=1)
    lr = check_real("lr", lr, gt=0)
    t0 = time.perf_counter()
    if data is None:
        if n_train < batch:
            raise EyevizError(
                f"-n must be >= {batch} (one batch of the one-cycle schedule), got {n_train}"
            )
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


def _split(data, seed: int, domain: Domain) -> tuple[dict, dict]:
    """Single-feature rows of a data set as interval columns, split 90/10 (seeded)."""
    from eyeviz.estimators.base import bitmaps_to_intervals

    if (data.eyes.h, data.eyes.l, data.eyes.m) != domain.design:
        raise EyevizError(
            f"data design h={data.eyes.h:g}, l={data.eyes.l:g}, m={data.eyes.m} differs from "
            f"the domain's h={domain.h:g}, l={domain.l:g}, m={domain.m}"
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


def _train_into(
    out: Path,
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
    source,
) -> dict:
    """The body of :func:`train`, writing into the staging directory ``out``."""
    torch.set_num_threads(threads)
    torch.manual_seed(seed)

    def prep(d):
        x, log_r0, p0 = features(d["la"], d["ra"], d["lb"], d["rb"], domain)
        return (
            torch.from_numpy(x),
            torch.from_numpy((np.log(d["r"]) - log_r0).astype(np.float32)),
            torch.from_numpy(((d["phi"] - p0) / AD_SCALE).astype(np.float32)),
            torch.from_numpy((d["phi"] / AD_SCALE).astype(np.float32)),
        )

    x, yd, ya, sa = prep(tr)
    xv, ydv, yav, sav = prep(va)

    def dd_loss(out, y):
        return (torch.exp(out - y) - 1.0).abs().mean()

    # AD: |phi_hat - phi| / phi with phi_hat - phi = AD_SCALE * (out - y)
    ya_pair = torch.stack([ya, sa], 1)
    yav_pair = torch.stack([yav, sav], 1)

    def ad_loss(out, y):
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
            lambda n_, p=path, w=width: _save_net(n_, w, p),
            progress,
            name.upper(),
        )
        info[name]["seconds"] = round(time.perf_counter() - ts, 1)
        _save_net(net, width, path)
        nets[name] = net
    est = CompactEstimator(nets["dd"], nets["ad"], domain)
    pv = est.predict_intervals(va["la"], va["ra"], va["lb"], va["rb"])
    from eyeviz.estimators import metrics

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
    _atomic(out / "compact.json", lambda tmp: Path(tmp).write_text(text))
    return meta


def fit(
    data=None,
    out_dir=None,
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
    import os

    for k, v in (("hidden", hidden), ("hidden_ad", hidden_ad), ("patience", patience)):
        check_int(k, v, ge=1)
    threads = check_int("threads", threads, ge=1)
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
