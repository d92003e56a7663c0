#!/usr/bin/env bash
# The README's run command: set up, then open the app (extra arguments go to `eyeviz app`).
# With no display ($DISPLAY unset) it says so and writes a screenshot of the app on the
# default scene, rendered on a virtual display (xvfb-run), then prints its path.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export QT_API=pyqt5
if [ -n "${DISPLAY:-}" ] || [ -n "${WAYLAND_DISPLAY:-}" ]; then
    exec .venv/bin/eyeviz app "$@"
fi
out="${EYEVIZ_SCREENSHOT:-$PWD/eyeviz-screenshot.png}"
echo "eyeviz: no display (\$DISPLAY is not set), so no window can open here;" >&2
echo "eyeviz: rendering the app on a virtual display (xvfb-run) into a screenshot instead." >&2
if ! command -v xvfb-run >/dev/null 2>&1; then
    echo "eyeviz: xvfb-run is missing: install the 'xvfb' package (scripts/setup.sh does as root)" >&2
    exit 1
fi
xvfb-run -a -s "-screen 0 1920x1080x24" .venv/bin/eyeviz app "$@" --screenshot "$out" >/dev/null \
    2> >(grep -v -e XDG_RUNTIME_DIR -e "default format" >&2)
echo "$out"
