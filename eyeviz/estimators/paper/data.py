"""Data adapters (data set -> 720 input bits), the metrics of Eq. 33-34, batched inference
and the device check.
"""

from __future__ import annotations

import numpy as np
import torch
from torch import nn

from eyeviz.estimators.paper.nets import N_INPUTS


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
    r_f, phi_f, g_f = (np.asarray(v, dtype=np.float64).reshape(-1) for v in (r, phi, g))
    return x, r_f, phi_f, g_f


def _metrics(y: np.ndarray, yhat: np.ndarray) -> dict[str, float]:
    """MAPE (Eq. 34), MAE (Eq. 33), standard R^2 (docs/conventions.md); NaN if the net diverged."""
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


def _resolve_device(device: str) -> str:
    if device not in ("cpu", "cuda") and not str(device).startswith("cuda:"):
        raise ValueError(f"device must be 'cpu' or 'cuda', got {device!r}")
    if device.startswith("cuda") and not torch.cuda.is_available():
        raise ValueError("device 'cuda' requested but torch sees no CUDA GPU; use --device cpu")
    return device
