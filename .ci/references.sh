#!/usr/bin/env bash
# Regenerates the reference solutions of verification/data with scikit-fem and FEniCSx (DOLFINx)
# themselves, and compares them numerically with the committed files (rtol 1e-9; see
# verification/python/compare.py). Exits non-zero on any difference or failure.
#
#   .ci/references.sh            regenerate into a temporary directory and compare
#   .ci/references.sh --update   regenerate straight into verification/data (then commit)
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
PYDIR=verification/python
DATA=verification/data
UPDATE=0
[ "${1:-}" = "--update" ] && UPDATE=1

t_start=$SECONDS
echo "== references: Python environments ($PYDIR/setup_envs.sh)"
"$PYDIR/setup_envs.sh"
echo "   ready in $((SECONDS - t_start)) s"

SK=.venv-skfem/bin/python
FX=.venv-fenicsx/bin/python
echo "== references: solvers"
"$SK" -c 'import sys, skfem, scipy, numpy; print("   scikit-fem %s (scipy %s, numpy %s, Python %s)" % (skfem.__version__, scipy.__version__, numpy.__version__, sys.version.split()[0]))'
"$FX" -c 'from mpi4py import MPI; import sys, dolfinx, basix, ffcx, ufl, numpy; from petsc4py import PETSc; print("   FEniCSx: DOLFINx %s, basix %s, FFCx %s, UFL %s, PETSc %d.%d.%d, numpy %s, Python %s" % ((dolfinx.__version__, basix.__version__, ffcx.__version__, ufl.__version__) + PETSc.Sys.getVersion() + (numpy.__version__, sys.version.split()[0])))'

if [ "$UPDATE" = 1 ]; then
    OUT="$DATA"
    mkdir -p "$OUT"
else
    OUT="$(mktemp -d)"
    trap 'rm -rf "$OUT"' EXIT
fi
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1

# Two streams in parallel (one per core): scikit-fem scripts, FEniCSx scripts.
run_stream() {  # PYTHON SCRIPT...
    local py="$1"; shift
    local s t0
    for s in "$@"; do
        t0=$SECONDS
        echo "-- $s"
        "$py" "$PYDIR/$s" --out "$OUT" || { echo "FAILED: $s"; return 1; }
        echo "-- $s done in $((SECONDS - t0)) s"
    done
}
echo "== references: regenerating into $OUT"
t_gen=$SECONDS
LOGS="$(mktemp -d)"
run_stream "$SK" patch_skfem.py cantilever_skfem.py >"$LOGS/skfem.log" 2>&1 &
p1=$!
run_stream "$FX" patch_fenicsx.py block_fenicsx.py >"$LOGS/fenicsx.log" 2>&1 &
p2=$!
rc=0
wait "$p1" || rc=1
wait "$p2" || rc=1
sed 's/^/   [scikit-fem] /' "$LOGS/skfem.log"
sed 's/^/   [FEniCSx]    /' "$LOGS/fenicsx.log"
rm -rf "$LOGS"
[ "$rc" = 0 ] || { echo "references: a reference script failed"; exit 1; }
echo "   regenerated in $((SECONDS - t_gen)) s"

if [ "$UPDATE" = 1 ]; then
    echo "references: updated $DATA (total $((SECONDS - t_start)) s); review with git diff and commit"
    exit 0
fi
echo "== references: comparing with the committed $DATA"
set +e
"$SK" "$PYDIR/compare.py" "$DATA" "$OUT"
rc=$?
set -e
echo "references: total $((SECONDS - t_start)) s"
exit "$rc"
