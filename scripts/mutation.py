"""Mutation testing of eyeviz's core, model and estimators: single-line mutants against
the tests that mirror each package (a tool, never part of the test suite).

Each mutant changes one token on one line:

- comparisons: ``<`` <-> ``<=``, ``>`` <-> ``>=``, ``==`` <-> ``!=``, ``is`` -> ``is not``,
  ``in`` -> ``not in``;
- arithmetic: binary ``+`` <-> ``-``, ``*`` -> ``/``, ``/`` -> ``*``, ``//`` -> ``/``,
  ``%`` -> ``//``; augmented ``+=`` <-> ``-=``;
- logic: ``and`` <-> ``or``, ``True`` <-> ``False``, ``not x`` -> ``x``;
- constants: an integer n -> n + 1 (off by one); a unary minus dropped (``-x`` -> ``x``).

Mutants that do not compile are dropped. From each module's mutants ``--per-module``
are drawn at random (seeded; all of them when there are fewer); each is written into the
copy, the mirroring tests run (``tests/<package>``, the module's own ``test_<name>.py``
first; for the modules of ``EXTRA_TESTS`` also the directories named there, e.g.
``tests/render`` for the frame's drawing data) with ``-x -q`` and a timeout, and the copy
is restored byte for byte. A mutant is *killed* when the tests fail (exit 1, or 2 when
the mutant breaks collection), *survived* when they pass, *timeout* when they run past
``--timeout-factor`` times the unmutated run (+ 20 s).

It never mutates the checkout it lives in: ``--root`` must be a copy, e.g.

    git worktree add /tmp/mut HEAD
    .venv/bin/python scripts/mutation.py --root /tmp/mut --per-module 8 --json out.json
    git worktree remove --force /tmp/mut

and it checks first that ``import eyeviz`` resolves into the copy (PYTHONPATH=root).
Results: docs/mutation.md.
"""

from __future__ import annotations

import argparse
import io
import json
import os
import random
import signal
import subprocess
import sys
import time
import tokenize
from dataclasses import asdict, dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
PACKAGES = ("eyeviz/core", "eyeviz/model", "eyeviz/estimators")
#: Modules whose behaviour is also tested outside their package's mirror: run these test
#: directories after it (the frame's drawing data is read by the painters in tests/render).
EXTRA_TESTS = {
    "eyeviz/model/frame.py": ("tests/render",),
    "eyeviz/model/frame_parts.py": ("tests/render",),
    "eyeviz/model/layers.py": ("tests/render",),
}
SKIP_MARK = "pragma: no mutate"

#: The spherical side (``--spherical``): each module with the test files that test it,
#: run with ``-m "not slow"`` (their whole directories take 10-25 min a mutant on two
#: shared cores). The compiled kernels are left out: numba's on-disk cache is keyed on
#: the file's time stamp and size, so a same-size mutant written within the second could
#: run the unmutated kernel. Ordered by the time their tests take, the slowest last.
_G3 = (
    "tests/core/test_geometry3d_edges.py",
    "tests/core/test_geometry3d_high_ties.py",
    "tests/core/test_healpix_conventions.py",
    "tests/core/test_geometry3d.py",
)
_MEASURED = ("tests/core/test_measured.py", "tests/core/test_measured_from.py")
_APP3D = (
    "tests/model/test_app_model3d.py",
    "tests/model/test_app_model3d_paths.py",
    "tests/model/test_camera3d.py",
)
SPHERICAL: dict[str, tuple[str, ...]] = {
    "eyeviz/core/healpix.py": (
        "tests/core/test_healpix.py",
        "tests/core/test_healpix_conventions.py",
        # healpix.vertex_lon is tested against healpix.boundaries beside the fast path
        "tests/core/test_geometry3d.py::test_vertex_lon_gives_every_cells_boundary_vertices",
    ),
    "eyeviz/core/measured.py": _MEASURED,
    "eyeviz/core/measured_exact.py": _MEASURED,
    "eyeviz/core/measured_fast.py": _MEASURED,
    "eyeviz/core/measured_from.py": _MEASURED,
    "eyeviz/core/measured_grid.py": _MEASURED,
    "eyeviz/core/measured_index.py": _MEASURED,
    "eyeviz/dataset/algorithm1_3d.py": (
        "tests/dataset/test_algorithm1_3d.py",
        "tests/dataset/test_algorithm1_3d_joint.py",
    ),
    "eyeviz/dataset/sparse3d.py": (
        "tests/dataset/test_sparse3d.py",
        "tests/dataset/test_sparse3d_design_check.py",
        "tests/dataset/test_sparse_measured.py",
    ),
    "eyeviz/estimators/analytic3d.py": (
        "tests/estimators/test_analytic3d.py",
        "tests/estimators/test_analytic3d_flagged.py",
        "tests/estimators/test_boundary_rays.py",
    ),
    "eyeviz/estimators/triangulation.py": (
        "tests/estimators/test_triangulation.py",
        "tests/estimators/test_analytic3d.py",
        "tests/estimators/test_boundary_rays.py",
    ),
    "eyeviz/model/app_model3d.py": _APP3D,
    "eyeviz/model/camera3d.py": _APP3D,
    "eyeviz/model/interactions.py": ("tests/model/test_app_model.py",),
    "eyeviz/core/healpix_fast.py": _G3,
    "eyeviz/core/geometry3d.py": _G3,
    "eyeviz/core/exact3d.py": _G3,
    "eyeviz/estimators/limit3d.py": (
        "tests/estimators/test_limit3d.py",
        "tests/estimators/test_limit3d_hostile.py",
    ),
}

