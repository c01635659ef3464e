#!/usr/bin/env bash
# Run the whole test suite from scratch:   bash tests/run.sh [pytest arguments]
#
# Works on a fresh Debian 12 with Python 3.11 and nothing else:
#   1. installs the Debian packages for a headless Qt + VTK (Xvfb and friends,
#      see DESIGN.md) when some are missing, with apt-get (sudo when not root);
#   2. creates the virtual environment .venv in the repository (once) and
#      installs the project into it with
#      `pip install -c tests/constraints.txt -e .[test]` (the test tools at the
#      versions pinned there; again only when pyproject.toml or the constraints
#      changed);
#   3. checks the code: `ruff check .` and `mypy` on gcmh_core and the Qt-free
#      modules of gcmh_studio (their settings are in pyproject.toml);
#   4. runs `python -m pytest --xvfb-backend xvfb "$@"` (tests/app run on Xvfb).
# The tests run even when step 3 finds something; the exit status is then 1 and the
# last line says which check failed.
#
# Environment: GCMH_SKIP_APT=1 skips step 1; GCMH_SKIP_LINT=1 skips step 3;
# PYTHON=/path/to/python picks the interpreter for a new .venv (default python3.11,
# else python3).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

say() { printf 'tests/run.sh: %s\n' "$*" >&2; }
die() { say "error: $*"; exit 1; }

# ---------------------------------------------------------------- interpreter
PY="${PYTHON:-}"
if [[ -z "$PY" ]]; then
    if command -v python3.11 >/dev/null 2>&1; then PY=python3.11
    elif command -v python3 >/dev/null 2>&1; then PY=python3
    else die "no python3.11 or python3 on PATH"
    fi
fi
PYVER="$("$PY" -c 'import sys; print("%d.%d" % sys.version_info[:2])')" || die "cannot run $PY"
"$PY" -c 'import sys; sys.exit(sys.version_info < (3, 10))' || die "$PY is Python $PYVER; need 3.10 or newer"

# ---------------------------------------------------------------- Debian packages
PKGS=(
    xvfb xauth libgl1 libegl1 libglib2.0-0 libfontconfig1 libdbus-1-3 libxkbcommon-x11-0
    libxcb-icccm4 libxcb-image0 libxcb-keysyms1 libxcb-render-util0 libxcb-shape0
    libxcb-xinerama0 libxcb-xkb1 libxcursor1
)
venv_ok() { [[ -x .venv/bin/python ]] && .venv/bin/python -c 'import sys' >/dev/null 2>&1; }
if ! venv_ok && ! "$PY" -c 'import ensurepip, venv' >/dev/null 2>&1; then
    # Debian's own python3.x lacks ensurepip until pythonX.Y-venv is installed.
    PKGS+=("python${PYVER}-venv")
fi

if [[ "${GCMH_SKIP_APT:-0}" != 1 ]] && command -v dpkg-query >/dev/null 2>&1; then
    missing=()
    for pkg in "${PKGS[@]}"; do
        status="$(dpkg-query -W -f='${db:Status-Status}' "$pkg" 2>/dev/null || true)"
        [[ "$status" == installed ]] || missing+=("$pkg")
    done
    if ((${#missing[@]})); then
        SUDO=()
        if [[ "$(id -u)" -ne 0 ]]; then
            command -v sudo >/dev/null 2>&1 \
                || die "missing Debian packages (${missing[*]}) and not root, no sudo: install them, or set GCMH_SKIP_APT=1"
            SUDO=(sudo)
        fi
        say "installing Debian packages: ${missing[*]}"
        "${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q
        "${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive \
            apt-get install -y -q --no-install-recommends "${missing[@]}"
    fi
fi

# ---------------------------------------------------------------- virtual environment
if ! venv_ok; then
    rm -rf .venv
    say "creating .venv with $PY (Python $PYVER)"
    "$PY" -m venv .venv
fi
VPY="$ROOT/.venv/bin/python"
export PIP_DISABLE_PIP_VERSION_CHECK=1
# The stamp is what was installed from: a change of either file installs again.
STAMP=.venv/.gcmh-installed
WANTED="$(cat pyproject.toml tests/constraints.txt)"
if [[ "$WANTED" != "$(cat "$STAMP" 2>/dev/null)" ]] \
    || ! "$VPY" -c 'import gcmh_core, gcmh_studio, pytest, pytestqt, pytest_xvfb, ruff, mypy' >/dev/null 2>&1; then
    say "installing the project: pip install -c tests/constraints.txt -e .[test]"
    "$VPY" -m pip install -q -c tests/constraints.txt -e ".[test]"
    printf '%s' "$WANTED" > "$STAMP"
fi

# ---------------------------------------------------------------- environment
# Qt wants a private runtime folder (0700); this silences its warning.
if [[ -z "${XDG_RUNTIME_DIR:-}" || ! -d "${XDG_RUNTIME_DIR:-}" || ! -O "${XDG_RUNTIME_DIR:-}" ]]; then
    export XDG_RUNTIME_DIR="${TMPDIR:-/tmp}/gcmh-runtime-$(id -u)"
fi
mkdir -p "$XDG_RUNTIME_DIR"
chmod 700 "$XDG_RUNTIME_DIR"

# ---------------------------------------------------------------- lint and types
# Caches go into .venv (ignored by git) rather than the repository's top level.
failed=()
if [[ "${GCMH_SKIP_LINT:-0}" != 1 ]]; then
    say "ruff check . (pyproject.toml [tool.ruff])"
    RUFF_CACHE_DIR=.venv/.ruff_cache "$VPY" -m ruff check . || failed+=(ruff)
    say "mypy on gcmh_core and the Qt-free modules of gcmh_studio (pyproject.toml [tool.mypy])"
    "$VPY" -m mypy --cache-dir .venv/.mypy_cache || failed+=(mypy)
fi

# ---------------------------------------------------------------- tests
# --xvfb-backend xvfb: tests/app need a real X server; with the flag a missing
# Xvfb is a clear usage error rather than "Fatal Python error: Aborted".
XVFB=(--xvfb-backend xvfb)
for arg in "$@"; do
    case "$arg" in
        no:xvfb|-pno:xvfb|--no-xvfb|--xvfb-backend*) XVFB=() ;;
    esac
done
status=0
"$VPY" -m pytest "${XVFB[@]}" "$@" || status=$?
if ((${#failed[@]})); then
    say "FAILED: ${failed[*]} found problems (listed above); pytest exited with $status"
    ((status)) || status=1
fi
exit "$status"
