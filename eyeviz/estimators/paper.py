"""The paper's AD and DD networks (Section 5, Figure 13, Appendix A/B), in torch.

AD (azimuth): Dense(720) relu -> 5760 tanh -> 6480 tanh -> 2880 relu -> 1 (60.6 M weights).
DD (distance): Dense(720) relu -> 5040 sigmoid -> 3600 relu -> 2880 relu -> 1 (33.3 M weights).
Both read the 720 bits (Omega_A, Omega_B) of a dataset row and regress phi (radians) or r
with the MAE loss, as the Appendix's Keras code does. The Keras defaults that code relies on
are reproduced: Dense kernels glorot-uniform and biases zero; RMSprop with rho = 0.9 and
epsilon = 1e-7 inside the square root (TF's ApplyRMSProp); SGD learning-rate decay
``lr / (1 + decay * iterations)`` applied per batch.

Choices the paper leaves open (stated in the metadata of every trained net):

- AD learning rate: the Appendix code says 0.003, Table 5 says 0.004. The default is the
  Appendix (DESIGN.md §4: the code is the architecture); ``ad_lr`` selects the other.
- DD optimiser: ``SGD(learning_rate=0.001, decay=1e-5, nesterov=True)`` with Keras' default
  momentum 0. Keras' Nesterov update with momentum 0 is plain SGD, so that is what runs
  (torch refuses nesterov without momentum); ``dd_momentum`` > 0 gives torch's Nesterov SGD.
- Split: 80 % train / 20 % held out (``train_test_split(test_size=0.2)`` in the Appendix);
  the held-out part gives the metrics in the metadata.

Full training (100 and 80 epochs) takes hours on a GPU; :func:`train` trains each network
as far as a wall-clock budget allows and records the budget and the epochs reached.
The weights (about 243 MB and 133 MB in float32) are never committed to git; only the
metadata JSON is. Make them with ``eyeviz train paper --budget SECONDS``.

This module imports torch at import time: import it only when the paper nets are used.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import platform
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import torch
from torch import nn

from eyeviz import EyevizError
from eyeviz.estimators.base import PAPER_DOMAIN, Estimator
from eyeviz.resources import models_dir

__all__ = [
    "AD",
    "DD",
    "NetSpec",
    "KerasRMSprop",
    "build",
    "keras_init_",
    "make_optimizer",
    "train",
    "train_net",
    "weights_dirs",
    "find_weights",
    "load_net",
    "PaperEstimator",
    "load",
]

N_INPUTS = 720  # 360 ommatidia per eye, m = 720 (Table 3)
WEIGHTS_HINT = "eyeviz train paper --budget 600"


@dataclass(frozen=True)
class NetSpec:
    """One of the paper's networks: layers (units, activation) and its Keras training setup."""

    name: str  # "ad" or "dd"
    target: str  # dataset column it regresses: "phi" or "r"
    layers: tuple[tuple[int, str | None], ...]
    optimizer: str  # "rmsprop" or "sgd"
    lr: float
    batch_size: int
    paper_epochs: int
    decay: float = 0.0
    momentum: float = 0.0
    nesterov: bool = False
    notes: tuple[str, ...] = field(default=())


AD = NetSpec(
    name="ad",
    target="phi",
    layers=((720, "relu"), (5760, "tanh"), (6480, "tanh"), (2880, "relu"), (1, None)),
    optimizer="rmsprop",
    lr=0.003,
    batch_size=64,
    paper_epochs=100,
    notes=("Appendix A: RMSProp(learning_rate=0.003); Table 5 says 0.004",),
)

DD = NetSpec(
    name="dd",
    target="r",
    layers=((720, "relu"), (5040, "sigmoid"), (3600, "relu"), (2880, "relu"), (1, None)),
    optimizer="sgd",
    lr=0.001,
    batch_size=32,
    paper_epochs=80,
    decay=1e-5,
    momentum=0.0,
    nesterov=True,
    notes=(
        "Appendix B: SGD(learning_rate=0.001, decay=1e-5, nesterov=True), Keras momentum "
        "default 0: Nesterov with momentum 0 is plain SGD, which is what runs",
    ),
)

