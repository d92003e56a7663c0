#!/usr/bin/env python
"""Benchmark of the spherical limit's compiled kernels (issue 31 item 3: >= 500 keys/s at
nside 180; issue 33: >= 200 keys/s on the honeybee).

For each eye model, on the same fresh keys (Algorithm 1 in 3D, a seed no shipped model
used), in this run: limit3d ``predict`` with the kernels, and with the numpy reference
(``EYEVIZ_JIT=0``) as the baseline; keys/s of wall and of this process's CPU time, their
ratio, the target's ratio, and whether the answers are the reference's (to 1e-9 with the
accepted draws the same, or bit for bit). The 1-minute load average is
printed beside: on shared cores the wall figures count other jobs, the CPU ones less so.

With ``--before REV`` the same keys are also answered by the code of git revision REV
(``git archive`` into a temporary directory, run in a subprocess of this run, kernels
warmed first): its keys/s of CPU, the ratio, whether the accepted draws are the same, and
how far the answers moved in units of their stated Monte-Carlo error (z = the relative
difference of r, or of the azimuth, over the two errors in quadrature).

    .venv/bin/python scripts/bench_limit3d.py [--keys 40] [--ref-keys 16] [--which 180,32,bee]
                                              [--before REV]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: what the subprocess of ``--before`` runs: the keys from an npz, the answers back
_BEFORE = """
import sys, time
import numpy as np
from eyeviz.core import kernels
from eyeviz.core.domain import Domain3D
from eyeviz.estimators.limit3d import Limit3DEstimator
from eyeviz.files.eye_io import load_eyes, shipped_eye
kernels.warm()
f = np.load(sys.argv[1])
which = str(f["which"])
if which == "bee":
    d = Domain3D.for_eyes(load_eyes(shipped_eye("AM_60185-real.eye")))
else:
    d = Domain3D(nside=int(which))
la, lb = (f["pa"], f["ia"]), (f["pb"], f["ib"])
c0 = time.process_time()
p = Limit3DEstimator(d).predict(la, lb)
cpu = time.process_time() - c0
import eyeviz.estimators.limit3d as mod
np.savez(sys.argv[2], r=p.r, az=p.azimuth, mc=p.mc_error, acc=p.n_accepted, flag=p.flagged,
         cpu=cpu, module=mod.__file__)