_OPS = {
    "<": ["<="],
    "<=": ["<"],
    ">": [">="],
    ">=": [">"],
    "==": ["!="],
    "!=": ["=="],
    "*": ["/"],
    "/": ["*"],
    "//": ["/"],
    "%": ["//"],
    "+=": ["-="],
    "-=": ["+="],
}
_NAMES = {"and": ["or"], "or": ["and"], "True": ["False"], "False": ["True"]}
# a '-' or '+' after one of these (or at the start of a line) is unary
_BEFORE_UNARY = {"(", "[", "{", ",", "=", ":", "return", "lambda", "**", "*", "/", "+", "-"}
_BEFORE_UNARY |= {"<", "<=", ">", ">=", "==", "!=", "and", "or", "not", "in", "if", "else"}
_BEFORE_UNARY |= {"+=", "-=", "*=", "/=", "yield", "->", "%", "//", "@", "is"}


@dataclass(frozen=True)
class Mutant:
    path: str  # relative to the root
    line: int  # 1-based
    col: int
    end: int
    old: str
    new: str
    kind: str

    def apply(self, source: str) -> str:
        lines = source.splitlines(keepends=True)
        s = lines[self.line - 1]
        assert s[self.col : self.end] == self.old, (self, s)
        lines[self.line - 1] = s[: self.col] + self.new + s[self.end :]
        return "".join(lines)

    def label(self) -> str:
        return f"{self.path}:{self.line}: {self.old!r} -> {self.new!r} ({self.kind})"


