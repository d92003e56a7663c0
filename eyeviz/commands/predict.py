"""``eyeviz predict --estimator NAME DATA.csv -o PRED.csv``: r_hat, phi_hat per row.

Reads a data set of docs/contract.md (.csv or .npz), writes a CSV with a header line
``r_hat,phi_hat`` and one row per input row (``nan`` where a row is not a single
feature), atomically. Prints the metrics against the data's own r and phi. The data set is
read block by block (its format's reader, :mod:`eyeviz.dataset.kinds`), so memory stays bounded
whatever its size.

The data set's eye design (h, l, m) must be the estimator's: an NPZ carries it, a CSV is
described by ``--h --l --m`` (default Tables 3-4). An estimator for any design (analytic,
limit) gets its domain from those flags (and ``--r-min --r-max --g-max``); the other
options come from the estimator's registry entry; an option the chosen estimator does
not take (``--weights`` for analytic, ``--target`` for compact, ``--r-min`` for a
fixed-design estimator) is refused, never ignored. ``-o`` may not be the input file
(compared by device and inode, so links count).

The file's eye design picks its data set format (:mod:`eyeviz.dataset.kinds`: the kind
read from its meta, :func:`~eyeviz.dataset.kinds.kind_of`; a kind or format nobody
registered is refused in one line naming the known kinds): its reader, and the columns
and wording of its rows (:class:`~eyeviz.dataset.kinds.RowFormat`); one run loop
(:func:`_predict_rows`) serves every kind. A sparse data set (``eyeviz generate --nside``
or ``--eye``) takes an estimator of the spherical side that answers for its eyes
(``analytic3d``, ``limit3d``, ``learned3d`` for HEALPix eyes; ``analytic3d`` and
``limit3d`` for a measured pair; docs/spherical.md, docs/measured.md): its design comes
from the file (no ``--h --l --m --r-min --r-max --g-max``), and the CSV has
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


def _reader(args, registry, fmt):
    """(block reader, design) of a planar data set (``fmt``, the planar format): the NPZ's
    own design, a CSV's from the flags (Tables 3-4)."""
    from eyeviz import EyevizError
    from eyeviz.core.domain import PAPER_DOMAIN
    from eyeviz.dataset.io import format_of

    path = Path(args.data)
    if format_of(path) == "npz":
        reader = fmt.call("reader", path)
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
    return fmt.call("reader", path, eyes=dom.eyes), dom.design


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


def _open_file_domain(args, entry, registry, fmt):
    """(block reader, design names, design, domain) of a data set that carries its whole
    domain (the sparse lit sets, HEALPix or measured): the design flags are refused."""
    from eyeviz import EyevizError

    if registry.domain_given(args):
        raise EyevizError(
            f"{args.data} is a 3D data set that carries its design (its eyes and ranges); "
            "--h --l --m --r-min --r-max --g-max are for planar data"
        )
    reader = fmt.call("reader", args.data)
    dom = reader.domain
    return reader, dom.design_names, dom.design, dom


def _open_flag_domain(args, entry, registry, fmt):
    """(block reader, design names, design, domain) of a planar data set: an NPZ's own
    design, a CSV's from the flags (Tables 3-4); the domain (ranges from the flags) only
    for an estimator of any design."""
    from eyeviz.core.domain import Domain

    reader, design = _reader(args, registry, fmt)
    dom = registry.domain_from_args(args, Domain(*design)) if entry.any_design else None
    return reader, ("h", "l", "m"), design, dom


def _open(args, entry, registry, kind: str):
    """(format, block reader, design names, design, domain) for ``args.data`` of eye kind
    ``kind``; the estimator is refused in one line when it does not answer for it."""
    from eyeviz import EyevizError
    from eyeviz.dataset.kinds import data_format

    fmt = data_format(kind)
    if kind not in entry.eye_models:
        if fmt.domain_flags:  # or unreadable: an empty, garbage or truncated NPZ is
            _reader(args, registry, fmt)  # named by the planar reader (issue 36)
        raise EyevizError(
            f"estimator {entry.name!r} answers for {' and '.join(entry.eye_models)} eyes, but "
            f"{args.data} is {fmt.what}; use one of "
            f"{', '.join(registry.available_for(kind)) or '(none registered)'}"
        )
    opener = _open_flag_domain if fmt.domain_flags else _open_file_domain
    return (fmt, *opener(args, entry, registry, fmt))


