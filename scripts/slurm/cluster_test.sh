#!/usr/bin/env bash
# The Slurm test (`scripts/dev.sh cluster-test`, run by CI): brings up a single-node Slurm from
# Debian's packages (slurm-wlm, munge) on this machine with its own munge key, slurm.conf, ports
# and folders (no systemd, nothing under /etc), runs a small suite as a 3-task job array plus the
# merge job through scripts/slurm/submit.sh, cancels one task mid-run, checks that the merge
# refuses the unfinished shard, resubmits the task (it resumes from its finished runs), and checks
# that the merged report has the rows and statuses that one `wrap bench` process gives for the
# same suite. Stops its daemons and removes everything it made, also when it fails.
#   scripts/slurm/cluster_test.sh [WRAP]    (WRAP default: build/app/wrap; must run as root)
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
wrap=$(cd "$(dirname "${1:-$repo/build/app/wrap}")" && pwd)/$(basename "${1:-$repo/build/app/wrap}")
start_time=$SECONDS
# The suite: task plans of the cross by two planners, 8 seeds (16 runs; shards of 6, 5 and 5:
# shard 2 is cancelled after its first run, and its other four leave time for that).
# Each takes a second or two; the limit is generous so that a loaded machine does not turn a
# plan into a timeout in one of the two runs that are compared.
suite=(--suite tiny --runs 8 --time-limit 60)
runs=16
shard2_runs=5

fail() { echo "cluster-test: FAILED: $*" >&2; exit 1; }
# Runs a command in the background and waits for it, so that a signal to this script is handled
# at once (bash defers traps until a foreground command ends).
bg() {
  "$@" &
  wait $!
}
say() { echo "cluster-test: [$((SECONDS - start_time)) s] $*"; }

[[ -x "$wrap" ]] || fail "no wrap at $wrap (build first)"
[[ $(id -u) -eq 0 ]] || fail "must run as root: slurmd starts jobs as their users"
for tool in munged slurmctld slurmd sbatch squeue scontrol scancel; do
  command -v "$tool" >/dev/null || fail "$tool not found (scripts/install_deps.sh --cluster)"
done

# Everything lives here; the socket's folders must be searchable by all (munged checks).
tmp=$(mktemp -d -t wrap-cluster-test.XXXXXX)
chmod 755 "$tmp"
mkdir -p "$tmp/munge" "$tmp/key" "$tmp/state" "$tmp/spool" "$tmp/log"
chmod 755 "$tmp/munge"
chmod 700 "$tmp/key"
export SLURM_CONF="$tmp/slurm.conf"

