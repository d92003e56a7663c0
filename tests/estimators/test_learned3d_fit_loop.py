"""The training loop shared by learned3d and the planar compact networks
(``eyeviz.estimators.fit_loop``): early stopping, the best epoch's weights kept,
``on_best`` and ``progress`` called as documented."""

from __future__ import annotations

import torch

from eyeviz.estimators.fit_loop import fit_one_cycle


def test_stops_after_patience_and_keeps_the_best_epoch():
    torch.manual_seed(0)
    net = torch.nn.Linear(2, 1)
    x = torch.randn(64, 2)
    y = x @ torch.tensor([[1.0], [-2.0]])
    vals = iter([5.0, 3.0, 2.0, 2.0 - 1e-9, 4.0, 6.0, 1.0])  # the 1.0 is never reached
    snapshots, reports = [], []

    def val_loss():
        v = next(vals)
        snapshots.append({k: t.clone() for k, t in net.state_dict().items()})
        return v

    bests = []
    history, best = fit_one_cycle(
        net,
        64,
        4,
        16,
        lambda idx: ((net(x[idx]) - y[idx]) ** 2).mean(),
        val_loss,
        epochs=10,
        lr=1e-2,
        patience=3,
        min_delta=1e-6,
        generator=torch.Generator().manual_seed(1),
        on_best=lambda: bests.append(len(snapshots)),
        progress=lambda *a: reports.append(a),
        label="T",
    )
    # 2.0 - 1e-9 does not beat 2.0 by min_delta: three epochs without a new best
    assert history == [5.0, 3.0, 2.0, 2.0 - 1e-9, 4.0, 6.0]
    assert best == 2.0 and bests == [1, 2, 3]
    assert reports == [("T", i + 1, 10, v) for i, v in enumerate(history)]
    for k, t in net.state_dict().items():  # the weights of epoch 3 are back
        assert torch.equal(t, snapshots[2][k])
    assert not torch.equal(net.weight, snapshots[-1]["weight"])