def run(args: argparse.Namespace) -> int:
    from eyeviz import EyevizError
    from eyeviz.dataset.kinds import kind_of
    from eyeviz.estimators import registry

    entry = registry.get(args.estimator)
    _refuse_foreign_options(entry, args, registry)
    out = Path(args.out)
    from eyeviz.files.limits import check_regular_file

    check_regular_file(args.data, "data file")  # names a folder, FIFO, device, link loop
    if same_file(args.data, out):
        raise EyevizError(f"output {args.out} is the input data file {args.data}; pick another -o")
    if not (out.parent if str(out.parent) else Path(".")).is_dir():
        raise EyevizError(f"output directory {out.parent} does not exist")
    fmt, reader, names, design, dom = _open(args, entry, registry, kind_of(args.data))
    kw = registry.options_from_args(entry.load_options, args)
    if args.weights is not None:
        kw["path"] = args.weights
    if entry.any_design:
        kw["domain"] = dom
    est = entry.load_estimator(**kw)
    if est.domain.design != design:
        raise EyevizError(_mismatch(args.data, names, design, entry.name, est.domain.design))
    return _predict_rows(fmt.rows, est, entry.name, reader, out)


def _mismatch(data, names: tuple[str, ...], design: tuple, name: str, theirs: tuple) -> str:
    """The one line refusing an estimator of another design than the data set's."""
    if names == ("h", "l", "m"):  # the planar flags' wording: h=40, l=20, m=720
        return (
            f"data set {data} has design {_design_text(*design)}, but estimator "
            f"{name!r} answers for {_design_text(*theirs)}"
        )
    return (
        f"data set {data} has the eyes ({', '.join(names)}) = {design}, but estimator "
        f"{name!r} answers for {theirs}"
    )


# the one run loop over a data set's rows for every kind (predict, write, count, the
# metrics), each kind's columns and wording from its dataset.kinds.RowFormat
def _predict_rows(rows, est, name: str, reader, out: Path) -> int:
    """Predict every block of ``reader`` with ``est``, write the CSV of ``rows``
    (:class:`eyeviz.dataset.kinds.RowFormat`) to ``out`` atomically, say the counts and
    the metrics on stderr; the exit status."""
    import numpy as np

    from eyeviz.estimators.metrics import RunningSummary
    from eyeviz.files.atomic import atomic_output

    n = invalid = unanswered = aside = 0
    sums = [RunningSummary() for _ in rows.truth]
    fmt = ["%.17g"] * len(rows.truth) + (["%d"] if rows.flag_column else [])
    with atomic_output(out) as tmp, open(tmp, "w", encoding="ascii") as fh:
        fh.write(rows.header + "\n")
        for b in reader:  # bounded memory: one block of rows at a time
            pred = est.predict_dataset(b)
            cols = [np.asarray(c, np.float64) for c in pred]
            table = [*cols, np.asarray(pred.flagged, bool)] if rows.flag_column else cols
            np.savetxt(fh, np.column_stack(table), fmt=fmt, delimiter=",")
            valid = np.asarray(pred.valid)
            answered = valid & np.logical_and.reduce([np.isfinite(c) for c in cols])
            n += len(valid)
            invalid += int((~valid).sum())
            unanswered += int((valid & ~answered).sum())
            aside += int(rows.aside(pred, valid).sum())
            for acc, key, got in zip(sums, rows.truth, cols, strict=True):
                acc.update(np.asarray(getattr(b, key))[answered], got[answered])
    msg = f"{name}: {n} rows -> {out}"
    if invalid:
        msg += f"; {invalid} {rows.no_answer}"
    if aside:
        msg += rows.aside_text.format(k=aside, name=name)
    print(msg, file=sys.stderr)
    if sums[0].n >= 2:
        try:
            results = [acc.result() for acc in sums]
        except ValueError:
            pass
        else:
            print(rows.summary.format(*results), file=sys.stderr)
    if unanswered:
        print(
            f"eyeviz: warning: {out} written, but {name} gave no finite answer for "
            f"{unanswered} of {n - invalid} {rows.answerable} (nan there; exit "
            f"{EXIT_UNANSWERED})",
            file=sys.stderr,
        )
        return EXIT_UNANSWERED
    return 0