stop_all() {
  local rc=$?
  set +e
  if [[ -f "$tmp/slurmctld.pid" ]]; then
    # Jobs first (their steps would outlive slurmd), then the daemons.
    scancel --quiet --user=root >/dev/null 2>&1
    for _ in $(seq 100); do
      [[ -z "$(squeue -h 2>/dev/null)" ]] && break
      sleep 0.1
    done
    scontrol shutdown >/dev/null 2>&1
  fi
  # The daemons this test started, by their pid files; SIGKILL for any that did not stop.
  for pidfile in "$tmp/slurmd.pid" "$tmp/slurmctld.pid" "$tmp/munge/munged.pid"; do
    [[ -f "$pidfile" ]] || continue
    pid=$(cat "$pidfile")
    [[ -n "$pid" ]] || continue
    [[ "$pidfile" == */munged.pid ]] && kill "$pid" 2>/dev/null
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null
  done
  # Anything of this test's jobs still running (its command line names this test's folder).
  for pid in $(command -v pgrep >/dev/null && pgrep -f "$tmp/"); do
    [[ "$pid" != "$$" ]] && kill -9 "$pid" 2>/dev/null
  done
  if [[ $rc -ne 0 ]]; then
    for f in "$tmp"/log/*.log "$tmp"/study/slurm/*.out; do
      [[ -f "$f" ]] && { echo "--- $f (last lines)"; tail -n 15 "$f"; }
    done >&2
  fi
  rm -rf "$tmp"
  exit $rc
}
trap stop_all EXIT
trap 'exit 130' INT TERM

# Two TCP ports that nothing listens on (from /proc/net/tcp*, no extra tools).
listening=$(cat /proc/net/tcp /proc/net/tcp6 2>/dev/null | while read -r _ local _ state _; do
  if [[ "$state" == 0A ]]; then echo $((16#${local##*:})); fi
done | sort -u)
ports=()
for _ in $(seq 200); do
  p=$((20000 + RANDOM % 30000))
  grep -qx "$p" <<<"$listening" || [[ " ${ports[*]} " == *" $p "* ]] || ports+=("$p")
  [[ ${#ports[@]} -eq 2 ]] && break
done

# munge: a key of our own, a socket of our own.
dd if=/dev/urandom of="$tmp/key/munge.key" bs=1024 count=1 status=none
chmod 400 "$tmp/key/munge.key"
munged --key-file="$tmp/key/munge.key" --socket="$tmp/munge/munge.sock" \
  --pid-file="$tmp/munge/munged.pid" --log-file="$tmp/log/munged.log" \
  --seed-file="$tmp/munge/munged.seed" || fail "munged did not start"

cpus=$(nproc)
mem=$(awk '/MemTotal/ { print int($2 / 1024 / 2) }' /proc/meminfo)
cat >"$SLURM_CONF" <<EOF
ClusterName=wraptest
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=${ports[0]}
SlurmdPort=${ports[1]}
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$tmp/munge/munge.sock
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/log/slurmctld.log
SlurmdLogFile=$tmp/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
MinJobAge=600
NodeName=wrapnode NodeAddr=127.0.0.1 NodeHostname=localhost CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=wrap Nodes=wrapnode Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -f "$SLURM_CONF" || fail "slurmctld did not start"
slurmd -f "$SLURM_CONF" -N wrapnode || fail "slurmd did not start"
for _ in $(seq 150); do
  [[ "$(sinfo -h -o %t 2>/dev/null)" == idle ]] && break
  sleep 0.2
done
[[ "$(sinfo -h -o %t 2>/dev/null)" == idle ]] || fail "the node did not come up (sinfo: $(sinfo 2>&1))"
say "Slurm up: 1 node, $cpus CPUs, ports ${ports[*]}"

# The reference: one process, the whole suite.
bg "$wrap" bench "${suite[@]}" --jobs "$cpus" --projects "$repo/projects" -o "$tmp/single" \
  >"$tmp/log/single.log" 2>&1 || fail "the one-process suite failed: $(tail -n 5 "$tmp/log/single.log")"
say "one process: $runs runs"

job_state() {  # JOBID -> its state (PENDING, RUNNING, COMPLETED, CANCELLED, FAILED, ...)
  scontrol show job "$1" -o 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' | head -n 1
}
wait_gone() {  # until no job of these ids is queued or running
  for _ in $(seq 1500); do
    [[ -z "$(squeue -h -j "$1" 2>/dev/null)" ]] && return 0
    sleep 0.2
  done
  fail "jobs $1 still in the queue after 300 s: $(squeue 2>&1)"
}
count_runs() {  # run results in a shard folder (a glob: no process per call)
  local files=("$1"/runs/*.json)
  echo "${#files[@]}"
}
shopt -s nullglob

# The array (3 tasks, one core each) and the merge job.
out=$("$repo/scripts/slurm/submit.sh" --shards 3 --out "$tmp/study" --cpus-per-task 1 \
  --wrap "$wrap" --projects "$repo/projects" -- "${suite[@]}")
echo "$out"
array=$(sed -n 's/^array job \([0-9]*\).*/\1/p' <<<"$out")
merge=$(sed -n 's/.*merge job \([0-9]*\)$/\1/p' <<<"$out")
[[ -n "$array" && -n "$merge" ]] || fail "submit.sh printed no job ids"

# Task 2 cancelled mid-run: as soon as its first run is recorded, before its last.
shard2="$tmp/study/shard-2"
for ((k = 0; ; ++k)); do
  [[ $(count_runs "$shard2") -ge 1 ]] && break
  if ((k % 40 == 39)); then
    state=$(job_state "${array}_2")
    [[ "$state" == PENDING || "$state" == RUNNING ]] ||
      fail "task 2 ended ($state) before its first run: $(cat "$tmp"/study/slurm/shard-2-*.out 2>&1)"
    ((k < 3000)) || fail "task 2 recorded no run in 150 s"
  fi
  sleep 0.05
done
scancel "${array}_2"
done_before=$(count_runs "$shard2")
((done_before >= 1 && done_before < shard2_runs)) ||
  fail "could not cancel shard 2 mid-run: it had $done_before of $shard2_runs runs"
wait_gone "$array,$merge"
done_at_cancel=$(count_runs "$shard2")
((done_at_cancel < shard2_runs)) || fail "shard 2 finished although it was cancelled"
grep -q '"end": "[0-9]' "$shard2/meta.json" ||
  fail "shard 2 did not record its session's end when cancelled (meta.json: $(cat "$shard2/meta.json"))"
say "task 2 cancelled with $done_at_cancel of its $shard2_runs runs; tasks 1 and 3: $(count_runs "$tmp/study/shard-1")" \
  "and $(count_runs "$tmp/study/shard-3") runs"

# The first merge job must have refused the unfinished shard, and said which.
[[ "$(job_state "$merge")" == FAILED ]] || fail "merge job $merge: $(job_state "$merge"), expected FAILED"
grep -q "shard-2 (shard 2/3 of suite 'tiny') has $done_at_cancel of its $shard2_runs runs" \
  "$tmp/study/slurm/merge-$merge.out" ||
  fail "merge did not name the unfinished shard: $(cat "$tmp/study/slurm/merge-$merge.out")"
[[ ! -f "$tmp/study/report/report.md" ]] || fail "merge wrote a report from an unfinished shard"
say "merge refused the unfinished shard"

# Task 2 again: it resumes from its finished runs; the new merge job merges.
bg "$repo/scripts/slurm/submit.sh" --resubmit "$tmp/study" --tasks 2 --cpus-per-task 1 --wait ||
  fail "the resubmitted shard or its merge failed"
logs2=("$tmp"/study/slurm/shard-2-*.out)
[[ ${#logs2[@]} -eq 2 ]] || fail "expected the logs of shard 2's two tasks, found ${#logs2[@]}"
reused=$(cat "${logs2[@]}" | grep -c '(reused)' || true)
((reused == done_at_cancel)) || fail "shard 2 reused $reused runs, expected $done_at_cancel"
say "task 2 resumed ($reused runs reused) and the study merged"

# Two shards never wrote the same run; together they are the suite.
names=()
for f in "$tmp"/study/shard-{1,2,3}/runs/*.json; do names+=("$(basename "$f")"); done
all=${#names[@]}
uniq=$(printf '%s\n' "${names[@]}" | sort -u | wc -l)
((all == runs && uniq == runs)) || fail "the shards hold $all run files ($uniq different), expected $runs"

# The merged report equals the one process's: the same rows with the same statuses (and costs:
# the same seed gives the same plan). Columns 1-8: project, planner, options, seed, status,
# solved, cost, first cost.
diff <(cut -d, -f1-8 "$tmp/single/results.csv") <(cut -d, -f1-8 "$tmp/study/report/results.csv") ||
  fail "the merged results differ from the one process's (above: < one process, > merged)"
[[ $(($(wc -l <"$tmp/study/report/results.csv") - 1)) -eq $runs ]] || fail "merged results: not $runs rows"
grep -q "merged from 3 folder(s)" "$tmp/study/report/report.md" || fail "the report does not say it merged 3 shards"
diff <(sed -n '/^| group /,/^$/p' "$tmp/single/report.md" | cut -d'|' -f1-9) \
  <(sed -n '/^| group /,/^$/p' "$tmp/study/report/report.md" | cut -d'|' -f1-9) ||
  fail "the reports' run counts differ"
say "merged report = one process's ($runs rows, same statuses and costs)"
say "passed"
