#!/usr/bin/env bash
# Idempotent set-up on a fresh Debian machine: system packages for Qt/Xvfb,
# a virtual environment in .venv/, numpy and numba first (the kernels compile beside the
# rest), then torch (CPU build, pinned) and eyeviz.
set -euo pipefail
cd "$(dirname "$0")/.."

APT_PACKAGES="xvfb xauth libxcb-icccm4 libxcb-keysyms1 libxcb-xinerama0 libxcb-image0 \
libxcb-render-util0 libxcb-randr0 libxcb-shape0 libxcb-xfixes0 libxcb-xkb1 libxkbcommon-x11-0 \
libgl1 libegl1 libxrender1 \
libfontconfig1 libdbus-1-3 poppler-utils xdotool openbox"

missing=""
for p in $APT_PACKAGES; do
    dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"
done
# On a fresh machine the system packages install beside pip's (apt waits on the network
# and dpkg on the disk, pip on its own downloads): both finish before this script does.
apt_install() {
    export DEBIAN_FRONTEND=noninteractive
    if [ "$(id -u)" = 0 ]; then
        apt-get update -qq >/dev/null && apt-get install -y -qq $missing >/dev/null
    elif command -v sudo >/dev/null 2>&1; then
        sudo apt-get update -qq >/dev/null &&
            sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $missing >/dev/null
    else
        echo "eyeviz setup: missing system packages (install them as root):$missing" >&2
    fi
}
apt_pid=""
if [ -n "$missing" ]; then
    echo "eyeviz setup: installing system packages:$missing" >&2
    apt_install &
    apt_pid=$!
fi

# Compile the numba kernels once into their cache (eyeviz/core/kernels/__pycache__), so
# neither a first run nor a test worker compiles them (a few seconds when already warm).
# Two processes, half the kernel modules each (a cold compile is single-threaded): the
# HEALPix modules (healpix_*, which share their ring and boundary helpers) in one, the
# limits' (which share limit3d_affine's and limit3d_region's) in the other, about 37
# CPU-seconds each (every other module of KERNELS, as before, was 23 and 53: the longer
# half is the set-up's longest path). On a first install they start as soon as numpy and
# numba are in, beside pip's install of the rest (the kernels import nothing else:
# PYTHONPATH finds eyeviz before its install).
warm_half() {
    PYTHONPATH=$PWD${PYTHONPATH:+:$PYTHONPATH} .venv/bin/python -c "from eyeviz.core import \
kernels as k; k.warm(tuple(n for n in k.KERNELS if n.startswith('healpix_') == $1))"
}
warm_kernels() {
    warm_half False &
    local half=$! ok=1
    warm_half True || ok=0
    wait "$half" || ok=0
    [ "$ok" = 1 ]
}

# Byte code of the packages eyeviz runs on, written once here (even under
# PYTHONDONTWRITEBYTECODE, which these machines set: an app start would otherwise compile
# them again each time). pip installs with --no-compile: compiling every file of every
# wheel (13,900, torch's and sympy's included) cost about 50 CPU-seconds, on one core in
# pip's own step, where importing what eyeviz uses compiles about a third of that. What no
# import here reaches compiles on its first use, as any Python does.
warm_imports() {
    env -u PYTHONDONTWRITEBYTECODE PYTHONPATH=$PWD${PYTHONPATH:+:$PYTHONPATH} \
        .venv/bin/python -c "import $1" >/dev/null 2>&1
}
warm_all_imports() {
    warm_imports "torch, numba, scipy.optimize, scipy.stats, scipy.spatial, scipy.special, pandas" &
    local torch=$! ok=1
    warm_imports "eyeviz.app.window, pyvistaqt, vtkmodules.util.vtkAlgorithm, matplotlib.pyplot, \
matplotlib.backends.backend_agg, matplotlib.backends.backend_qt5agg, PIL.features, \
PIL.JpegImagePlugin, PIL.GifImagePlugin, PIL.BmpImagePlugin, PIL.PpmImagePlugin, \
distributed, dask.array, hypothesis, pytest, xdist, pytestqt, pytest_timeout" || ok=0
    wait "$torch" || ok=0
    [ "$ok" = 1 ]
}

PY=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
    "$PY" -m venv .venv
fi
# eyeviz's byte code, written even under PYTHONDONTWRITEBYTECODE (read all the same): the
# tests' Python processes then load it, not compile it (beside pip; quick when current)
.venv/bin/python -m compileall -q eyeviz >/dev/null 2>&1 &
stamp=.venv/.eyeviz-installed
fresh=0
if [ ! -f "$stamp" ] || [ pyproject.toml -nt "$stamp" ]; then
    echo "eyeviz setup: installing Python packages into .venv (first run takes a few minutes)" >&2
    log=.venv/setup.log
    {
        .venv/bin/python -m pip install --upgrade pip &&
        # what the kernels need first (pyproject's bounds), so that their cold compile
        # (the set-up's longest part on 2 cores) starts seconds in and runs beside the
        # rest; torch pinned (its CPU build: any other request pulls a multi-GB CUDA one)
        .venv/bin/python -m pip install --no-compile "numpy>=1.26" "numba>=0.60" &&
        { { warm_kernels && echo "$SECONDS" >.venv/.kernels-compiled-at; } & } &&
        warm_pid=$! &&
        .venv/bin/python -m pip install --no-compile "torch==2.13.0" -e ".[app,ml,study,dev]"
    } >"$log" 2>&1 || {
        wait
        tail -n 30 "$log" >&2
        echo "eyeviz setup: pip failed (log: $log)" >&2
        exit 1
    }
    touch "$stamp"
    fresh=1
    pip_done=$SECONDS
fi
if [ -n "$apt_pid" ] && ! wait "$apt_pid"; then
    echo "eyeviz setup: installing the system packages failed:$missing" >&2
    exit 1
fi
# After an install, the packages' byte code (beside the compile begun beside pip, which
# often runs on after pip: started after it, the imports left a core idle while one
# half of the compile finished). Then wait for that compile and warm (again): the cache
# is read in a few seconds, and what pip's second step changed (a numba or numpy
# version) compiles now.
imports=
if [ "$fresh" = 1 ]; then
    warm_all_imports &
    imports=$!
fi
if [ -n "${warm_pid:-}" ]; then
    wait "$warm_pid" || true
fi
warm_kernels ||
    echo "eyeviz setup: warming the compiled kernels failed (they compile on first use)" >&2
if [ -n "$imports" ] && ! wait "$imports"; then
    echo "eyeviz setup: importing the installed packages failed:" \
        ".venv/bin/python -c 'import torch, eyeviz.app.window' shows why" >&2
fi
wait  # eyeviz's byte code (compileall, begun first)
if [ "$fresh" = 1 ]; then  # where a first install's time went (CI logs show it)
    echo "eyeviz setup: ${SECONDS} s (pip's install ended at ${pip_done} s, the kernels'" \
        "cold compile at $(cat .venv/.kernels-compiled-at 2>/dev/null || echo '?') s)" >&2
fi
