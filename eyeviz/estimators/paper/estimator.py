"""The paper's AD and DD networks behind the estimator protocol."""

from __future__ import annotations

import os

import numpy as np
import torch

from eyeviz.estimators.base import PAPER_DOMAIN, Estimator
from eyeviz.estimators.paper.data import _resolve_device, predict_net
from eyeviz.estimators.paper.nets import count_weights
from eyeviz.estimators.paper.weights import load_net


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
