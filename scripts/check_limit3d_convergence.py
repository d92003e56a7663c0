"""How the limit's DD moves with its accuracy setting (issue 38.2): limit3d's DD (mean
|dr| / r, %) over one fresh data set at nside 180 at several targets of the per-key
Monte-Carlo error, each against the tightest, on the same rows (paired: the differences
are far more precise than the DD itself; their errors are bootstrap standard errors over
rows). Prints a Markdown table and the keys/s of each.

A target may run on the first ROWS rows only (``0.001:500``): its row is then compared on
those rows, and the chain "target -> next tighter target on the rows both ran" is
printed too, so an expensive tight target need not run on every row. The per-row errors
are saved after each target (``--out``, npz) and ``--table`` reprints from those files
(several runs on the same rows merged).

    python scripts/check_limit3d_convergence.py [-n ROWS] [--seed SEED] [--nside NSIDE]
        [--targets 0.01,0.005,0.0025,0.001:500] [--out FILE.npz] [--table FILE.npz]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from eyeviz.core.domain import Domain3D
from eyeviz.dataset.algorithm1_3d import generate3d
from eyeviz.estimators.base import take_rows
from eyeviz.estimators.limit3d import MC_TARGET, Limit3DEstimator
from eyeviz.files.atomic import atomic_output
from eyeviz.reports.errors import bootstrap_se

TARGETS = "0.04,0.02,0.01,0.005,0.0025"


def _parse(spec: str, n: int) -> list[tuple[float, int]]:
    out = []
    for part in spec.split(","):
        t, _, k = part.partition(":")
        out.append((float(t), min(n, int(k)) if k else n))
    return out


def _run(a: argparse.Namespace) -> dict[str, np.ndarray]:
    dom = Domain3D(nside=a.nside)
    ds = generate3d(a.n, dom, seed=a.seed)
    Limit3DEstimator(dom).predict_dataset(generate3d(4, dom, seed=1))  # warm
    meta = [a.n, a.seed, a.nside, a.max_batches, a.samples]
    res: dict[str, np.ndarray] = {"meta": np.array(meta)}
    for t, k in _parse(a.targets, a.n):
        est = Limit3DEstimator(dom, accuracy=t, max_batches=a.max_batches, samples=a.samples)
        rows = np.arange(k)
        lit_a = take_rows(ds.indptr_a, ds.indices_a, rows)
        lit_b = take_rows(ds.indptr_b, ds.indices_b, rows)
        t0 = time.perf_counter()
        p = est.predict(lit_a, lit_b)
        dt = time.perf_counter() - t0
        rel = np.full(a.n, np.nan)
        rel[:k] = np.abs(p.r - ds.r[:k]) / ds.r[:k]
        res[f"rel_{t:g}"] = rel
        res[f"info_{t:g}"] = np.array(
            [k, dt, np.median(p.n_accepted), p.mc_capped.mean(), p.flagged.mean()]
        )
        if a.out:
            with atomic_output(a.out) as tmp:
                np.savez(tmp, **res)
        print(f"target {t:g}: {k} rows in {dt:.0f} s ({k / dt:.2f} keys/s)", flush=True)
    return res


def table(res: dict[str, np.ndarray]) -> str:
    """The Markdown convergence table of a run's per-row errors."""
    n, seed, nside, mb = (int(v) for v in res["meta"][:4])
    ts = sorted((float(k[4:]) for k in res if k.startswith("rel_")), reverse=True)
    tight = ts[-1]
    ref = res[f"rel_{tight:g}"]
    lines = [
        f"limit3d DD at nside {nside}, rows of seed {seed} (fresh; max batches {mb}); "
        f"paired differences against the tightest target {tight:g} on the rows both ran, "
        "and against the next tighter target; ± are bootstrap standard errors over rows\n",
        "| target | rows | DD % | ± | DD - DD(tightest), points | ± | DD - DD(next), points "
        "| ± | keys/s | median accepted | capped % | flagged % |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for i, t in enumerate(ts):
        rel = res[f"rel_{t:g}"]
        k, dt, med, cap, flag = res[f"info_{t:g}"]
        ok = np.isfinite(rel)
        both = ok & np.isfinite(ref)
        d = 100 * (rel[both] - ref[both])
        nxt = "| | "
        if i + 1 < len(ts):
            r2 = res[f"rel_{ts[i + 1]:g}"]
            m = ok & np.isfinite(r2)
            dn = 100 * (rel[m] - r2[m])
            nxt = f"| {dn.mean():+.4f} | {bootstrap_se(dn):.4f} "
        name = f"{t:g} (default)" if t == MC_TARGET else f"{t:g}"
        lines.append(
            f"| {name} | {int(k)} | {100 * rel[ok].mean():.3f} | "
            f"{bootstrap_se(100 * rel[ok]):.3f} | {d.mean():+.4f} | "
            f"{bootstrap_se(d) if t != tight else 0.0:.4f} {nxt}| {k / dt:.2f} | "
            f"{med:.0f} | {100 * cap:.1f} | {100 * flag:.1f} |"
        )
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=300)
    ap.add_argument("--seed", type=int, default=5550123)
    ap.add_argument("--nside", type=int, default=180)
    ap.add_argument("--max-batches", type=int, default=64)
    ap.add_argument("--samples", type=int, default=256, help="draws per batch")
    ap.add_argument("--targets", default=TARGETS, help="comma-separated, each T or T:ROWS")
    ap.add_argument("--out", default="", help="save the per-row errors (npz)")
    ap.add_argument(
        "--table",
        nargs="+",
        default=[],
        help="only print the table of saved runs (of the "
        "same rows: -n, --seed, --nside; several are merged)",
    )
    a = ap.parse_args()
    if a.table:
        res = {}
        for f in a.table:
            with np.load(f) as z:
                if "meta" in res and not np.array_equal(res["meta"][:3], z["meta"][:3]):
                    raise SystemExit(f"{f}: another data set (-n, --seed, --nside)")
                res.update({k: z[k] for k in z.files})
    else:
        res = _run(a)
    print(table(res))


if __name__ == "__main__":
    main()