SPECS = {"ad": AD, "dd": DD}

_ACTIVATIONS = {"relu": nn.ReLU, "tanh": nn.Tanh, "sigmoid": nn.Sigmoid}


def build(spec: NetSpec, n_inputs: int = N_INPUTS) -> nn.Sequential:
    """The Sequential model of Appendix A/B: Dense + Activation per layer, Keras-initialised."""
    mods: list[nn.Module] = []
    width = n_inputs
    for units, act in spec.layers:
        mods.append(nn.Linear(width, units))
        if act is not None:
            mods.append(_ACTIVATIONS[act]())
        width = units
    net = nn.Sequential(*mods)
    keras_init_(net)
    return net


def keras_init_(net: nn.Module) -> nn.Module:
    """Keras Dense defaults: glorot-uniform kernel, zero bias."""
    for mod in net.modules():
        if isinstance(mod, nn.Linear):
            nn.init.xavier_uniform_(mod.weight)
            nn.init.zeros_(mod.bias)
    return net


def count_weights(net: nn.Module) -> int:
    return int(sum(p.numel() for p in net.parameters()))


class KerasRMSprop(torch.optim.Optimizer):
    """RMSprop as Keras/TF apply it: ``ms = rho*ms + (1-rho)*g^2; p -= lr*g/sqrt(ms + eps)``.

    torch's RMSprop adds eps outside the square root; with eps = 1e-7 that differs where
    ms is tiny (the first steps of rarely active weights), so the TF form is used here.
    """

    def __init__(self, params, lr: float = 0.001, rho: float = 0.9, eps: float = 1e-7):
        if lr <= 0 or not 0 <= rho < 1 or eps < 0:
            raise ValueError(f"bad RMSprop hyper-parameters lr={lr}, rho={rho}, eps={eps}")
        super().__init__(params, dict(lr=lr, rho=rho, eps=eps))

    @torch.no_grad()
    def step(self, closure=None):
        loss = None
        if closure is not None:
            with torch.enable_grad():
                loss = closure()
        for group in self.param_groups:
            lr, rho, eps = group["lr"], group["rho"], group["eps"]
            for p in group["params"]:
                if p.grad is None:
                    continue
                state = self.state[p]
                if not state:
                    state["ms"] = torch.zeros_like(p)
                ms = state["ms"]
                ms.mul_(rho).addcmul_(p.grad, p.grad, value=1 - rho)
                p.addcdiv_(p.grad, ms.add(eps).sqrt_(), value=-lr)
        return loss


def make_optimizer(spec: NetSpec, params, lr: float | None = None):
    """(optimizer, per-batch scheduler or None) as the Appendix compiles them."""
    lr = spec.lr if lr is None else lr
    if spec.optimizer == "rmsprop":
        return KerasRMSprop(params, lr=lr, rho=0.9, eps=1e-7), None
    if spec.optimizer == "sgd":
        nesterov = spec.nesterov and spec.momentum > 0
        opt = torch.optim.SGD(params, lr=lr, momentum=spec.momentum, nesterov=nesterov)
        decay = spec.decay
        sched = torch.optim.lr_scheduler.LambdaLR(opt, lambda it: 1.0 / (1.0 + decay * it))
        return opt, sched
    raise ValueError(f"unknown optimizer {spec.optimizer!r}")


# --- data ---------------------------------------------------------------------------------


