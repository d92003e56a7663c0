#!/usr/bin/env bash
# The README's test command: set up everything, run the guardrails (ruff lint and format,
# import-linter's layer contracts, mypy on the typed layers), then the display-free tests,
# then the GUI tests under a virtual X display (they drive a real Qt/VTK window).
# Extra arguments go to both pytest runs (e.g. -q, -x).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export QT_API=pyqt5 MPLBACKEND=Agg
echo "== ruff (lint, format)" >&2
.venv/bin/ruff check eyeviz tests scripts examples
.venv/bin/ruff format --check eyeviz tests scripts examples
echo "== import-linter (layers)" >&2
.venv/bin/lint-imports --no-cache
echo "== mypy (the whole package)" >&2
.venv/bin/mypy
echo "== display-free tests" >&2
env -u DISPLAY .venv/bin/python -m pytest --ignore=tests/app -p no:cacheprovider "$@"
echo "== GUI tests (real Qt/VTK window under Xvfb)" >&2
if [ -n "${DISPLAY:-}" ]; then
    exec .venv/bin/python -m pytest tests/app -p no:cacheprovider "$@"
fi
exec xvfb-run -a -s "-screen 0 1920x1080x24" .venv/bin/python -m pytest tests/app -p no:cacheprovider "$@"
