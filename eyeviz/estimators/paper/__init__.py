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
  Appendix (docs/conventions.md: the code is the architecture); ``ad_lr`` selects the other.
- DD optimiser: ``SGD(learning_rate=0.001, decay=1e-5, nesterov=True)`` with Keras' default
  momentum 0. Keras' Nesterov update with momentum 0 is plain SGD, so that is what runs
  (torch refuses nesterov without momentum); ``dd_momentum`` > 0 gives torch's Nesterov SGD.
- Split: 80 % train / 20 % held out (``train_test_split(test_size=0.2)`` in the Appendix);
  the held-out part gives the metrics in the metadata.

Full training (100 and 80 epochs) takes hours on a GPU; :func:`train` trains each network
as far as a wall-clock budget allows and records the budget and the epochs reached.
The weights (about 243 MB and 133 MB in float32) are never committed to git; only the
metadata JSON is. Make them with ``eyeviz train paper --budget SECONDS``.

Modules, one job each: :mod:`.nets` (specs, Keras init and optimisers), :mod:`.data`
(adapters, metrics, inference), :mod:`.weights` (files), :mod:`.training` (loop, ``train``,
``fit``), :mod:`.estimator` (``PaperEstimator``, ``load``). This package imports torch at
import time: import it only when the paper nets are used.
"""

from __future__ import annotations

from eyeviz.estimators.paper.data import _columns, _metrics, _resolve_device, predict_net
from eyeviz.estimators.paper.estimator import PaperEstimator, load
from eyeviz.estimators.paper.nets import (
    AD,
    DD,
    N_INPUTS,
    SPECS,
    KerasRMSprop,
    NetSpec,
    _optimizer_detail,
    _with,
    build,
    count_weights,
    keras_init_,
    make_optimizer,
)
from eyeviz.estimators.paper.training import fit, train, train_net
from eyeviz.estimators.paper.weights import (
    WEIGHTS_HINT,
    default_out_dir,
    find_weights,
    load_net,
    weights_dirs,
)

__all__ = [
    "AD",
    "DD",
    "N_INPUTS",
    "SPECS",
    "NetSpec",
    "KerasRMSprop",
    "build",
    "keras_init_",
    "count_weights",
    "make_optimizer",
    "predict_net",
    "train",
    "train_net",
    "fit",
    "weights_dirs",
    "default_out_dir",
    "find_weights",
    "load_net",
    "WEIGHTS_HINT",
    "PaperEstimator",
    "load",
    "_columns",
    "_metrics",
    "_resolve_device",
    "_optimizer_detail",
    "_with",
]