def _columns(data) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(X uint8 (n, 720), r, phi, g) from a dataset object, mapping or 5-tuple."""
    if isinstance(data, (tuple, list)):
        oa, ob, r, phi, g = data
    elif isinstance(data, dict):
        oa, ob, r, phi, g = (data[k] for k in ("omega_a", "omega_b", "r", "phi", "g"))
    else:
        oa, ob, r, phi, g = (getattr(data, k) for k in ("omega_a", "omega_b", "r", "phi", "g"))
    oa, ob = np.asarray(oa), np.asarray(ob)
    if oa.ndim != 2 or oa.shape != ob.shape or oa.shape[1] * 2 != N_INPUTS:
        raise ValueError(
            f"the paper nets need bitmaps of shape (n, {N_INPUTS // 2}) per eye (m = 720), "
            f"got {oa.shape} and {ob.shape}"
        )
    x = np.concatenate([oa, ob], axis=1).astype(np.uint8)
    as_f = [np.asarray(v, dtype=np.float64).reshape(-1) for v in (r, phi, g)]
    return x, *as_f


def _metrics(y: np.ndarray, yhat: np.ndarray) -> dict[str, float]:
    """MAPE (Eq. 34), MAE (Eq. 33), standard R^2 (DESIGN.md §4); NaN if the net diverged."""
    from eyeviz.estimators import metrics

    if not np.all(np.isfinite(yhat)):
        return {"mape": float("nan"), "mae": float("nan"), "r2": float("nan")}
    return metrics.summary(y, yhat)


@torch.no_grad()
def predict_net(
    net: nn.Module, x: np.ndarray, device: str = "cpu", batch: int = 4096
) -> np.ndarray:
    """Run a net on uint8/bool/float inputs (n, 720); float64 output (n,)."""
    net.eval()
    out = np.empty(len(x), dtype=np.float64)
    for i in range(0, len(x), batch):
        xb = torch.as_tensor(np.asarray(x[i : i + batch], dtype=np.float32), device=device)
        out[i : i + batch] = net(xb).reshape(-1).double().cpu().numpy()
    return out


# --- files --------------------------------------------------------------------------------


def _repo_dir() -> Path:
    return models_dir() / "paper"


def _cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "eyeviz" / "models" / "paper"


def weights_dirs() -> list[Path]:
    """Where the weights are looked for: $EYEVIZ_PAPER_DIR alone when it is set, else
    assets/models/paper/ in the source tree, then the user cache (~/.cache/eyeviz/...)."""
    env = os.environ.get("EYEVIZ_PAPER_DIR")
    if env:
        return [Path(env)]
    return [_repo_dir(), _cache_dir()]


def default_out_dir() -> Path:
    """assets/models/paper/ in a writable source checkout, else the user cache directory."""
    env = os.environ.get("EYEVIZ_PAPER_DIR")
    if env:
        return Path(env)
    repo = _repo_dir()
    if repo.is_dir() and os.access(repo, os.W_OK):
        return repo
    return _cache_dir()


def find_weights(name: str, path: str | os.PathLike | None = None) -> Path:
    """The ``<name>.pt`` weights file; one-line error naming the command that makes it."""
    dirs = [Path(path)] if path is not None else weights_dirs()
    for d in dirs:
        f = d / f"{name}.pt"
        if f.is_file():
            return f
    where = ", ".join(str(d) for d in dirs)
    raise EyevizError(
        f"paper network weights {name}.pt not found (looked in {where}); "
        f"make them with `{WEIGHTS_HINT}` (weights are not shipped: ~243 MB + ~133 MB)"
    )


def _atomic_write(path: Path, write) -> None:
    """``write(tmp)`` into a temporary file next to ``path``, then rename it over ``path``."""
    from eyeviz.files.atomic import atomic_output

    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(path) as tmp:
        write(str(tmp))


def _save_json(path: Path, obj: dict) -> None:
    def write(tmp):
        with open(tmp, "w", encoding="utf-8") as fh:
            json.dump(obj, fh, indent=2, sort_keys=False)
            fh.write("\n")

    _atomic_write(path, write)


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def load_net(name: str, path=None, device: str = "cpu") -> tuple[nn.Module, dict]:
    """(net, metadata) for "ad" or "dd"; metadata is {} when the JSON is missing."""
    spec = SPECS[name]
    f = find_weights(name, path)
    net = build(spec)
    try:
        state = torch.load(f, map_location=device, weights_only=True)
        net.load_state_dict(state["model"] if "model" in state else state)
    except Exception as exc:  # a truncated or foreign file: say which one
        raise ValueError(f"cannot read paper weights {f}: {type(exc).__name__}: {exc}") from None
    net.to(device).eval()
    meta_f = f.with_suffix(".json")
    meta = json.loads(meta_f.read_text()) if meta_f.is_file() else {}
    return net, meta


# --- training -----------------------------------------------------------------------------


def _resolve_device(device: str) -> str:
    if device not in ("cpu", "cuda") and not str(device).startswith("cuda:"):
        raise ValueError(f"device must be 'cpu' or 'cuda', got {device!r}")
    if device.startswith("cuda") and not torch.cuda.is_available():
        raise ValueError("device 'cuda' requested but torch sees no CUDA GPU; use --device cpu")
    return device


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
    info = {
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
    into ``out_dir`` (default: assets/models/paper/ in a checkout, else the user cache),
    each atomically. Returns the metadata per net.
    """
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


