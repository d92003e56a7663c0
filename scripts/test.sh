#!/usr/bin/env bash
# The README's test command: set up everything, lint, then run the whole suite
# under a virtual X display (GUI tests drive a real Qt/VTK window).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
.venv/bin/ruff check eyeviz tests scripts
export QT_API=pyqt5 MPLBACKEND=Agg
if [ -n "${DISPLAY:-}" ]; then
    exec .venv/bin/python -m pytest "$@"
fi
exec xvfb-run -a -s "-screen 0 1920x1080x24" .venv/bin/python -m pytest "$@"