"""


def run(est, la, lb):
    t0, c0 = time.perf_counter(), time.process_time()
    p = est.predict(la, lb)
    return p, time.perf_counter() - t0, time.process_time() - c0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    ap.add_argument("--keys", type=int, default=40, help="keys timed with the kernels")
    ap.add_argument("--ref-keys", type=int, default=16, help="of those, timed on the reference")
    ap.add_argument("--which", default="180,32,bee")
    ap.add_argument("--seed", type=int, default=7_310_551)
    ap.add_argument("--before", help="a git revision to answer the same keys (see above)")
    args = ap.parse_args(argv)

    import numpy as np

    # this checkout's eyeviz, not the one the venv's editable install points at (a
    # worktree sharing another checkout's venv would time that checkout's code)
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    import eyeviz
    from eyeviz.core import kernels
    from eyeviz.core.domain import Domain3D
    from eyeviz.dataset.algorithm1_3d import generate3d
    from eyeviz.estimators.base import take_rows
    from eyeviz.estimators.limit3d import Limit3DEstimator
    from eyeviz.files.eye_io import load_eyes, shipped_eye

    print(f"eyeviz from {Path(eyeviz.__file__).parent}")
    kernels.warm()
    for which in args.which.split(","):
        if which == "bee":
            d = Domain3D.for_eyes(load_eyes(shipped_eye("AM_60185-real.eye")))
            name, target = "honeybee (AM_60185)", 200.0
        else:
            d = Domain3D(nside=int(which))
            name, target = f"nside {which}", 500.0
        ds = generate3d(max(args.keys, 50), d, seed=args.seed)
        rows = np.arange(args.keys)
        la = take_rows(ds.indptr_a, ds.indices_a, rows)
        lb = take_rows(ds.indptr_b, ds.indices_b, rows)
        p, wall, cpu = run(Limit3DEstimator(d), la, lb)
        load = os.getloadavg()[0]
        k = args.ref_keys
        rate, rate_c = args.keys / wall, args.keys / cpu
        if k == 0:  # no reference run asked for: the kernels' rate only
            print(f"{name}: {args.keys} keys, load {load:.1f}")
            print(
                f"  kernels    {rate:8.1f} keys/s wall {rate_c:8.1f} keys/s CPU; target "
                f"{target:.0f}: {rate_c / target:.3g}x CPU; median accepted "
                f"{np.median(p.n_accepted):.0f}, flagged {int(p.flagged.sum())}"
            )
            if args.before:
                _before(args.before, which, la, lb, p, cpu)
            continue
        sa, sb = take_rows(*la, np.arange(k)), take_rows(*lb, np.arange(k))
        _, wall_k, cpu_k = run(Limit3DEstimator(d), sa, sb)  # the ratio's keys, same run
        os.environ["EYEVIZ_JIT"] = "0"
        try:
            q, wall_r, cpu_r = run(Limit3DEstimator(d), sa, sb)
        finally:
            del os.environ["EYEVIZ_JIT"]
        ref, ref_c = k / wall_r, k / cpu_r
        sub, sub_c = k / wall_k, k / cpu_k
        acc_same = np.array_equal(p.n_accepted[:k], q.n_accepted)
        # both models' set-up kernels round differently from numpy: the same accepted draws,
        # the answers to 1e-9 (bit for bit still said where they are)
        bits = np.array_equal(p.r[:k], q.r) and np.array_equal(p.elevation[:k], q.elevation)
        close = np.allclose(p.r[:k], q.r, rtol=1e-9) and acc_same
        same = "bit for bit" if bits and acc_same else "same to 1e-9" if close else "DIFFERENT"
        print(f"{name}: {args.keys} keys (the first {k} also on the reference), load {load:.1f}")
        print(f"  kernels    {rate:8.1f} keys/s wall {rate_c:8.1f} keys/s CPU")
        print(f"  reference  {ref:8.1f} keys/s wall {ref_c:8.1f} keys/s CPU")
        print(
            f"  ratio      {sub / ref:8.2f}x wall {sub_c / ref_c:8.2f}x CPU (same {k} keys); "
            f"target {target:.0f}: {rate / target:.3g}x wall, {rate_c / target:.3g}x CPU "
            f"({'met' if rate >= target else 'NOT met'}); answers {same}; median accepted "
            f"{np.median(p.n_accepted):.0f}, flagged {int(p.flagged.sum())}"
        )
        if args.before:
            _before(args.before, which, la, lb, p, cpu)
    return 0


def _before(rev: str, which: str, la, lb, p, cpu: float) -> None:
    """The same keys answered by revision ``rev`` in a subprocess: CPU keys/s, the ratio,
    the accepted draws and the answers' z-scores against this run's."""
    import numpy as np

    root = Path(__file__).resolve().parent.parent
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "src"
        src.mkdir()
        arc = subprocess.run(["git", "-C", str(root), "archive", rev], capture_output=True,
                             check=True).stdout  # fmt: skip
        subprocess.run(["tar", "-x", "-C", str(src)], input=arc, check=True)
        keys, out = Path(tmp) / "keys.npz", Path(tmp) / "out.npz"
        np.savez(keys, which=which, pa=la[0], ia=la[1], pb=lb[0], ib=lb[1])
        env = dict(os.environ, PYTHONPATH=str(src))
        # cwd: ``-c`` puts the working directory first on sys.path, before PYTHONPATH
        cmd = [sys.executable, "-c", _BEFORE, str(keys), str(out)]
        subprocess.run(cmd, env=env, cwd=tmp, check=True)
        q = np.load(out)
        if str(q["module"]) != str(src / "eyeviz" / "estimators" / "limit3d.py"):
            raise RuntimeError(f"--before imported {q['module']}, not revision {rev}'s code")
        n = p.r.size
        # keys flagged in either run, or with no stated error in both (0 or NaN), are left out
        err = np.hypot(q["mc"], p.mc_error)
        ok = ~q["flag"] & ~p.flagged & (err > 0)
        err = err[ok]
        z_r = ((p.r - q["r"]) / q["r"])[ok] / err
        z_az = ((p.azimuth - q["az"]) / q["az"])[ok] / err
        same = np.array_equal(q["acc"], p.n_accepted)
        print(
            f"  before ({rev}) {n / float(q['cpu']):8.1f} keys/s CPU; now / before "
            f"{float(q['cpu']) / cpu:.2f}x CPU; accepted draws {'the same' if same else 'DIFFER'}"
            f"; answers moved |z| r max {np.abs(z_r).max():.2f} "
            f"(rms {np.sqrt(np.mean(z_r**2)):.2f})"
            f", azimuth max {np.abs(z_az).max():.2f}; flagged {int(q['flag'].sum())} -> "
            f"{int(p.flagged.sum())}"
        )


if __name__ == "__main__":
    raise SystemExit(main())