def _with(spec: NetSpec, **kw) -> NetSpec:
    d = asdict(spec)
    d.update(kw)
    d["layers"] = tuple(tuple(t) for t in d["layers"])
    d["notes"] = tuple(d["notes"])
    return NetSpec(**d)


def _optimizer_detail(spec: NetSpec, lr: float) -> str:
    if spec.optimizer == "rmsprop":
        return f"RMSprop lr={lr} rho=0.9 eps=1e-7 (inside sqrt, as TF/Keras)"
    if spec.momentum > 0:
        return f"SGD lr={lr} decay={spec.decay} (per batch) nesterov momentum={spec.momentum}"
    return (
        f"SGD lr={lr} decay={spec.decay} (per batch), momentum 0 "
        "(Keras SGD(nesterov=True) default momentum 0 = plain SGD)"
    )


# --- the estimator ------------------------------------------------------------------------


class PaperEstimator(Estimator):
    """The paper's AD (phi) and DD (r) networks behind the estimator protocol.

    Reads the raw 720 bits like the paper does. ``path`` is a directory holding ``ad.pt``
    and ``dd.pt`` (default: $EYEVIZ_PAPER_DIR, assets/models/paper/, the user cache).
    """

    name = "paper"
    uses_bitmaps = True

    def __init__(self, path: str | os.PathLike | None = None, device: str = "cpu") -> None:
        device = _resolve_device(device)
        self.device = device
        self.ad, meta_ad = load_net("ad", path, device)
        self.dd, meta_dd = load_net("dd", path, device)
        n = count_weights(self.ad) + count_weights(self.dd)
        train_s = [m.get("train_seconds") for m in (meta_ad, meta_dd)]
        super().__init__(
            PAPER_DOMAIN,
            {
                "n_weights": n,
                "train_seconds": sum(train_s) if None not in train_s else None,
                "ad": meta_ad,
                "dd": meta_dd,
                "label": "; ".join(m["label"] for m in (meta_ad, meta_dd) if "label" in m),
            },
        )

    def _predict_bitmaps(self, omega_a, omega_b) -> tuple[np.ndarray, np.ndarray]:
        x = np.concatenate([omega_a, omega_b], axis=1)
        with torch.inference_mode():
            phi = predict_net(self.ad, x, self.device)
            r = predict_net(self.dd, x, self.device)
        return r, phi


def load(path: str | os.PathLike | None = None, device: str = "cpu") -> PaperEstimator:
    """The trained paper nets; one-line error naming ``eyeviz train paper`` if absent."""
    return PaperEstimator(path, device)


# --- command line (``eyeviz train paper`` and ``python -m eyeviz.estimators.paper``) --------


if __name__ == "__main__":
    from eyeviz.cli import main

    sys.exit(main(["train", "paper", *sys.argv[1:]]))
