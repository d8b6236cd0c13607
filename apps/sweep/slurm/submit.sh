#!/usr/bin/env bash
# Submits a kelp-sweep parameter sweep to Slurm: a job array of N shards (sweep.sbatch), and the
# merge of their results (merge.sbatch) as a job that starts only after every shard succeeded
# (--dependency=afterok:<array job>; it is cancelled if a shard fails).
#
#   submit.sh [options] SWEEP.json OUTDIR [-- SBATCH_OPTION...]
#
# Options:
#   -n, --shards N       number of shards, i.e. array tasks 0..N-1 (default 4)
#   --program PATH       the kelp-sweep program (default: kelp-sweep on the PATH)
#   -c, --cpus C         CPUs per shard, passed to kelp-sweep as --jobs (default 1)
#   -p, --partition P    Slurm partition (or set SBATCH_PARTITION)
#   -A, --account A      Slurm account (or set SBATCH_ACCOUNT)
#   -t, --time T         time limit of each shard (or set SBATCH_TIMELIMIT)
#   --merge-time T       time limit of the merge job (default: as --time)
#   --no-plot            the merge writes no errors.png
#   --dry-run            print the sbatch commands instead of running them
#   -h, --help           this text
# Everything after `--` is passed to both sbatch calls (e.g. -- --qos=short --mem=2G).
#
# Shard I writes OUTDIR/shard-I, the merge OUTDIR/merged (table.csv, table.md, errors.png), the
# jobs' output goes to OUTDIR/logs/. OUTDIR, SWEEP.json and the program must be on a file system
# the compute nodes share. Prints the job ids, and the lines `array_job=ID` and `merge_job=ID`.
# Submitting again with the same N and OUTDIR resumes: finished runs are skipped.
set -euo pipefail

die() {
  echo "submit.sh: $*" >&2
  exit 2
}
usage() { sed -n '2,/^set -euo/{/^set -euo/d;s/^# \{0,1\}//;p}' "$0"; }

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
shards=4
program=
cpus=1
time_limit=
merge_time=
no_plot=0
dry_run=0
common=()
positional=()
need() { (($1 >= 2)) || die "$2 needs a value"; }
while (($# > 0)); do
  case $1 in
    -n | --shards) need $# "$1"; shards=$2; shift 2 ;;
    --shards=*) shards=${1#*=}; shift ;;
    --program) need $# "$1"; program=$2; shift 2 ;;
    --program=*) program=${1#*=}; shift ;;
    -c | --cpus) need $# "$1"; cpus=$2; shift 2 ;;
    --cpus=*) cpus=${1#*=}; shift ;;
    -p | --partition) need $# "$1"; common+=("--partition=$2"); shift 2 ;;
    --partition=*) common+=("--partition=${1#*=}"); shift ;;
    -A | --account) need $# "$1"; common+=("--account=$2"); shift 2 ;;
    --account=*) common+=("--account=${1#*=}"); shift ;;
    -t | --time) need $# "$1"; time_limit=$2; shift 2 ;;
    --time=*) time_limit=${1#*=}; shift ;;
    --merge-time) need $# "$1"; merge_time=$2; shift 2 ;;
    --merge-time=*) merge_time=${1#*=}; shift ;;
    --no-plot) no_plot=1; shift ;;
    --dry-run) dry_run=1; shift ;;
    -h | --help) usage; exit 0 ;;
    --) shift; break ;;
    -*) die "unknown option $1 (sbatch options go after --)" ;;
    *) positional+=("$1"); shift ;;
  esac
done
passthrough=("$@")
((${#positional[@]} == 2)) || die "expected SWEEP.json OUTDIR (see --help)"
[[ $shards =~ ^[1-9][0-9]*$ ]] || die "bad shard count '$shards'"
[[ $cpus =~ ^[1-9][0-9]*$ ]] || die "bad CPU count '$cpus'"
[ -f "${positional[0]}" ] || die "no sweep file ${positional[0]}"
sweep=$(realpath "${positional[0]}")
out=$(realpath -m "${positional[1]}")
if [ -z "$program" ]; then
  program=$(command -v kelp-sweep) || die "kelp-sweep is not on the PATH: give --program PATH"
elif [[ $program != */* ]]; then
  program=$(command -v "$program") || die "no program $program on the PATH"
fi
[ -x "$program" ] || die "program $program is not executable"
program=$(realpath "$program")
[ -n "$merge_time" ] || merge_time=$time_limit

array_cmd=(sbatch --parsable --array="0-$((shards - 1))" --cpus-per-task="$cpus"
  --output="$out/logs/sweep-%A_%a.out" "${common[@]}")
[ -z "$time_limit" ] || array_cmd+=("--time=$time_limit")
array_cmd+=("${passthrough[@]}" "$here/sweep.sbatch" --program "$program" --shards "$shards" "$sweep" "$out")

merge_cmd=(sbatch --parsable --kill-on-invalid-dep=yes --output="$out/logs/merge-%j.out" "${common[@]}")
[ -z "$merge_time" ] || merge_cmd+=("--time=$merge_time")
merge_args=(--program "$program" --shards "$shards")
[ "$no_plot" = 0 ] || merge_args+=(--no-plot)

if [ "$dry_run" = 1 ]; then
  printf '%q ' "${array_cmd[@]}"
  echo
  printf '%q ' "${merge_cmd[@]}" --dependency=afterok:ARRAY_JOB_ID "${passthrough[@]}" "$here/merge.sbatch" "${merge_args[@]}" "$out"
  echo
  exit 0
fi

command -v sbatch >/dev/null 2>&1 || die "sbatch is not on the PATH (is this a Slurm login node?)"
mkdir -p "$out/logs" # Slurm does not create the directory of --output
array_id=$("${array_cmd[@]}") || die "submitting the array failed"
array_id=${array_id%%;*} # --parsable prints ID or ID;CLUSTER
[[ $array_id =~ ^[0-9]+$ ]] || die "unexpected sbatch output '$array_id'"
echo "submit.sh: array job $array_id: $shards shard(s) of $sweep into $out/shard-*"

merge_id=$("${merge_cmd[@]}" --dependency="afterok:$array_id" "${passthrough[@]}" \
  "$here/merge.sbatch" "${merge_args[@]}" "$out") ||
  die "submitting the merge failed (array job $array_id is queued; merge later with: sbatch $here/merge.sbatch ${merge_args[*]} $out)"
merge_id=${merge_id%%;*}
echo "submit.sh: merge job $merge_id: after array job $array_id succeeds, into $out/merged"
echo "array_job=$array_id"
echo "merge_job=$merge_id"
