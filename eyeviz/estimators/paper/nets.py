"""The paper's networks (Appendix A/B, Figure 13): layer specs, Keras initialisation and
the Keras optimisers (RMSprop with eps inside the root; SGD with per-batch decay).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import torch
from torch import nn

from eyeviz.core import paper

N_INPUTS = paper.M  # m / 2 = 360 ommatidia per eye, both eyes (Table 3)


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
