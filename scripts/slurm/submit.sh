#!/usr/bin/env bash
# Runs a `wrap bench` study on a Slurm cluster: a job array with one shard per task
# (bench_shard.sbatch: `wrap bench --shard I/N`, each into STUDY/shard-I) and a merge job that
# starts when the array has ended (bench_merge.sbatch: `wrap bench merge` into STUDY/report).
#
#   scripts/slurm/submit.sh --shards N --out STUDY [options] -- BENCH-OPTIONS...
#       e.g. scripts/slurm/submit.sh --shards 40 --out /scratch/wrap-study -- --suite all --runs 10
#   scripts/slurm/submit.sh --resubmit STUDY [--tasks LIST] [options]
#       the tasks again (all, or e.g. --tasks 2,7-9): each resumes from its finished runs; then a
#       new merge job
#
# Options:
#   --wrap EXE            the wrap to run (default: build/app/wrap of this checkout); every task
#                         must see it, e.g. on a shared file system
#   --projects DIR        the example projects (default: projects/ of this checkout)
#   --cpus-per-task C     cores per task, and `wrap bench --jobs C` (default 1: one run at a time)
#   --time MINUTES        a task's wall-clock limit (default: the longest its shard can take, every
#                         run at its hard limit, from `wrap bench --dry-run`, plus 10 minutes)
#   --sbatch-args "ARGS"  more sbatch options for both jobs (partition, account, ...)
#   --wait                wait for the merge job; exit 0 when it merged, 1 otherwise
# The study's settings are kept in STUDY/slurm/study.env (a resubmission reuses them); Slurm's
# logs are STUDY/slurm/shard-I-JOBID.out and STUDY/slurm/merge-JOBID.out.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)

die() { echo "submit.sh: $*" >&2; exit 2; }

shards="" out="" resubmit="" tasks="" cpus=1 time_min="" sbatch_args="" wait=0
wrap_exe="$repo/build/app/wrap" projects="$repo/projects"
bench_args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --shards) shards=${2:?}; shift 2 ;;
    --out) out=${2:?}; shift 2 ;;
    --resubmit) resubmit=${2:?}; shift 2 ;;
    --tasks) tasks=${2:?}; shift 2 ;;
    --wrap) wrap_exe=${2:?}; shift 2 ;;
    --projects) projects=${2:?}; shift 2 ;;
    --cpus-per-task) cpus=${2:?}; shift 2 ;;
    --time) time_min=${2:?}; shift 2 ;;
    --sbatch-args) sbatch_args=${2:?}; shift 2 ;;
    --wait) wait=1; shift ;;
    --) shift; bench_args=("$@"); break ;;
    *) die "unknown option '$1' (see the comment at the top of this script)" ;;
  esac
done
command -v sbatch >/dev/null || die "sbatch not found: run this on a Slurm submit host"
[[ "$cpus" =~ ^[1-9][0-9]*$ ]] || die "--cpus-per-task: expected a positive number, got '$cpus'"

