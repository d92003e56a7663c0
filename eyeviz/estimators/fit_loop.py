"""The training loop the learned estimators share: Adam with a one-cycle schedule over
shuffled mini-batches, early stopping on a validation loss, the best epoch's weights kept.
Used by the planar compact networks (:mod:`eyeviz.estimators.compact_training`) and the
learned 3D network (:mod:`eyeviz.estimators.learned3d_training`); each supplies its own
loss. Imports torch."""

from __future__ import annotations

import math
from collections.abc import Callable

import torch
from torch import nn

__all__ = ["fit_one_cycle"]


def fit_one_cycle(
    net: nn.Module,
    n: int,
    steps: int,
    batch: int,
    train_loss: Callable[[torch.Tensor], torch.Tensor],
    val_loss: Callable[[], float],
    *,
    epochs: int,
    lr: float,
    patience: int,
    min_delta: float,
    generator: torch.Generator,
    on_best: Callable[[], None] | None = None,
    progress: Callable[[str, int, int, float], None] | None = None,
    label: str = "",
) -> tuple[list[float], float]:
    """Train ``net`` in place; returns (the validation loss of every epoch run, the best).

    Each epoch draws a permutation of the ``n`` training rows from ``generator`` and takes
    ``steps`` batches of ``batch`` rows from it: ``train_loss(rows)`` is the batch's loss.
    After the epoch ``val_loss()`` is evaluated (eval mode, inference mode) and reported
    to ``progress(label, epoch, epochs, loss)``; a loss below the best by more than
    ``min_delta`` is the new best (its weights copied, ``on_best()`` called), and
    ``patience`` epochs in a row without one stop the loop. The best weights are loaded
    back at the end."""
    opt = torch.optim.Adam(net.parameters(), lr=lr)
    sched = torch.optim.lr_scheduler.OneCycleLR(opt, max_lr=lr, total_steps=epochs * steps)
    best, best_state, bad, history = math.inf, None, 0, []
    for ep in range(epochs):
        net.train()
        perm = torch.randperm(n, generator=generator)
        for i in range(steps):
            idx = perm[i * batch : (i + 1) * batch]
            opt.zero_grad(set_to_none=True)
            loss = train_loss(idx)
            loss.backward()
            opt.step()
            sched.step()
        net.eval()
        with torch.inference_mode():
            val = val_loss()
        history.append(val)
        if progress is not None:
            progress(label, ep + 1, epochs, val)
        if val < best - min_delta:
            best, bad = val, 0
            best_state = {k: v.detach().clone() for k, v in net.state_dict().items()}
            if on_best is not None:
                on_best()
        else:
            bad += 1
            if bad >= patience:
                break
    if best_state is not None:
        net.load_state_dict(best_state)
    return history, best
