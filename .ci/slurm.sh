#!/usr/bin/env bash
# A real Slurm on this machine, and scenes/campaign-slurm.sbatch on it (docs/cluster.md):
#
#   1. install Debian's slurm-wlm and munge (apt-get, when they are missing);
#   2. a one-node cluster on loopback: munged, slurmctld and slurmd with a private
#      configuration and state under /tmp (no cgroups, no accounting), the node's CPUs and
#      memory read from this machine;
#   3. the quick campaign (scenes/campaign-quick.toml) as an array job of 2 shards and the
#      dependent merge, submitted by the sbatch script itself; the merged dataset compared
#      byte for byte with an unsharded run of the same campaign;
#   4. one task's output deleted (the whole shard directory, as a lost node would leave it) and
#      that task alone resubmitted with --array=1, which used to fail with `--shard 1/1`; the
#      merge again compared byte for byte;
#   5. the daemons stopped (also on failure).
#
#   bash .ci/slurm.sh [UNSHARDED_DIR]
#
# It uses the release binary target/release/palpa (build it first). UNSHARDED_DIR is a finished
# unsharded run of scenes/campaign-quick.toml by that binary (.ci/run passes the surrogate
# chain's); without it the script runs one. Everything it writes lies in target/slurm and a
# fresh /tmp/palpa-slurm.* directory (removed at the end unless KEEP_SLURM_STATE=1).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
ROOT=$PWD
PALPA=$ROOT/target/release/palpa
CAMPAIGN=$ROOT/scenes/campaign-quick.toml
SBATCH_SCRIPT=$ROOT/scenes/campaign-slurm.sbatch
WORK=$ROOT/target/slurm
OUT=$WORK/campaign
REFERENCE=${1:-}
JOB_TIMEOUT=${JOB_TIMEOUT:-300} # seconds a submission may take, queueing included

[[ $(id -u) == 0 ]] || {
    echo "slurm.sh: run me as root: I install packages and start slurmd" >&2
    exit 1
}
[[ -x $PALPA ]] || {
    echo "slurm.sh: $PALPA is missing: cargo build --release first" >&2
    exit 1
}

# --- stage timings ---------------------------------------------------------------------------
T_ALL=$SECONDS
STAGE=""
T_STAGE=$SECONDS
TIMINGS=()
stage() {
    end_stage
    STAGE=$1
    T_STAGE=$SECONDS
    echo "-- $STAGE"
}
end_stage() {
    if [[ -n $STAGE ]]; then
        local dt=$((SECONDS - T_STAGE))
        TIMINGS+=("$(printf '%5d s  %s' "$dt" "$STAGE")")
        echo "   ($STAGE: $dt s)"
        STAGE=""
    fi
}

