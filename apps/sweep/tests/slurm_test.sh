#!/usr/bin/env bash
# End-to-end test of apps/sweep/slurm/ on a real, single-node Slurm started here:
#
#   slurm_test.sh PROGRAM SWEEP.json WORKDIR
#
# As root, it starts munged (its own key and socket) and slurmctld + slurmd on this host, all
# configured, spooled and logged under WORKDIR/slurm (a short directory in /tmp instead when
# WORKDIR's path is too long for Unix sockets), with the commands pointed there by SLURM_CONF and
# all traffic on 127.0.0.1. It submits the sweep with submit.sh as 3 shards plus the merge, waits
# for both jobs (at most $KELP_SLURM_TEST_TIMEOUT s, default 300), runs PROGRAM unsharded, and
# passes only when the merged table.csv and table.md equal the unsharded ones byte for byte and
# the shards split the runs exactly. Then it pre-empts a task (SIGTERM to its batch script, as
# Slurm sends before a time limit) while its runs write checkpoints: the task must requeue itself
# and resume the interrupted run from its checkpoint to the table of a sweep never stopped. It
# always stops the daemons it started, prints their logs
# on failure, and fails (never skips) when Slurm cannot be started: not root, a package missing
# (scripts/install-deps installs slurm-wlm and munge), or a daemon that does not come up.
set -euo pipefail

say() { echo "slurm_test: $*"; }

started=0 # daemons were started: print their logs on failure
fail() {
  echo "slurm_test: FAIL: $*" >&2
  if [ "$started" = 1 ]; then print_logs >&2; fi
  exit 1
}