def mutants_of(path: str, source: str) -> list[Mutant]:
    """Every single-token mutant of ``source`` that still compiles."""
    out: list[Mutant] = []
    lines = source.splitlines()
    toks = [
        t
        for t in tokenize.generate_tokens(io.StringIO(source).readline)
        if t.type not in (tokenize.COMMENT, tokenize.NL, tokenize.INDENT, tokenize.DEDENT)
    ]
    prev = "\n"
    for k, t in enumerate(toks):
        (ln, c0), (ln1, c1) = t.start, t.end
        text = t.string
        if t.type in (tokenize.STRING, tokenize.NEWLINE, tokenize.ENDMARKER) or ln != ln1:
            prev = text if t.type != tokenize.NEWLINE else "\n"
            continue
        if SKIP_MARK in lines[ln - 1] or lines[ln - 1].lstrip().startswith("__all__"):
            prev = text if t.type != tokenize.NEWLINE else "\n"
            continue
        nxt = toks[k + 1].string if k + 1 < len(toks) else ""
        cands: list[tuple[str, str]] = []
        unary = prev in _BEFORE_UNARY or prev == "\n"
        if t.type == tokenize.OP:
            if text in ("+", "-"):
                if unary:
                    if text == "-":
                        cands.append(("", "drop unary minus"))
                else:
                    cands.append(("-" if text == "+" else "+", "arithmetic"))
            elif text in ("*", "/") and nxt in (",", ")"):
                pass  # a signature's keyword-only / positional-only marker
            elif text in _OPS:
                kind = "comparison" if text in ("<", "<=", ">", ">=", "==", "!=") else "arithmetic"
                cands += [(n, kind) for n in _OPS[text]]
        elif t.type == tokenize.NAME:
            if text in _NAMES:
                cands += [(n, "logic") for n in _NAMES[text]]
            elif text == "not" and prev not in ("is",) and nxt != "in":
                cands.append(("", "drop not"))
            elif text == "is" and nxt != "not":
                cands.append(("is not", "comparison"))
            elif text == "in" and prev not in ("not", "for") and not _in_for(toks, k):
                cands.append(("not in", "comparison"))
        elif t.type == tokenize.NUMBER:
            try:
                v = int(text, 0)
            except ValueError:
                v = None
            if v is not None and "_" not in text and text.isdigit():
                cands.append((str(v + 1), "constant + 1"))
        for new, kind in cands:
            end = c1
            if kind == "drop not" and lines[ln - 1][c1 : c1 + 1] == " ":
                end += 1  # 'not x' -> 'x'
            m = Mutant(path, ln, c0, end, lines[ln - 1][c0:end], new, kind)
            try:
                compile(m.apply(source), path, "exec")
            except SyntaxError:
                continue
            out.append(m)
        prev = text if t.type != tokenize.NEWLINE else "\n"
    return out


def _in_for(toks, k: int) -> bool:
    """Whether the ``in`` at toks[k] belongs to a ``for`` on the same line."""
    ln = toks[k].start[0]
    j = k - 1
    while j >= 0 and toks[j].start[0] == ln:
        if toks[j].string == "for":
            # 'x in y' inside a comprehension's condition still counts as a for-in here
            return True
        j -= 1
    return False


# --- running -------------------------------------------------------------------------------
def _env(root: Path) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(root)
    env.setdefault("QT_API", "pyqt5")
    env.setdefault("MPLBACKEND", "Agg")
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    return env


def check_root(root: Path, package: str, python: str) -> None:
    """Refuse to mutate this checkout, and check that the package imports from root."""
    if root.resolve() == HERE:
        raise SystemExit(
            f"--root {root} is the checkout this script lives in: mutate a copy "
            "(git worktree add /tmp/mut HEAD)"
        )
    mod = package.replace("/", ".")
    r = subprocess.run(
        [python, "-c", f"import {mod} as m; print(m.__file__)"],
        cwd=root,
        env=_env(root),
        capture_output=True,
        text=True,
    )
    got = Path(r.stdout.strip() or "?").resolve()
    if r.returncode or root.resolve() not in got.parents:
        raise SystemExit(f"{mod} does not import from {root} (got {got}): {r.stderr.strip()}")


def _drop_pyc(path: Path) -> None:
    """Remove the module's bytecode: a mutant of the same size written in the same second
    as the original would otherwise be shadowed by a stale .pyc (or leave one behind)."""
    cache = path.parent / "__pycache__"
    if cache.is_dir():
        for p in cache.glob(f"{path.stem}.*.pyc"):
            p.unlink(missing_ok=True)