# --- cleanup: our jobs cancelled, our daemons stopped (by the pids they recorded) -----------
STATE=""
JOBS=()
OK=0
stop_pid() { # stop_pid NAME PIDFILE
    local pid
    [[ -s $2 ]] || return 0
    pid=$(<"$2")
    if kill -0 "$pid" 2>/dev/null; then
        kill "$pid" 2>/dev/null || true
        for _ in $(seq 50); do
            kill -0 "$pid" 2>/dev/null || break
            sleep 0.1
        done
        if kill -0 "$pid" 2>/dev/null; then
            echo "   $1 ($pid) did not stop: killing it"
            kill -9 "$pid" 2>/dev/null || true
        fi
    fi
}
cleanup() {
    local rc=$?
    end_stage
    if [[ -n $STATE ]]; then
        if ((${#JOBS[@]})) && [[ -s $STATE/slurmctld.pid ]]; then
            scancel "${JOBS[@]}" 2>/dev/null || true
        fi
        if ((OK == 0)); then
            echo "== slurm.sh failed: the last lines of the daemons' and jobs' logs"
            for f in "$STATE"/slurmctld.log "$STATE"/slurmd.log "$STATE"/munge/munged.log "$WORK"/*.log; do
                [[ -f $f ]] || continue
                echo "--- $f"
                tail -n 25 "$f"
            done
        fi
        stop_pid slurmd "$STATE/slurmd.pid"
        stop_pid slurmctld "$STATE/slurmctld.pid"
        stop_pid munged "$STATE/munge/munged.pid"
        echo "   daemons stopped"
        if [[ ${KEEP_SLURM_STATE:-0} == 1 ]]; then
            echo "   state kept in $STATE"
        else
            rm -rf "$STATE"
        fi
    fi
    echo "== slurm.sh stage timings"
    printf '%s\n' "${TIMINGS[@]}"
    echo "   total $((SECONDS - T_ALL)) s: $([[ $OK == 1 ]] && echo passed || echo FAILED)"
    exit "$rc"
}
trap cleanup EXIT

# --- 1. packages -----------------------------------------------------------------------------
stage "install slurm-wlm and munge"
if command -v slurmctld >/dev/null && command -v slurmd >/dev/null && command -v sbatch >/dev/null &&
    command -v munged >/dev/null; then
    echo "   already installed: $(slurmctld -V), munge $(munged -V 2>&1 | head -n 1)"
else
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
    echo "   installed: $(slurmctld -V), $(munged -V 2>&1 | head -n 1)"
fi

# --- 2. the cluster --------------------------------------------------------------------------
stage "start munged, slurmctld and slurmd (one node on loopback)"
STATE=$(mktemp -d /tmp/palpa-slurm.XXXXXX)
chmod 0755 "$STATE"
HOST=$(hostname -s)
CPUS=$(nproc)
MEM_MB=$(awk '/^MemTotal:/ { print int($2 / 1024) }' /proc/meminfo)
if [[ -r /sys/fs/cgroup/memory.max ]] && [[ $(</sys/fs/cgroup/memory.max) =~ ^[0-9]+$ ]]; then
    CG_MB=$(($(</sys/fs/cgroup/memory.max) / 1048576))
    ((CG_MB < MEM_MB)) && MEM_MB=$CG_MB
fi
MEM_MB=$((MEM_MB * 9 / 10)) # leave the system some room
echo "   node $HOST: $CPUS CPUs, RealMemory $MEM_MB MB; state in $STATE"

# munge: a private daemon, key and socket
mkdir -m 0711 "$STATE/munge"
dd if=/dev/urandom of="$STATE/munge/munge.key" bs=1024 count=1 status=none
chmod 0400 "$STATE/munge/munge.key"
MUNGE_SOCKET=$STATE/munge/munge.socket
munged --force --socket="$MUNGE_SOCKET" --key-file="$STATE/munge/munge.key" \
    --pid-file="$STATE/munge/munged.pid" --log-file="$STATE/munge/munged.log" \
    --seed-file="$STATE/munge/munged.seed"
munge --socket="$MUNGE_SOCKET" -n | unmunge --socket="$MUNGE_SOCKET" >/dev/null
echo "   munged answers on $MUNGE_SOCKET"

mkdir -p "$STATE/ctld" "$STATE/spool"
export SLURM_CONF=$STATE/slurm.conf
cat >"$SLURM_CONF" <<EOF
# palpa CI: a one-node cluster on loopback, written by .ci/slurm.sh
ClusterName=palpa-ci
SlurmctldHost=$HOST(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$MUNGE_SOCKET
StateSaveLocation=$STATE/ctld
SlurmdSpoolDir=$STATE/spool
SlurmctldPidFile=$STATE/slurmctld.pid
SlurmdPidFile=$STATE/slurmd.pid
SlurmctldLogFile=$STATE/slurmctld.log
SlurmdLogFile=$STATE/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
# a container: no cgroups, processes tracked by their parents
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MailProg=/bin/true
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU_Memory
SlurmdParameters=config_overrides
ReturnToService=2
# finished jobs stay visible to scontrol for 10 min
MinJobAge=600
NodeName=$HOST NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=$MEM_MB State=UNKNOWN
PartitionName=ci Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -c
slurmd
echo -n "   waiting for $HOST to be idle:"
for i in $(seq 60); do
    st=$(sinfo -h -n "$HOST" -o %T 2>/dev/null || true)
    [[ $st == idle ]] && break
    ((i == 60)) && {
        echo " still \`$st\` after 60 s" >&2
        exit 1
    }
    sleep 1
done
echo " $st ($(sinfo -h -o '%P %D node(s) %c CPUs %m MB'))"

# --- jobs ------------------------------------------------------------------------------------
# The states of jobs $@ (every array task), one per line: ID STATE REASON.
states() {
    local j
    for j in "$@"; do
        scontrol -o show job "$j" | sed -E 's/.*\bArrayJobId=([0-9]+) ArrayTaskId=([^ ]+).*\bJobState=([A-Z_]+) Reason=([^ ]+).*/\1_\2 \3 \4/; t; s/.*\bJobId=([0-9]+).*\bJobState=([A-Z_]+) Reason=([^ ]+).*/\1 \2 \3/'
    done
}
# Wait until jobs $@ have ended; fail unless every one COMPLETED.
wait_jobs() {
    local t0=$SECONDS last="" now
    while :; do
        now=$(states "$@")
        if [[ $now != "$last" ]]; then
            echo "   [$((SECONDS - t0)) s] $(tr '\n' ' ' <<<"$now")"
            last=$now
        fi
        if grep -q DependencyNeverSatisfied <<<"$now"; then
            echo "a dependency failed" >&2
            return 1
        fi
        if ! grep -qE ' (PENDING|RUNNING|CONFIGURING|COMPLETING|REQUEUED|RESIZING|SUSPENDED) ' <<<"$now "; then
            break
        fi
        if ((SECONDS - t0 > JOB_TIMEOUT)); then
            echo "jobs $* still not finished after $JOB_TIMEOUT s" >&2
            return 1
        fi
        sleep 2
    done
    if grep -v ' COMPLETED ' <<<"$now" | grep -q .; then
        echo "not every job completed" >&2
        return 1
    fi
}
# Submit through the sbatch script (`submit` mode): the array with sbatch options $@, then
# the merge after it; sets ARRAY and MERGE.
submit() {
    local line
    line=$(cd "$WORK" && CAMPAIGN=$CAMPAIGN OUT=$OUT PALPA=$PALPA bash "$SBATCH_SCRIPT" submit "$@")
    echo "   $line"
    ARRAY=$(sed -E 's/.*array job ([0-9]+).*/\1/' <<<"$line")
    MERGE=$(sed -E 's/.*merge job ([0-9]+).*/\1/' <<<"$line")
    JOBS+=("$ARRAY" "$MERGE")
}
# The merged dataset against the unsharded one, byte for byte.
sha() { # the first 16 hex digits of file $1's SHA-256, or "missing"
    if [[ -f $1 ]]; then sha256sum <"$1" | cut -c1-16; else echo missing; fi
}
compare() {
    local f bad=0
    for f in dataset.npz manifest.json dataset.json view.json; do
        if cmp -s "$REFERENCE/$f" "$OUT/merged/$f"; then
            echo "   $f identical: sha256 $(sha "$OUT/merged/$f")..."
        else
            echo "   $f DIFFERS: merged $(sha "$OUT/merged/$f"), unsharded $(sha "$REFERENCE/$f")" >&2
            bad=1
        fi
    done
    return $bad
}

rm -rf "$WORK"
mkdir -p "$WORK"

# --- 3. the campaign as an array of 2 shards and the merge after it ---------------------------
stage "campaign: array job (2 shards, 1 CPU each) and the dependent merge"
submit --array=0-1
wait_jobs "$ARRAY" "$MERGE"
echo "   shard count recorded: $(<"$OUT/shard-count")"

stage "unsharded reference"
if [[ -n $REFERENCE ]]; then
    REFERENCE=$(realpath "$REFERENCE")
    [[ -f $REFERENCE/dataset.npz ]] || {
        echo "$REFERENCE has no dataset.npz" >&2
        exit 1
    }
    echo "   given: $REFERENCE"
else
    REFERENCE=$WORK/unsharded
    "$PALPA" campaign "$CAMPAIGN" --out "$REFERENCE" --quiet
    echo "   ran: palpa campaign scenes/campaign-quick.toml --out $REFERENCE"
fi

stage "merged dataset against the unsharded one"
compare

# --- 4. one task lost and resubmitted alone ---------------------------------------------------
stage "shard 1 lost, task 1 resubmitted alone (--array=1) and merged again"
lost=$(ls "$OUT/shard-1/runs")
lost=${lost//$'\n'/ }
rm -rf "$OUT/shard-1"
echo "   deleted $OUT/shard-1 (runs $lost)"
submit --array=1
wait_jobs "$ARRAY" "$MERGE"
grep -q '"shard": "1/2"' "$OUT/shard-1/campaign.json" || {
    echo "the resubmitted task did not run shard 1/2" >&2
    exit 1
}
for r in $lost; do
    [[ -f $OUT/shard-1/runs/$r/done.json ]] || {
        echo "run $r was not redone" >&2
        exit 1
    }
done
echo "   shard 1/2 redone: $lost"
compare

end_stage
OK=1