(($# == 3)) || {
  echo "usage: slurm_test.sh PROGRAM SWEEP.json WORKDIR" >&2
  exit 2
}
[ "$(id -u)" -eq 0 ] || fail "must run as root to start slurmctld, slurmd and munged (uid $(id -u))"
[ -x "$1" ] || fail "program $1 is not an executable file"
[ -f "$2" ] || fail "no sweep file $2"
program=$(realpath "$1")
sweep=$(realpath "$2")
mkdir -p "$3"
work=$(realpath "$3")
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
submit=$(realpath "$here/../slurm/submit.sh")
[ -x "$submit" ] || fail "no executable $submit"
shards=3
timeout=${KELP_SLURM_TEST_TIMEOUT:-300}
t0=$SECONDS

# --- preconditions: fail loudly, never skip ------------------------------------------------------
for c in munged munge unmunge slurmctld slurmd sbatch squeue sinfo scontrol scancel; do
  command -v "$c" >/dev/null 2>&1 ||
    fail "$c not found: install the Debian packages slurm-wlm and munge (scripts/install-deps)"
done

# --- layout -------------------------------------------------------------------------------------
rm -rf "$work/slurm" "$work/sharded" "$work/unsharded" "$work/unsharded.log" "$work/requeue" \
  "$work/requeue_ref" "$work"/kelp-sweep-*.out
rt=$work/slurm
tmp_rt=
# Unix socket paths are limited to 107 bytes (munged's socket, slurmd's step sockets in its spool).
if ((${#rt} > 60)); then
  tmp_rt=$(mktemp -d /tmp/kelp-slurm.XXXXXX)
  rt=$tmp_rt
  say "WORKDIR's path is long for Unix sockets: Slurm's state goes to $rt (removed at exit)"
fi
mkdir -p "$rt/munge/key" "$rt/state" "$rt/spool" "$rt/log"
chmod 0755 "$rt" "$rt/munge" "$rt/state" "$rt/spool" # munged: socket dir searchable by all
chmod 0700 "$rt/munge/key"                            # munged: key dir private to its owner
conf=$rt/slurm.conf
node=$(hostname -s)
[ -n "$node" ] || fail "hostname -s is empty"

munged_pid="" ctld_pid="" slurmd_pid=""

print_logs() {
  local f
  for f in "$rt"/log/* "$work"/sharded/logs/* "$work"/unsharded.log; do
    [ -s "$f" ] || continue
    # A daemon's stdout repeats its log file: shown only when the log file is empty.
    if [[ $f == *.out && -s ${f%.out}.log ]]; then continue; fi
    echo "----- $f (last 60 lines)"
    tail -n 60 "$f"
  done
  if [ -n "$ctld_pid" ] && kill -0 "$ctld_pid" 2>/dev/null; then
    echo "----- squeue"
    squeue 2>&1 || true
    echo "----- sinfo"
    sinfo -N -l 2>&1 || true
  fi
}

stop_pid() { # stop_pid PID: TERM, wait up to 10 s, then KILL
  local pid=$1 i
  [ -n "$pid" ] || return 0
  kill -TERM "$pid" 2>/dev/null || return 0
  for ((i = 0; i < 50; i++)); do
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.2
  done
  kill -KILL "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
}

cleanup() {
  local rc=$? i
  set +e
  if [ -n "$ctld_pid" ] && kill -0 "$ctld_pid" 2>/dev/null; then
    # Cancel what is left so that no job step outlives slurmd.
    scancel --quiet --user=root 2>/dev/null
    for ((i = 0; i < 50; i++)); do
      [ -z "$(squeue -h -o %i 2>/dev/null)" ] && break
      sleep 0.2
    done
  fi
  stop_pid "$slurmd_pid"
  stop_pid "$ctld_pid"
  stop_pid "$munged_pid"
  [ -z "$tmp_rt" ] || rm -rf "$tmp_rt"
  exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# Slurm settings inherited from the caller (a partition, a job's id) would not fit this cluster.
while read -r v; do unset "$v"; done < <(compgen -e | grep -E '^(SLURM_|SBATCH_|SQUEUE_|SINFO_|SCONTROL_)' || true)
export SLURM_CONF=$conf

port_free() { ! (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }
pick_port() { # a free port at or above $1
  local p=$1
  while ! port_free "$p" || ! port_free $((p + 1)); do p=$((p + 2)); done
  echo "$p"
}
ctld_port=$(pick_port $((20000 + $$ % 20000 * 2)))
slurmd_port=$((ctld_port + 1))

# --- munged: its own key, socket, pid, seed and log -------------------------------------------------
key=$rt/munge/key/munge.key
if command -v mungekey >/dev/null 2>&1; then
  mungekey --create --keyfile="$key" || fail "mungekey could not create $key"
else
  dd if=/dev/urandom of="$key" bs=1024 count=1 status=none || fail "could not write $key"
fi
chmod 0400 "$key"
socket=$rt/munge/munge.socket
started=1
munged --foreground --force --key-file="$key" --socket="$socket" --pid-file="$rt/munge/munged.pid" \
  --seed-file="$rt/munge/key/munged.seed" --log-file="$rt/log/munged.log" \
  >"$rt/log/munged.out" 2>&1 &
munged_pid=$!
for ((i = 0; ; i++)); do
  kill -0 "$munged_pid" 2>/dev/null || fail "munged exited at start"
  if munge -S "$socket" -n 2>/dev/null | unmunge -S "$socket" >/dev/null 2>&1; then break; fi
  ((i < 50)) || fail "munged does not answer on $socket after 10 s"
  sleep 0.2
done
say "munged up (pid $munged_pid, socket $socket)"

# --- slurmctld + slurmd ---------------------------------------------------------------------------
cat >"$conf" <<EOF
# Single-node test cluster of apps/sweep/tests/slurm_test.sh
ClusterName=kelptest
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
StateSaveLocation=$rt/state
SlurmdSpoolDir=$rt/spool
SlurmctldPidFile=$rt/slurmctld.pid
SlurmdPidFile=$rt/slurmd.pid
SlurmctldLogFile=$rt/log/slurmctld.log
SlurmdLogFile=$rt/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
# No cgroups, systemd or accounting in a container.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SwitchType=switch/none
MpiDefault=none
MailProg=/bin/true
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
DependencyParameters=kill_invalid_depend
ReturnToService=2
MinJobAge=600
SlurmdParameters=config_overrides
NodeName=$node NodeAddr=127.0.0.1 NodeHostname=$node CPUs=$(nproc) RealMemory=512 State=UNKNOWN
PartitionName=kelptest Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF

slurmctld -D -c -i -f "$conf" >"$rt/log/slurmctld.out" 2>&1 &
ctld_pid=$!
slurmd -D -f "$conf" -N "$node" >"$rt/log/slurmd.out" 2>&1 &
slurmd_pid=$!
for ((i = 0; ; i++)); do
  kill -0 "$ctld_pid" 2>/dev/null || fail "slurmctld exited at start"
  kill -0 "$slurmd_pid" 2>/dev/null || fail "slurmd exited at start"
  state=$(sinfo -h -N -n "$node" -o %T 2>/dev/null || true)
  [ "$state" = idle ] && break
  ((i < 300)) || fail "node $node is not idle after 60 s (state '${state:-none}')"
  sleep 0.2
done
say "Slurm up: node $node idle, slurmctld pid $ctld_pid (port $ctld_port), slurmd pid $slurmd_pid ($((SECONDS - t0)) s)"

# --- the sweep on Slurm -----------------------------------------------------------------------------
cd "$work"
out=$("$submit" -n "$shards" --program "$program" --no-plot --time 10 "$sweep" "$work/sharded") ||
  fail "submit.sh failed: $out"
echo "$out"
array_job=$(sed -n 's/^array_job=//p' <<<"$out")
merge_job=$(sed -n 's/^merge_job=//p' <<<"$out")
[[ $array_job =~ ^[0-9]+$ && $merge_job =~ ^[0-9]+$ ]] || fail "no job ids in submit.sh's output"

deadline=$((SECONDS + timeout))
while [ -n "$(squeue -h -o %i 2>/dev/null)" ] || ! squeue -h >/dev/null 2>&1; do
  kill -0 "$ctld_pid" 2>/dev/null || fail "slurmctld died while the jobs ran"
  kill -0 "$slurmd_pid" 2>/dev/null || fail "slurmd died while the jobs ran"
  ((SECONDS < deadline)) || fail "jobs $array_job and $merge_job not finished after $timeout s"
  sleep 1
done
job_states() { # "COUNT STATE ..." of a job's (or an array's) tasks
  { scontrol -o show job "$1" 2>&1 || true; } | grep -o 'JobState=[A-Z_]*' | sed 's/JobState=//' | sort | uniq -c | xargs
}
array_states=$(job_states "$array_job")
merge_state=$(job_states "$merge_job")
[ "$array_states" = "$shards COMPLETED" ] || fail "array job $array_job: $array_states (expected $shards COMPLETED)"
[ "$merge_state" = "1 COMPLETED" ] || fail "merge job $merge_job: $merge_state"
say "array job $array_job ($shards shards) and merge job $merge_job completed ($((SECONDS - t0)) s)"

# --- the same sweep unsharded, and the comparison ---------------------------------------------------
"$program" --sweep "$sweep" --out "$work/unsharded" --no-plot >"$work/unsharded.log" 2>&1 ||
  fail "the unsharded run failed (exit $?)"

runs_of() { { find "$@" -maxdepth 1 -name '*.json' -printf '%f\n' 2>/dev/null || true; } | sort; }
all=$(runs_of "$work/unsharded/runs")
[ -n "$all" ] || fail "the unsharded run wrote no runs/*.json"
sharded=$(runs_of "$work"/sharded/shard-*/runs)
[ "$sharded" = "$all" ] ||
  fail "the shards' runs are not a partition of the unsharded runs: $(diff <(echo "$sharded") <(echo "$all") | head -20)"
for i in $(seq 0 $((shards - 1))); do
  n=$(runs_of "$work/sharded/shard-$i/runs" | grep -c . || true)
  say "shard $i: $n run(s)"
done

ok=1
for t in table.csv table.md; do
  [ -f "$work/sharded/merged/$t" ] || fail "merge wrote no $t"
  [ -f "$work/unsharded/$t" ] || fail "the unsharded run wrote no $t"
  if ! cmp "$work/sharded/merged/$t" "$work/unsharded/$t"; then
    diff -u "$work/unsharded/$t" "$work/sharded/merged/$t" | head -40 >&2
    ok=0
  fi
done
[ "$ok" = 1 ] || fail "the merged table differs from the unsharded one"
say "merged table of $shards shards equals the unsharded one ($(grep -c . <<<"$all") runs, $((SECONDS - t0)) s)"

# --- pre-empted: SIGTERM to the task, which stops kelp-sweep, requeues itself and resumes -------
# (sweep.sbatch: --requeue, the runs checkpointed every KELP_SWEEP_CHECKPOINT_EVERY s.) Two runs
# of 120 s; once one has written a checkpoint, the batch script gets SIGTERM as Slurm sends it
# before a time limit (scancel --signal=TERM --batch). The task must requeue itself, run again
# (restart 1), resume the interrupted run from its checkpoint, and leave the table of the same
# sweep run without a stop.
echo '{"base": {"duration": 120}, "axes": [{"path": "/tether/length", "values": [10]}], "seeds": 2}' \
  >"$work/requeue.json"
job=$(KELP_SWEEP_CHECKPOINT_EVERY=1 sbatch --parsable --array=0 --time 10 \
  "$here/../slurm/sweep.sbatch" --program "$program" --shards 1 "$work/requeue.json" \
  "$work/requeue") || fail "sbatch of the requeue sweep failed"
job=${job%%;*}
runs=$work/requeue/shard-0/runs
deadline=$((SECONDS + timeout))
until compgen -G "$runs/*.checkpoint.bin" >/dev/null; do
  ((SECONDS < deadline)) || fail "the requeue sweep wrote no checkpoint in $timeout s"
  sleep 0.05
done
scancel --signal=TERM --batch "${job}_0" || fail "scancel --signal=TERM --batch ${job}_0 failed"
say "sent SIGTERM to task ${job}_0 with a checkpoint under way"
task_field() { { scontrol -o show job "${job}_0" 2>/dev/null || true; } | grep -o "$1=[A-Z_0-9]*" | sed "s/$1=//"; }
released=0
while :; do
  state=$(task_field JobState)
  [ "$state" = COMPLETED ] && break
  # Slurm makes a requeued job wait (its begin time a few minutes on): start it now.
  if [ "$state" = PENDING ] && [ "$released" = 0 ] && [ "$(task_field Restarts)" = 1 ]; then
    scontrol update JobId="${job}_0" StartTime=now || fail "cannot start the requeued task now"
    released=1
  fi
  case "$state" in FAILED | CANCELLED | TIMEOUT | NODE_FAIL) fail "task ${job}_0: $state" ;; esac
  ((SECONDS < deadline)) || fail "task ${job}_0 not done after $timeout s (state $state)"
  sleep 0.5
done
restarts=$(task_field Restarts)
log=$work/kelp-sweep-${job}_0.out
[ "$restarts" = 1 ] || fail "task ${job}_0 restarted ${restarts:-?} times, expected once (requeued)"
grep -q "requeueing job" "$log" || fail "$log: the task did not requeue itself: $(cat "$log")"
grep -q "resumed from its checkpoint at" "$log" ||
  fail "$log: the interrupted run did not resume from its checkpoint: $(cat "$log")"
"$program" --sweep "$work/requeue.json" --out "$work/requeue_ref" --no-plot \
  >"$work/requeue_ref.log" 2>&1 || fail "the uninterrupted requeue sweep failed"
"$program" merge "$work/requeue/shard-0" --out "$work/requeue/merged" --no-plot \
  >"$work/requeue_merge.log" 2>&1 || fail "merging the requeued shard failed"
cmp "$work/requeue/merged/table.csv" "$work/requeue_ref/table.csv" ||
  fail "the requeued sweep's table differs from the uninterrupted one's"
say "requeue: task ${job}_0 stopped, requeued and resumed from its checkpoint; its table equals the uninterrupted one's ($((SECONDS - t0)) s)"
say "PASS"
