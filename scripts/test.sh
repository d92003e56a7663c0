#!/usr/bin/env bash
# The README's test command. Sets up everything (scripts/setup.sh), then runs three stages
# and reports each, carrying on when one fails (the exit status is non-zero if any did):
#   1. the guardrails: ruff lint and format, import-linter's layer contracts, mypy;
#   2. the display-free tests (everything but tests/app);
#   3. the GUI tests under a virtual X display (they drive a real Qt/VTK window).
# In the full run the three run at once (see below); --quick runs 1 then 2.
# The tests run on every core (pytest-xdist, `-n <cores>`; EYEVIZ_TEST_WORKERS=N sets
# the number, 1 runs them in this process); under xdist each GUI worker starts an Xvfb
# display of its own (tests/app/conftest.py), so real key presses never meet another
# worker's window.
#
#   scripts/test.sh [pytest args]          every test (extra arguments go to both runs, e.g. -q)
#   scripts/test.sh --quick [pytest args]  a tier under 2 minutes: ruff, then the
#                                          display-free tests not marked slow or gui
set -uo pipefail
cd "$(dirname "$0")/.."

quick=0
if [ "${1:-}" = "--quick" ]; then
    quick=1
    shift
fi

bash scripts/setup.sh || exit 1
export QT_API=pyqt5 MPLBACKEND=Agg

workers=${EYEVIZ_TEST_WORKERS:-$(nproc 2>/dev/null || echo 1)}
par=()
if [ "$workers" -gt 1 ]; then
    # loadgroup: tests spread one by one, but an xdist_group runs on one worker, in
    # order (the fuzz modules' closing tests read what the module's other tests recorded)
    par=(-n "$workers" --dist loadgroup)
fi

logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
summary=()
failed=0
start=$SECONDS

# summarise NAME LOG RC SECONDS: one summary line for a stage (its pytest result line)
summarise() {
    local name=$1 log=$2 rc=${3:-1} secs=${4:-?} last
    last=$(grep -E '^(=+ )?[0-9]+ (passed|failed|error|skipped|deselected).* in [0-9.]+s' "$log" |
        tail -n 1 | sed -E 's/^=+ //; s/ =+$//')
    if [ "$rc" -eq 0 ]; then
        summary+=("$name: ok${last:+ ($last)}, $secs s")
    else
        summary+=("$name: FAILED (exit $rc)${last:+ ($last)}, $secs s")
        failed=1
    fi
}

# stage NAME LOG CMD...: run CMD, its output also to LOG; one summary line for NAME
stage() {
    local name=$1 log=$2 t0=$SECONDS rc
    shift 2
    echo "== $name" >&2
    "$@" 2>&1 | tee "$log"
    rc=${PIPESTATUS[0]}
    summarise "$name" "$log" "$rc" "$((SECONDS - t0))"
}

guardrails() {
    local rc=0
    echo "-- ruff (lint, format)"
    .venv/bin/ruff check eyeviz tests scripts examples || rc=1
    .venv/bin/ruff format --check eyeviz tests scripts examples || rc=1
    if [ "$quick" = 0 ]; then
        echo "-- import-linter (layers)"
        .venv/bin/lint-imports --no-cache || rc=1
        echo "-- mypy (the whole package)"
        .venv/bin/mypy || rc=1
    fi
    return $rc
}

# pytest's rewritten asserts of every test module, written once (scripts/rewrite_tests.py):
# on a fresh clone each of the four test workers rewrote every module it collected (about
# 13 CPU-seconds in all, where this takes about 4); quick when the cache is current
rewrite_tests() {
    .venv/bin/python scripts/rewrite_tests.py tests || true
}

gui_tests() {
    if [ -n "${DISPLAY:-}" ]; then
        .venv/bin/python -m pytest tests/app -p no:cacheprovider "${par[@]}" "$@"
    else
        xvfb-run -a -s "-screen 0 1920x1080x24" \
            .venv/bin/python -m pytest tests/app -p no:cacheprovider "${par[@]}" "$@"
    fi
}

if [ "$quick" = 1 ]; then
    stage "guardrails (ruff)" "$logs/guard" guardrails
    rewrite_tests
    stage "display-free tests, quick tier (not slow, not gui)" "$logs/free" \
        env -u DISPLAY .venv/bin/python -m pytest --ignore=tests/app -p no:cacheprovider \
        -m "not slow and not gui" "${par[@]}" "$@"
else
    # The three run at once: the GUI tests' workers wait for windows, X and timers, and
    # the guardrails are one core's half minute, so beside the display-free tests (both
    # cores busy, but for their processes' start-ups and the studies' waits) they fill
    # the idle part of the cores that running one stage after another left (issue 31).
    # Each writes its own log, shown when all have finished.
    background() {  # background NAME CMD...: CMD's output, exit code and seconds to files
        local name=$1 t0=$SECONDS
        shift
        "$@" >"$logs/$name" 2>&1
        echo $? >"$logs/$name.rc"
        echo $((SECONDS - t0)) >"$logs/$name.time"
    }
    # a script's background jobs ignore Ctrl-C: on Ctrl-C or SIGTERM every stage ends
    trap 'trap - INT TERM; echo "scripts/test.sh: interrupted" >&2; kill -TERM 0' INT TERM
    background guard guardrails &
    guard_pid=$!
    rewrite_tests  # beside the guardrails, before any test worker collects
    background gui gui_tests "$@" &
    gui_pid=$!
    stage "display-free tests" "$logs/free" \
        env -u DISPLAY .venv/bin/python -m pytest --ignore=tests/app -p no:cacheprovider \
        "${par[@]}" "$@"
    wait "$gui_pid" "$guard_pid"
    echo "== GUI tests (Xvfb; ran beside the display-free tests)" >&2
    cat "$logs/gui"
    echo "== guardrails (ruff, import-linter, mypy; ran beside the display-free tests)" >&2
    cat "$logs/guard"
    summarise "GUI tests (Xvfb)" "$logs/gui" "$(cat "$logs/gui.rc" 2>/dev/null)" \
        "$(cat "$logs/gui.time" 2>/dev/null)"
    if [ "$(cat "$logs/guard.rc" 2>/dev/null)" = 0 ]; then
        summary=("guardrails (ruff, import-linter, mypy): ok, $(cat "$logs/guard.time") s" \
            "${summary[@]}")
    else
        summary=("guardrails (ruff, import-linter, mypy): FAILED, $(cat "$logs/guard.time") s" \
            "${summary[@]}")
        failed=1
    fi
fi

echo "== summary ($((SECONDS - start)) s, ${workers} worker(s))" >&2
for line in "${summary[@]}"; do
    echo "$line" >&2
done
exit $failed
