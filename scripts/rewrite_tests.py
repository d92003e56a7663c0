"""Write pytest's assert-rewritten byte code of every test module once, before the test
stages start (scripts/test.sh; issue 31: the CI's 10 minutes).

pytest rewrites each test module's asserts as it imports it and caches the result in
``__pycache__`` (``*.cpython-311-pytest-<version>.pyc``, checked against the source's
hash). On a fresh clone there is no such cache, and the stages' four test workers start
at once: each rewrote every module it collects (about 5.5 CPU-seconds in each
display-free worker, 1.1 in each GUI worker). Here it is done once, in about 3.5, with
pytest's own rewriting (the same code objects pytest would make and cache itself); a
module already cached is skipped, and one edited later is rewritten by pytest as usual.

Written even under PYTHONDONTWRITEBYTECODE (pytest reads the cache then too). pytest's
rewriting is not public API: if it moves, this script says so and exits 0, and pytest
rewrites as it always did.

    .venv/bin/python scripts/rewrite_tests.py [tests]
"""

from __future__ import annotations

import os
import sys
from pathlib import Path


def main(root: str = "tests") -> int:
    try:
        from _pytest.assertion import rewrite as rw
        from _pytest.config import _prepareconfig

        config = _prepareconfig(["-p", "no:cacheprovider"])
        patterns = [*config.getini("python_files"), "conftest.py"]
        for fn in sorted(Path(os.path.abspath(root)).rglob("*.py")):  # as pytest names them
            if not any(fn.match(p) for p in patterns):
                continue
            pyc = rw.get_cache_dir(fn) / (fn.name[:-3] + rw.PYC_TAIL)
            if rw._read_pyc(fn, pyc) is not None:
                continue
            try:
                source_hash, co = rw._rewrite_test(fn, config)
            except SyntaxError:
                continue  # pytest reports it when it collects the module
            if not rw.try_makedirs(pyc.parent):
                continue
            tmp = f"{pyc}.{os.getpid()}"
            with open(tmp, "wb") as fp:
                rw._write_pyc_fp(fp, source_hash, co)
            os.replace(tmp, pyc)  # atomic: a reader sees a whole pyc or none (pytest's way)
    except Exception as exc:  # noqa: BLE001 (pytest's internals moved, a read-only tree...)
        print(f"rewrite_tests: stopped ({type(exc).__name__}: {exc})", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
