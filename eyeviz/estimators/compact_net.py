"""The compact estimator itself: its 11 features, its network and its estimator class.

Shared by loading (:mod:`eyeviz.estimators.compact`) and training
(:mod:`eyeviz.estimators.compact_training`), which import it and not each other, so the
two form no import cycle (issue 20). The design of the features is described in
:mod:`eyeviz.estimators.compact`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import torch
from torch import nn

from eyeviz.estimators import analytic
from eyeviz.estimators.base import PAPER_DOMAIN, Domain, Estimator
from eyeviz.files.atomic import atomic_output

__all__ = [
    "AD_SCALE",
    "N_FEATURES",
    "CompactEstimator",
    "CompactNet",
    "count_weights",
    "features",
    "save_net",
    "write_atomic",
]

N_FEATURES = 11
AD_SCALE = 1e-3  # radians per unit of the AD network's output


def features(
    LA: np.ndarray, RA: np.ndarray, LB: np.ndarray, RB: np.ndarray, domain: Domain = PAPER_DOMAIN
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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
            last = self.net[-1]
            assert isinstance(last, nn.Linear)
            nn.init.zeros_(last.weight)
            nn.init.zeros_(last.bias)

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

    def _predict_intervals(
        self, LA: np.ndarray, RA: np.ndarray, LB: np.ndarray, RB: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
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


def write_atomic(path: Path, write: Callable[[str], object]) -> None:
    """``write(tmp)`` into a temporary file beside ``path``, renamed over it at the end."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(path) as tmp:
        write(str(tmp))


def save_net(net: CompactNet, hidden: int, path: Path) -> None:
    """One network as ``{"hidden": hidden, "state": {name: tensor}}`` (what load reads)."""
    weights = {k: v.detach().clone() for k, v in net.state_dict().items()}
    state = {"hidden": hidden, "state": weights}
    write_atomic(path, lambda tmp: torch.save(state, tmp))