def run_tests(
    root: Path, tests: list[str], python: str, timeout: float, marks: str = ""
) -> tuple[str, float]:
    cmd = [python, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", "-p", "no:randomly"]
    cmd += ["-m", marks] if marks else []
    cmd += ["-o", "addopts=--import-mode=importlib", "--hypothesis-seed=0", *tests]
    t0 = time.monotonic()
    proc = subprocess.Popen(
        cmd,
        cwd=root,
        env=_env(root),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        rc = proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        return "timeout", time.monotonic() - t0
    dt = time.monotonic() - t0
    if rc == 0:
        return "survived", dt
    if rc in (1, 2):
        return "killed", dt
    return f"error (pytest exit {rc})", dt


def extra_tests(root: Path, module: Path) -> list[str]:
    """The directories of :data:`EXTRA_TESTS` for ``module`` that exist under root."""
    rel = module.relative_to(root).as_posix()
    return [d for d in EXTRA_TESTS.get(rel, ()) if (root / d).is_dir()]


def tests_for(root: Path, module: Path, tests_dir: str) -> list[str]:
    own = Path(tests_dir) / f"test_{module.stem}.py"
    return ([str(own)] if (root / own).exists() else []) + [tests_dir, *extra_tests(root, module)]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--root", type=Path, required=True, help="a copy of the repository")
    ap.add_argument("--packages", nargs="+", default=list(PACKAGES))
    ap.add_argument("--tests", nargs="+", default=None, help="test dir per package")
    ap.add_argument("--per-module", type=int, default=8, help="mutants drawn per module")
    ap.add_argument("--modules", nargs="*", default=None, help="only these module stems")
    ap.add_argument("--seed", type=int, default=20)
    ap.add_argument("--timeout-factor", type=float, default=3.0)
    ap.add_argument("--python", default=sys.executable)
    ap.add_argument("--json", type=Path, default=None, help="write every result here")
    ap.add_argument("--list", action="store_true", help="count the mutants, run nothing")
    ap.add_argument(
        "--spherical",
        action="store_true",
        help="the spherical modules (SPHERICAL), each against its own test files",
    )
    a = ap.parse_args(argv)
    if a.per_module < 1:
        ap.error(f"--per-module must be an integer >= 1, got {a.per_module}")
    root = a.root.resolve()
    # a SIGTERM ends the run through the finally below, which restores the mutated file
    signal.signal(signal.SIGTERM, lambda *_: sys.exit("mutation run stopped (SIGTERM)"))
    if a.spherical:
        return run_spherical(a, root)
    tests = a.tests or ["tests/" + Path(p).name for p in a.packages]
    if len(tests) != len(a.packages):
        ap.error("--tests needs one directory per package")
    results: list[dict] = []
    totals = {"sites": 0, "sampled": 0}
    rng = random.Random(a.seed)
    for package, tdir in zip(a.packages, tests, strict=True):
        if not a.list:
            check_root(root, package, a.python)
        modules = sorted((root / package).glob("*.py"))
        if a.modules:
            modules = [m for m in modules if m.stem in a.modules]
        plan: list[tuple[Path, list[Mutant], int]] = []
        for mod in modules:
            rel = str(mod.relative_to(root))
            every = mutants_of(rel, mod.read_text())
            pick = sorted(
                rng.sample(every, min(a.per_module, len(every))),
                key=lambda m: (m.line, m.col),
            )
            plan.append((mod, pick, len(every)))
            totals["sites"] += len(every)
            totals["sampled"] += len(pick)
            print(f"{rel}: {len(pick)} of {len(every)} mutants", flush=True)
        if a.list:
            continue
        status, base = run_tests(root, [tdir], a.python, 3600.0)
        if status != "survived":
            raise SystemExit(f"{tdir} fails without any mutant ({status}): fix that first")
        timeout = a.timeout_factor * base + 20.0
        print(f"{tdir}: {base:.1f} s unmutated, timeout {timeout:.0f} s", flush=True)
        extra_base: dict[str, float] = {}  # the unmutated run of each extra directory
        for d in sorted({d for mod, pick, _ in plan if pick for d in extra_tests(root, mod)}):
            status, extra_base[d] = run_tests(root, [d], a.python, 3600.0)
            if status != "survived":
                raise SystemExit(f"{d} fails without any mutant ({status}): fix that first")
            print(f"{d}: {extra_base[d]:.1f} s unmutated (also run for some modules)", flush=True)
        for mod, pick, _ in plan:
            more = sum(extra_base[d] for d in extra_tests(root, mod))
            original = mod.read_bytes()
            src = original.decode()
            try:
                for m in pick:
                    mod.write_text(m.apply(src))
                    _drop_pyc(mod)
                    t_out = timeout + a.timeout_factor * more
                    st, dt = run_tests(root, tests_for(root, mod, tdir), a.python, t_out)
                    mod.write_bytes(original)
                    _drop_pyc(mod)
                    results.append({**asdict(m), "status": st, "seconds": round(dt, 1)})
                    print(f"  {st:9s} {dt:6.1f} s  {m.label()}", flush=True)
                    if a.json:  # kept up to date: a stopped run keeps what it ran
                        a.json.write_text(json.dumps({"totals": totals, "results": results}))
            finally:
                mod.write_bytes(original)
                _drop_pyc(mod)
            assert mod.read_bytes() == original
    if a.list:
        print(f"{totals['sampled']} mutants of {totals['sites']} would run")
        return 0
    print(f"{totals['sampled']} mutants of {totals['sites']} run", flush=True)
    counts: dict[str, int] = {}
    for r in results:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    n = len(results)
    killed = counts.get("killed", 0) + counts.get("timeout", 0)
    print("  ".join(f"{k}: {v}" for k, v in sorted(counts.items())))
    if n:
        print(f"kill rate {killed}/{n} = {100 * killed / n:.1f} % (timeouts count as killed)")
    for r in results:
        if r["status"] == "survived":
            print(f"SURVIVED {r['path']}:{r['line']}: {r['old']!r} -> {r['new']!r}")
    if a.json:
        a.json.write_text(json.dumps({"totals": totals, "results": results}, indent=1))
    return 0


def _summary(results: list[dict], totals: dict[str, int], out: Path | None) -> None:
    counts: dict[str, int] = {}
    for r in results:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    n = len(results)
    killed = counts.get("killed", 0) + counts.get("timeout", 0)
    print("  ".join(f"{k}: {v}" for k, v in sorted(counts.items())))
    if n:
        print(f"kill rate {killed}/{n} = {100 * killed / n:.1f} % (timeouts count as killed)")
    for r in results:
        if r["status"] == "survived":
            print(f"SURVIVED {r['path']}:{r['line']}: {r['old']!r} -> {r['new']!r}")
    if out:
        out.write_text(json.dumps({"totals": totals, "results": results}, indent=1))


def run_spherical(a: argparse.Namespace, root: Path) -> int:
    """The modules of :data:`SPHERICAL` (``--modules`` picks by stem), each mutant against
    its module's own test files with ``-m "not slow"``; unmutated runs set the timeouts."""
    if not a.list:
        check_root(root, "eyeviz", a.python)
    rng = random.Random(a.seed)
    totals = {"sites": 0, "sampled": 0}
    plan: list[tuple[Path, list[Mutant], tuple[str, ...]]] = []
    for rel, tests in SPHERICAL.items():
        mod = root / rel
        if a.modules and mod.stem not in a.modules:
            continue
        every = mutants_of(rel, mod.read_text())
        pick = sorted(
            rng.sample(every, min(a.per_module, len(every))), key=lambda m: (m.line, m.col)
        )
        plan.append((mod, pick, tests))
        totals["sites"] += len(every)
        totals["sampled"] += len(pick)
        print(f"{rel}: {len(pick)} of {len(every)} mutants", flush=True)
    if a.list:
        print(f"{totals['sampled']} mutants of {totals['sites']} would run")
        return 0
    base: dict[tuple[str, ...], float] = {}
    results: list[dict] = []
    for mod, pick, tests in plan:
        if tests not in base:
            status, base[tests] = run_tests(root, list(tests), a.python, 3600.0, "not slow")
            if status != "survived":
                raise SystemExit(f"{tests} fail without any mutant ({status}): fix that first")
            print(f"{' '.join(tests)}: {base[tests]:.1f} s unmutated", flush=True)
        t_out = a.timeout_factor * base[tests] + 20.0
        original = mod.read_bytes()
        src = original.decode()
        try:
            for m in pick:
                mod.write_text(m.apply(src))
                _drop_pyc(mod)
                st, dt = run_tests(root, list(tests), a.python, t_out, "not slow")
                mod.write_bytes(original)
                _drop_pyc(mod)
                results.append({**asdict(m), "status": st, "seconds": round(dt, 1)})
                print(f"  {st:9s} {dt:6.1f} s  {m.label()}", flush=True)
                if a.json:
                    a.json.write_text(json.dumps({"totals": totals, "results": results}))
        finally:
            mod.write_bytes(original)
            _drop_pyc(mod)
        assert mod.read_bytes() == original
    print(f"{totals['sampled']} mutants of {totals['sites']} run", flush=True)
    _summary(results, totals, a.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
