"""``eyeviz predict --estimator NAME DATA.csv -o PRED.csv``: r_hat, phi_hat per row.

Reads a data set of docs/contract.md (.csv or .npz), writes a CSV with a header line
``r_hat,phi_hat`` and one row per input row (``nan`` where a row is not a single
feature), atomically. Prints the metrics against the data's own r and phi. The data set is
read block by block (:func:`eyeviz.dataset.io.iter_blocks`), so memory stays bounded
whatever its size.

The data set's eye design (h, l, m) must be the estimator's: an NPZ carries it, a CSV is
described by ``--h --l --m`` (default Tables 3-4). An estimator for any design (analytic,
limit) gets its domain from those flags (and ``--r-min --r-max --g-max``); the other
options come from the estimator's registry entry; an option the chosen estimator does
not take (``--weights`` for analytic, ``--target`` for compact, ``--r-min`` for a
fixed-design estimator) is refused, never ignored. ``-o`` may not be the input file
(compared by device and inode, so links count).

The file's eye design picks its reader (:func:`eyeviz.dataset.kinds.kind_of`, read
from its meta). A sparse data set (``eyeviz generate --nside`` or ``--eye``) takes an
estimator of the spherical side that answers for its eyes (``analytic3d``, ``limit3d``,
``learned3d`` for HEALPix eyes; ``analytic3d`` and ``limit3d`` for a measured pair;
docs/spherical.md, docs/measured.md): it is read in blocks
(:class:`eyeviz.dataset.sparse3d.Sparse3DReader`), its design comes from the file (no
``--h --l --m --r-min --r-max --g-max``), and the CSV has
``r_hat,azimuth_hat,elevation_hat,flagged`` (radians; ``flagged`` is 1 where the
estimator answered by its fallback or the row lies outside its domain, e.g. learned3d
past its training ranges, and the count is on stderr: no such answer is written
unmarked, issue 36). An estimator that does not answer for
the file's eyes is refused in one line naming those that do.

Exit status (also in ``--help``):

- **0**: the output was written. Rows that are not a single feature (an eye with no lit
  ommatidium, or two separate lit runs) have no answer by definition: they are written as
  ``nan`` and counted on stderr.
- **2**: refused with one line (bad input, options, design mismatch); nothing written.
- **3**: the output was written, but the estimator gave no finite answer (``nan`` or
  ``inf``) for some rows that *are* a single feature; one line on stderr counts them.
  Nothing is lost, but a script should not take the file as complete.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

NAME = "predict"
HELP = "predict distance and azimuth for every row of a data set"
#: What the command writes, checked before any work (eyeviz.files.outputs).
OUTPUTS = {"out": "file"}
EPILOG = (
    "exit status: 0 written (rows that are not a single feature are nan, counted on "
    "stderr); 2 refused, nothing written; 3 written, but the estimator left some "
    "single-feature rows without a finite answer (counted on stderr)"
)
#: Exit status when the output is written but some valid rows got no finite prediction.
EXIT_UNANSWERED = 3


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from eyeviz.estimators import registry

    names = registry.available(None)
    parser.epilog = EPILOG
    parser.add_argument("data", help="data set (.csv or .npz, as `eyeviz generate` writes)")
    parser.add_argument(
        "-e",
        "--estimator",
        default="compact",
        help="; ".join(f"{e.name}: {e.help}" for e in registry.entries(None))
        + f" (one of {', '.join(names)}; default compact)",
    )
    parser.add_argument(
        "-o",
        "--out",
        required=True,
        help="output CSV (r_hat,phi_hat; r_hat,azimuth_hat,elevation_hat,flagged for 3D data)",
    )
    parser.add_argument(
        "--weights", default=None, help="weights directory/file instead of the shipped ones"
    )
    g = parser.add_argument_group(
        "design (a CSV's eyes; the domain of an estimator for any design; default Tables 3-4)"
    )
    registry.add_options(g, registry.DOMAIN_OPTIONS)
    o = parser.add_argument_group("estimator options")
    for e in registry.entries(None):
        registry.add_options(o, e.load_options)


def same_file(a, b) -> bool:
    """Whether paths ``a`` and ``b`` are the same file (device and inode: links count)."""
    try:
        sa, sb = os.stat(a), os.stat(b)
    except OSError:
        return False
    return (sa.st_dev, sa.st_ino) == (sb.st_dev, sb.st_ino)


def _design_text(h: float, l: float, m: int) -> str:  # noqa: E741
    from eyeviz.core.validation import num

    return f"h={num(h)}, l={num(l)}, m={m}"


def _reader(args, registry):
    """(block reader, design): the NPZ's own design, a CSV's from the flags (Tables 3-4)."""
    from eyeviz import EyevizError
    from eyeviz.core.domain import PAPER_DOMAIN
    from eyeviz.core.geometry import EyePair
    from eyeviz.dataset.io import format_of, iter_blocks

    path = Path(args.data)
    if format_of(path) == "npz":
        reader = iter_blocks(path)
        e = reader.eyes
        design = (float(e.h), float(e.l), int(e.m))
        given = {k: getattr(args, k, None) for k in ("h", "l", "m")}
        file_design = dict(zip(("h", "l", "m"), design, strict=True))
        bad = {k: v for k, v in given.items() if v is not None and float(v) != file_design[k]}
        if bad:
            raise EyevizError(
                f"{path} has design {_design_text(*design)}, but "
                + ", ".join(
                    f"--{k} {v:g}" if isinstance(v, float) else f"--{k} {v}" for k, v in bad.items()
                )
                + " was given"
            )
        return reader, design
    dom = registry.domain_from_args(args, PAPER_DOMAIN)
    return iter_blocks(path, eyes=EyePair(dom.h, dom.l, dom.m)), dom.design


def _refuse_foreign_options(entry, args, registry) -> None:
    """EyevizError for an option given on the command line that ``entry`` does not take:
    another estimator's option, ``--weights`` for an estimator without weights, or the
    object ranges (``--r-min --r-max --g-max``) for an estimator of a fixed design."""
    from eyeviz import EyevizError

    name = entry.name
    if args.weights is not None and not entry.weights_hint:
        raise EyevizError(
            f"estimator {name!r} has no weights: --weights is not an option of it "
            f"(estimators with weights: {', '.join(_with_weights(registry))})"
        )
    own = {o.dest for o in entry.load_options}
    for other in registry.entries(None):
        for opt in other.load_options:
            if opt.dest not in own and getattr(args, opt.dest, None) is not None:
                flag = next((f for f in opt.flags if f.startswith("--")), opt.flags[0])
                raise EyevizError(
                    f"{flag} is an option of estimator {other.name!r}, not of {name!r}"
                )
    if not entry.any_design:
        for k in ("r_min", "r_max", "g_max"):
            if getattr(args, k, None) is not None:
                raise EyevizError(
                    f"--{k.replace('_', '-')} is for estimators of any design; {name!r} "
                    "answers for the ranges it was trained on"
                )


def _with_weights(registry) -> list[str]:
    return [e.name for e in registry.entries(None) if e.weights_hint]


# long: the command's one sequence (read, check, predict, write), each step with its own one-line
# error
def run(args: argparse.Namespace) -> int:
    import numpy as np

    from eyeviz import EyevizError
    from eyeviz.core.domain import Domain
    from eyeviz.estimators import registry
    from eyeviz.estimators.metrics import RunningSummary
    from eyeviz.files.atomic import atomic_output

    entry = registry.get(args.estimator)
    _refuse_foreign_options(entry, args, registry)
    out = Path(args.out)
    from eyeviz.files.limits import check_regular_file

    check_regular_file(args.data, "data file")  # names a folder, FIFO, device, link loop
    if same_file(args.data, out):
        raise EyevizError(f"output {args.out} is the input data file {args.data}; pick another -o")
    if not (out.parent if str(out.parent) else Path(".")).is_dir():
        raise EyevizError(f"output directory {out.parent} does not exist")
    from eyeviz.dataset.kinds import kind_of

    kind = kind_of(args.data)
    if kind not in entry.eye_models:
        if kind == "planar":  # or unreadable: an empty, garbage or truncated NPZ is
            _reader(args, registry)  # named by the planar reader (issue 36)
        which = {"planar": "a planar", "spherical": "a sparse 3D"}.get(kind, f"a {kind}-eye")
        raise EyevizError(
            f"estimator {entry.name!r} answers for {' and '.join(entry.eye_models)} eyes, but "
            f"{args.data} is {which} data set; use one of "
            f"{', '.join(registry.available_for(kind)) or '(none registered)'}"
        )
    if kind != "planar":
        return _run3d(args, entry, registry, out, kind)
    reader, design = _reader(args, registry)
    kw = registry.options_from_args(entry.load_options, args)
    if args.weights is not None:
        kw["path"] = args.weights
    if entry.any_design:
        h, l, m = design  # noqa: E741
        kw["domain"] = registry.domain_from_args(args, Domain(h, l, m))
    est = entry.load_estimator(**kw)
    if est.domain.design != design:
        raise EyevizError(
            f"data set {args.data} has design {_design_text(*design)}, but estimator "
            f"{entry.name!r} answers for {_design_text(*est.domain.design)}"
        )
    n = invalid = outside = unanswered = 0
    dd, ad = RunningSummary(), RunningSummary()
    with atomic_output(out) as tmp, open(tmp, "w", encoding="ascii") as fh:
        fh.write("r_hat,phi_hat\n")
        for b in reader:  # bounded memory: one block of rows at a time
            pred = est.predict(b.omega_a, b.omega_b)
            np.savetxt(fh, np.column_stack([pred.r, pred.phi]), fmt="%.17g", delimiter=",")
            valid = np.asarray(pred.valid)
            answered = valid & np.isfinite(pred.r) & np.isfinite(pred.phi)
            n += len(valid)
            invalid += int((~valid).sum())
            unanswered += int((valid & ~answered).sum())
            outside += int((valid & ~np.asarray(pred.in_domain)).sum())
            dd.update(b.r[answered], pred.r[answered])
            ad.update(b.phi[answered], pred.phi[answered])
    msg = f"{args.estimator}: {n} rows -> {out}"
    if invalid:
        msg += f"; {invalid} not a single feature (nan)"
    if outside:
        msg += f"; {outside} outside the training domain"
    print(msg, file=sys.stderr)
    if dd.n >= 2:
        try:
            d, a = dd.result(), ad.result()
            ok = True
        except ValueError:
            ok = False
        if ok:
            print(
                f"DD MAPE {d['mape']:.3f} %  MAE {d['mae']:.2f}  R^2 {d['r2']:.4f} | "
                f"AD MAPE {a['mape']:.4f} %  MAE {a['mae']:.3g} rad  R^2 {a['r2']:.6f}",
                file=sys.stderr,
            )
    if unanswered:
        print(
            f"eyeviz: warning: {out} written, but {args.estimator} gave no finite answer "
            f"for {unanswered} of {n - invalid} single-feature rows (nan there; exit "
            f"{EXIT_UNANSWERED})",
            file=sys.stderr,
        )
        return EXIT_UNANSWERED
    return 0


def _run3d(args: argparse.Namespace, entry, registry, out: Path, kind: str) -> int:
    """``predict`` on a sparse data set (HEALPix or measured eyes): r, azimuth, elevation
    per row, block by block."""
    import numpy as np

    from eyeviz import EyevizError
    from eyeviz.dataset.kinds import open_reader
    from eyeviz.estimators.metrics import RunningSummary
    from eyeviz.files.atomic import atomic_output

    if registry.domain_given(args):
        raise EyevizError(
            f"{args.data} is a 3D data set that carries its design (its eyes and ranges); "
            "--h --l --m --r-min --r-max --g-max are for planar data"
        )
    reader = open_reader(args.data, kind)
    dom = reader.domain
    kw = registry.options_from_args(entry.load_options, args)
    if args.weights is not None:
        kw["path"] = args.weights
    if entry.any_design:
        kw["domain"] = dom
    est = entry.load_estimator(**kw)
    if est.domain.design != dom.design:
        what = f"({', '.join(dom.design_names)})"
        raise EyevizError(
            f"data set {args.data} has the eyes {what} = {dom.design}, but estimator "
            f"{entry.name!r} answers for {est.domain.design}"
        )
    n = invalid = unanswered = flagged = 0
    sums = [RunningSummary() for _ in range(3)]
    with atomic_output(out) as tmp, open(tmp, "w", encoding="ascii") as fh:
        fh.write("r_hat,azimuth_hat,elevation_hat,flagged\n")
        for b in reader:  # bounded memory: one block of rows at a time
            pred = est.predict_dataset(b)
            cols = [np.asarray(c, np.float64) for c in pred]
            flag = np.asarray(pred.flagged, bool)
            table = np.column_stack([*cols, flag])
            np.savetxt(fh, table, fmt=["%.17g"] * 3 + ["%d"], delimiter=",")
            valid = np.asarray(pred.valid)
            answered = valid & np.isfinite(cols[0]) & np.isfinite(cols[1]) & np.isfinite(cols[2])
            n += len(valid)
            invalid += int((~valid).sum())
            unanswered += int((valid & ~answered).sum())
            flagged += int(flag.sum())
            for acc, true, got in zip(sums, (b.r, b.azimuth, b.elevation), cols, strict=True):
                acc.update(true[answered], got[answered])
    msg = f"{entry.name}: {n} rows -> {out}"
    if invalid:
        msg += f"; {invalid} with an eye that lit nothing (nan)"
    if flagged:
        msg += (
            f"; {flagged} flagged (column 'flagged' = 1: answered by {entry.name}'s fallback "
            "or outside its domain; not its own answer)"
        )
    print(msg, file=sys.stderr)
    if sums[0].n >= 2:
        try:
            d, a, e = (acc.result() for acc in sums)
        except ValueError:
            pass
        else:
            print(
                f"DD MAPE {d['mape']:.3f} %  MAE {d['mae']:.2f} | azimuth MAE "
                f"{a['mae']:.3g} rad | elevation MAE {e['mae']:.3g} rad",
                file=sys.stderr,
            )
    if unanswered:
        print(
            f"eyeviz: warning: {out} written, but {entry.name} gave no finite answer for "
            f"{unanswered} of {n - invalid} rows where both eyes lit facets (nan there; exit "
            f"{EXIT_UNANSWERED})",
            file=sys.stderr,
        )
        return EXIT_UNANSWERED
    return 0