if [[ -n "$resubmit" ]]; then
  [[ -z "$shards" && -z "$out" && ${#bench_args[@]} -eq 0 ]] ||
    die "--resubmit takes the study's settings from its study.env: no --shards, --out or --"
  study_env="$(cd "$resubmit" 2>/dev/null && pwd)/slurm/study.env"
  [[ -f "$study_env" ]] || die "$resubmit: no slurm/study.env (not a study that submit.sh began)"
  # shellcheck source=/dev/null
  source "$study_env"
else
  [[ "$shards" =~ ^[1-9][0-9]*$ ]] || die "--shards: expected a positive number, got '$shards'"
  [[ -n "$out" ]] || die "--out STUDY: the study's folder is required"
  [[ ${#bench_args[@]} -gt 0 ]] || die "give the suite's options after --, e.g. -- --suite all --runs 10"
  [[ -x "$wrap_exe" ]] || die "--wrap: '$wrap_exe' is not an executable (build first: scripts/dev.sh build)"
  [[ -d "$projects" ]] || die "--projects: '$projects' is not a folder"
  mkdir -p "$out/slurm"
  out=$(cd "$out" && pwd)
  study_env="$out/slurm/study.env"
  [[ ! -e "$study_env" ]] ||
    die "$out already holds a study: resume it with --resubmit $out [--tasks LIST], or give another --out"
  WRAP_EXE=$(cd "$(dirname "$wrap_exe")" && pwd)/$(basename "$wrap_exe")
  WRAP_PROJECTS=$(cd "$projects" && pwd)
  WRAP_OUT=$out
  WRAP_SHARDS=$shards
  WRAP_BENCH_ARGS=("${bench_args[@]}")
  # The suite's options must be valid before anything is queued.
  "$WRAP_EXE" bench "${WRAP_BENCH_ARGS[@]}" --shard "1/$WRAP_SHARDS" --projects "$WRAP_PROJECTS" \
    --dry-run >/dev/null || die "wrap bench refused the options above"
  {
    echo "# The settings of a wrap bench study (scripts/slurm/submit.sh); sourced by its jobs."
    printf 'WRAP_EXE=%q\nWRAP_PROJECTS=%q\nWRAP_OUT=%q\nWRAP_SHARDS=%q\n' \
      "$WRAP_EXE" "$WRAP_PROJECTS" "$WRAP_OUT" "$WRAP_SHARDS"
    printf 'WRAP_BENCH_ARGS=('
    printf '%q ' "${WRAP_BENCH_ARGS[@]}"
    printf ')\n'
  } >"$study_env"
fi

# The tasks of this submission, one number a line ("2,7-9" -> 2 7 8 9).
task_list() {
  local spec=${tasks:-1-$WRAP_SHARDS} item
  for item in ${spec//,/ }; do
    if [[ "$item" =~ ^([0-9]+)-([0-9]+)$ ]]; then
      seq "${BASH_REMATCH[1]}" "${BASH_REMATCH[2]}"
    elif [[ "$item" =~ ^[0-9]+$ ]]; then
      echo "$item"
    else
      die "--tasks: '$item' is not a task number or range (e.g. 2,7-9)"
    fi
  done
}
task_ids=$(task_list)
for i in $task_ids; do
  ((i >= 1 && i <= WRAP_SHARDS)) || die "--tasks: $i is not one of the study's shards 1..$WRAP_SHARDS"
done

# A task's time limit: its shard's longest run time at C runs at once, plus 10 minutes.
if [[ -z "$time_min" ]]; then
  longest=0
  for i in $task_ids; do
    s=$("$WRAP_EXE" bench "${WRAP_BENCH_ARGS[@]}" --shard "$i/$WRAP_SHARDS" --jobs "$cpus" \
          --projects "$WRAP_PROJECTS" --dry-run | sed -n 's/.*(\([0-9]*\) s) at --jobs.*/\1/p')
    ((s > longest)) && longest=$s
  done
  time_min=$(((longest + 59) / 60 + 10))
fi

# shellcheck disable=SC2206
extra=($sbatch_args)
array=$(sbatch --parsable --array="${tasks:-1-$WRAP_SHARDS}" --cpus-per-task="$cpus" \
  --time="$time_min" --output="$WRAP_OUT/slurm/shard-%a-%A.out" \
  --export="ALL,WRAP_STUDY=$study_env" "${extra[@]}" "$here/bench_shard.sbatch")
array=${array%%;*}
merge=$(sbatch --parsable --dependency="afterany:$array" --time=30 \
  --output="$WRAP_OUT/slurm/merge-%j.out" --export="ALL,WRAP_STUDY=$study_env" "${extra[@]}" \
  "$here/bench_merge.sbatch")
merge=${merge%%;*}
echo "array job $array (shards ${tasks:-1-$WRAP_SHARDS} of $WRAP_SHARDS, $cpus core(s) and" \
  "$time_min min each), merge job $merge"
echo "report: $WRAP_OUT/report/report.md; logs: $WRAP_OUT/slurm/"
echo "a shard that stopped early: $0 --resubmit $WRAP_OUT --tasks I"
[[ $wait -eq 1 ]] || exit 0

# --wait: until the merge job has ended, then its verdict.
state=""
while true; do
  state=$(scontrol show job "$merge" -o 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p')
  case "$state" in
    PENDING | RUNNING | CONFIGURING | COMPLETING | SUSPENDED | REQUEUED | RESIZING) sleep 2 ;;
    *) break ;;
  esac
done
log="$WRAP_OUT/slurm/merge-$merge.out"
if [[ "$state" == COMPLETED ]]; then
  echo "merged: $WRAP_OUT/report/report.md"
  exit 0
fi
echo "merge job $merge ended ${state:-(its record is gone)}:" >&2
[[ -f "$log" ]] && tail -n 20 "$log" >&2
exit 1
