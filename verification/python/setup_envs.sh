#!/usr/bin/env bash
# Creates (or checks) the two Python environments of the reference scripts:
#   .venv-skfem    Python 3.11 + requirements-skfem.txt   (scikit-fem, numpy, scipy, scikit-learn)
#   .venv-fenicsx  Python 3.12 + requirements-fenicsx.txt (dolfinx-solver-real, mpi4py, numpy)
# at the repository root (both ignored by git: /.venv*).
#
# Idempotent: an environment whose stamp (interpreter version + requirements file) matches and
# whose imports work is left alone. Quiet on success; on failure it prints pip's log and exits 1.
# Needs: Python 3.11 (python3.11, python3 or pyenv), Python 3.12 (pyenv or python3.12), network
# access to PyPI, and a C compiler (cc) for the FFCx just-in-time compilation of DOLFINx forms.
# Environment: PALPA_PY311 / PALPA_PY312 override the interpreters; PALPA_VENV_DIR the location.
set -euo pipefail

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
VENV_DIR="${PALPA_VENV_DIR:-$ROOT}"

die() { echo "setup_envs.sh: error: $*" >&2; exit 1; }

# Prints the absolute path of the first candidate interpreter whose version is $1 (e.g. 3.12).
find_python() {
    local want="$1"; shift
    local c exe
    for c in "$@"; do
        [ -n "$c" ] || continue
        exe="$("$c" -c "import sys; print(sys.executable if '%d.%d' % sys.version_info[:2] == '$want' else '')" 2>/dev/null)" || continue
        if [ -n "$exe" ]; then echo "$exe"; return 0; fi
    done
    return 1
}

pyenv_candidates() {  # pyenv-installed interpreters of version $1, newest patch level first
    local want="$1" roots=() r
    if command -v pyenv >/dev/null 2>&1; then roots+=("$(pyenv root 2>/dev/null || true)"); fi
    roots+=("${PYENV_ROOT:-}" "$HOME/.pyenv")
    for r in "${roots[@]}"; do
        [ -n "$r" ] && [ -d "$r/versions" ] || continue
        ls -d "$r/versions/$want".* 2>/dev/null | grep -E "/$want\.[0-9]+$" | sort -Vr |
            while read -r d; do echo "$d/bin/python$want"; done
    done
}

PY311="$(find_python 3.11 "${PALPA_PY311:-}" python3.11 python3 $(pyenv_candidates 3.11))" ||
    die "no Python 3.11 found (tried \$PALPA_PY311, python3.11, python3, pyenv versions 3.11.*)"
PY312="$(find_python 3.12 "${PALPA_PY312:-}" $(pyenv_candidates 3.12) python3.12)" ||
    die "no Python 3.12 found (tried \$PALPA_PY312, pyenv versions 3.12.*, python3.12); dolfinx-solver-real needs >= 3.12"
command -v cc >/dev/null 2>&1 || command -v gcc >/dev/null 2>&1 ||
    die "no C compiler (cc): DOLFINx compiles its forms just in time through FFCx/cffi"

# make_env NAME PYTHON REQUIREMENTS CHECK_CODE
make_env() {
    local name="$1" py="$2" req="$3" check="$4"
    local venv="$VENV_DIR/$name" log stamp
    stamp="$("$py" -c 'import sys; print(sys.version.split()[0])') $(sha256sum "$req" | cut -c1-16)"
    if [ -x "$venv/bin/python" ] && [ "$(cat "$venv/.palpa-stamp" 2>/dev/null)" = "$stamp" ] &&
        "$venv/bin/python" -c "$check" >/dev/null 2>&1; then
        return 0  # up to date
    fi
    log="$(mktemp)"
    {
        rm -rf "$venv" &&
            "$py" -m venv "$venv" &&
            "$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-input \
                --only-binary=:all: -r "$req"
    } >"$log" 2>&1 || { cat "$log" >&2; rm -f "$log"; die "could not build $venv from $req with $py"; }
    "$venv/bin/python" -c "$check" >"$log" 2>&1 ||
        { cat "$log" >&2; rm -f "$log"; die "$venv was built but its imports fail"; }
    rm -f "$log"
    echo "$stamp" >"$venv/.palpa-stamp"
}

make_env .venv-skfem "$PY311" "$HERE/requirements-skfem.txt" \
    "import numpy, scipy, skfem, sklearn" &
pid_sk=$!
make_env .venv-fenicsx "$PY312" "$HERE/requirements-fenicsx.txt" \
    "from mpi4py import MPI; import dolfinx, dolfinx.fem.petsc, basix, ffcx, ufl" &
pid_fx=$!
status=0
wait "$pid_sk" || status=1
wait "$pid_fx" || status=1
[ "$status" = 0 ] || die "environment setup failed (see above)"
