#!/usr/bin/env bash
# The paper's wrench ablation (§V-B): PROJECTS x wrench models x seeds planned and simulated.
# Each plan is tried with motion first (--time-limit MOTION_S); when no motion is found in that
# time the task plan alone is written (--task-only) and `wrap sim` replays its keyframes.
# Usage: tests/sim/wrench_ablation.sh WRAP_BINARY OUT_DIR [phase: plan|sim|table|all]
# Environment: PROJECTS (default "cross cube chair"), MODELS ("none gravity full"),
# SEEDS ("1 2 ... 10"), MOTION_S (30), JOBS (1 parallel runs).
# Results: OUT_DIR/P_W_S.plan.json, .sim.json, .plan.log, .sim.log; `table` prints the
# BENCHMARKS.md table (needs python3): per project and model the success rate, mean tasks
# completed / total, failure reasons counted, and the mean over runs of each run's peak
# utilisation (the paper's "mean peak utilisation ... for the successful part of the trajectory").
set -u
wrap=$(readlink -f "$1")
out=$(readlink -f "$2")
phase=${3:-all}
repo=$(cd "$(dirname "$0")/../.." && pwd)
projects=${PROJECTS:-"cross cube chair"}
models=${MODELS:-"none gravity full"}
seeds=${SEEDS:-"1 2 3 4 5 6 7 8 9 10"}
motion_s=${MOTION_S:-30}
jobs=${JOBS:-1}
mkdir -p "$out"

plan_one() {  # project model seed
  local base="$out/$1_$2_$3"
  [ -s "$base.plan.json" ] && return 0
  if ! "$wrap" plan "$repo/projects/$1.json" --seed "$3" --wrench "$2" \
      --time-limit "$motion_s" -o "$base.plan.json" >"$base.plan.log" 2>&1; then
    rm -f "$base.plan.json"
    echo "--- no motion within ${motion_s} s: task plan only" >>"$base.plan.log"
    "$wrap" plan "$repo/projects/$1.json" --seed "$3" --wrench "$2" --task-only \
      -o "$base.plan.json" >>"$base.plan.log" 2>&1 || rm -f "$base.plan.json"
  fi
}

sim_one() {  # project model seed
  local base="$out/$1_$2_$3"
  [ -s "$base.plan.json" ] || return 0
  "$wrap" sim "$repo/projects/$1.json" --plan "$base.plan.json" -o "$base.sim.json" \
    >"$base.sim.log" 2>&1
  echo $? >"$base.sim.rc"
}
export -f plan_one sim_one
export wrap out repo motion_s

list() { for p in $projects; do for w in $models; do for s in $seeds; do echo "$p $w $s"; done; done; done; }
if [ "$phase" = plan ] || [ "$phase" = all ]; then
  list | xargs -P "$jobs" -L 1 bash -c 'plan_one "$@"' _
fi
if [ "$phase" = sim ] || [ "$phase" = all ]; then
  list | xargs -P "$jobs" -L 1 bash -c 'sim_one "$@"' _
fi
if [ "$phase" = table ] || [ "$phase" = all ]; then
  PROJECTS="$projects" MODELS="$models" SEEDS="$seeds" python3 - "$out" <<'PY'
import json, os, sys
out = sys.argv[1]
def pct(v):
    return "-" if v is None else f"{v:.0f}"
print("| project | model | motion | success [%] | tasks | failures | transport 2F | transport vac. | insertion 2F | insertion vac. | connections | table friction |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
for p in os.environ["PROJECTS"].split():
    for w in os.environ["MODELS"].split():
        runs, ok, done, total, fails, motion = 0, 0, 0, 0, {}, {"trajectories": 0, "keyframes": 0}
        peaks = {k: [] for k in ("t2", "tv", "i2", "iv", "c", "tf")}
        for s in os.environ["SEEDS"].split():
            f = f"{out}/{p}_{w}_{s}.sim.json"
            if not os.path.exists(f):
                continue
            r = json.load(open(f))
            runs += 1
            ok += r["success"]
            done += r["tasks_completed"]
            total += r["tasks_total"]
            motion[r.get("motion", "trajectories")] += 1
            if r["failure"]:
                key = r["failure"]["reason"]
                fails[key] = fails.get(key, 0) + 1
            u = r["peak_utilisation_percent"]
            for k, v in (("t2", u["transport"]["two_finger"]), ("tv", u["transport"]["vacuum"]),
                         ("i2", u["insertion"]["two_finger"]), ("iv", u["insertion"]["vacuum"]),
                         ("c", u["connection"]), ("tf", u["table_friction"])):
                if v is not None:
                    peaks[k].append(v)
        if runs == 0:
            print(f"| {p} | {w} | | no runs | | | | | | | | |")
            continue
        mean = {k: (sum(v) / len(v) if v else None) for k, v in peaks.items()}
        fail_text = ", ".join(f"{k} ({n})" for k, n in sorted(fails.items())) or "-"
        mot = f"{motion['trajectories']} traj., {motion['keyframes']} kf."
        print(f"| {p} | {w} | {mot} | {100 * ok / runs:.0f} | {done / runs:.1f}/{total / runs:.1f} | "
              f"{fail_text} | {pct(mean['t2'])} | {pct(mean['tv'])} | {pct(mean['i2'])} | "
              f"{pct(mean['iv'])} | {pct(mean['c'])} | {pct(mean['tf'])} |")
PY
fi
