#!/usr/bin/env bash
# Plans example projects with motion over several seeds, two at a time, and prints one line per
# run (the numbers of BENCHMARKS.md's motion table):
#   project seed solved t_init t_kf t_mp makespan sequential task_plans suspensions failure
# Usage: scripts/motion_sweep.sh OUT_DIR "SEEDS" [PROJECT ...]   (default: every example project)
# Environment: WRAP (default build/app/wrap), TIME_LIMIT (default 60), JOBS (default 2).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:?usage: scripts/motion_sweep.sh OUT_DIR "SEEDS" [PROJECT ...]}
seeds=${2:-"0 1 2"}
shift 2 || true
projects=("$@")
if [[ ${#projects[@]} -eq 0 ]]; then
  projects=(stool half_stool chair cross cross_openarm cube cube_2x2x3 fabrica_beam fabrica_car
    fabrica_plumbers_block fabrica_gamepad fabrica_cooling_manifold)
fi
wrap=${WRAP:-build/app/wrap}
limit=${TIME_LIMIT:-60}
jobs=${JOBS:-2}
mkdir -p "$out"

run_one() {
  local p=$1 s=$2
  "$wrap" plan "projects/$p.json" --seed "$s" --time-limit "$limit" --validate \
    -o "$out/$p.s$s.json" >"$out/$p.s$s.out" 2>"$out/$p.s$s.err" || true
}
export -f run_one
export wrap limit out
for p in "${projects[@]}"; do
  for s in $seeds; do echo "$p $s"; done
done | xargs -P "$jobs" -n 2 bash -c 'run_one "$0" "$1"'

python3 - "$out" "${projects[@]}" <<'EOF'
import json, os, sys
out, projects = sys.argv[1], sys.argv[2:]
print("project\tseed\tsolved\tt_init\tt_kf\tt_mp\tmakespan\tsequential\ttask_plans\tsuspensions\tfailure")
for p in projects:
    for f in sorted(os.listdir(out)):
        if not (f.startswith(p + ".s") and f.endswith(".json")):
            continue
        seed = f[len(p) + 2:-5]
        try:
            st = json.load(open(os.path.join(out, f)))["stats"]
        except Exception as e:
            print(f"{p}\t{seed}\terror\t\t\t\t\t\t\t\t{e}")
            continue
        g = lambda k: st.get(k, "")
        fmt = lambda v: f"{v:.2f}" if isinstance(v, float) else str(v)
        print("\t".join([p, seed, "yes" if st.get("solved") and st.get("motion") else "no"] +
                        [fmt(g(k)) for k in ("t_init_s", "t_kf_s", "t_mp_s", "makespan_s",
                                             "makespan_sequential_s", "task_plans",
                                             "motion_suspensions")] +
                        [str(g("failure"))[:160]]))
EOF
