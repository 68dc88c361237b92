#!/usr/bin/env bash
# Runs after the two-tier loop where the posterior asks for them (issue 35, item 4; posterior_runs,
# docs/calibration.md). `granucal calibrate --tier check-posterior --stage granule` from scratch:
#  - each run after the loop was asked for by the posterior, at the pair its "-- posterior:" line
#    names, and that pair is one of the stage's candidates in simulations.csv;
#  - then (return_runs) the loop resumed: runs at the corrected optimum those runs moved, each at a
#    point none of the earlier runs stood at;
#  - the tier's candidates are the loop's runs plus those, at most max_evaluations + posterior_runs
#    + return_runs;
#  - report.md says how many were made and why they stopped, as the log does;
#  - the same command again runs nothing and writes the same table (the posterior is deterministic);
#  - with return_runs: 0 the stage re-derives from the same store with 0 simulations, without the
#    returned runs; with posterior_runs: 0 as well, the loop's runs alone, and no word of runs after it;
#  - with angle_aim_sd: 1 (from a copy of the store) the loop's first run is aimed no farther from the
#    angle's target than without it (a penalty that grows with the distance cannot push the optimum
#    away), and report.md says how the runs were aimed.
#   usage: posterior_runs.sh GRANUCAL SOURCE_DIR WORK_DIR
set -euo pipefail
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
cd "$src"
args=(calibrate --tier check-posterior --stage granule --jobs 2 --checkpoint-every 0)
run() { # run NAME CONFIG OUT
  "$bin" "${args[@]}" "$2" --out "$3" > "$work/$1.out" 2> "$work/$1.log" || { cat "$work/$1.log"; exit 1; }
}
run first configs/calibration.yaml "$work/out"
cp "$work/out/calibrated_parameters.csv" "$work/first.csv"
run again configs/calibration.yaml "$work/out"
# The copied configs read their data relative to themselves: point them at the shipped files.
sed -e 's/^    return_runs: 1$/    return_runs: 0/' -e "s|\.\./experiments/|$src/experiments/|" configs/calibration.yaml \
  > "$work/no_return.yaml"
# (every tier's: a return_runs without posterior_runs is refused)
sed -e 's/^    posterior_runs: 2$/    posterior_runs: 0/' -e 's/^    return_runs: [0-9]*$/    return_runs: 0/' \
  "$work/no_return.yaml" > "$work/none.yaml"
sed -e 's/^    return_runs: 1$/    return_runs: 1\n    angle_aim_sd: 1/' -e "s|\.\./experiments/|$src/experiments/|" \
  configs/calibration.yaml > "$work/aim.yaml"
for v in no_return none aim; do
  mkdir -p "$work/$v" && cp -r "$work/out/store" "$work/$v/"
  run $v "$work/$v.yaml" "$work/$v"
done
python3 - "$work" configs/calibration.yaml <<'PY'
import csv, re, sys
work, config = sys.argv[1], sys.argv[2]
sys.path.insert(0, "tests/calibration")
from checks import check, finish, tier_int  # noqa: E402

max_evaluations = tier_int(config, "check-posterior", "max_evaluations")
posterior_runs = tier_int(config, "check-posterior", "posterior_runs")
return_runs = tier_int(config, "check-posterior", "return_runs")

def deciding_pairs(out):
    with open(f"{out}/simulations.csv") as f:
        return {(float(r["mu_s"]), float(r["mu_r"])) for r in csv.DictReader(f) if r["stage"] == "granule"}

log = open(f"{work}/first.log").read()
asked = [(float(a), float(b)) for a, b in re.findall(r"^-- posterior: .*one more run where it weighs most, mu_s = (\S+), mu_r = (\S+)$", log, re.M)]
loop = re.search(r"after (\d+) run\(s\) at tier 'check-posterior'(?:, then (\d+) where the posterior asked)?"
                 r"(?:, then (\d+) back at the corrected optimum \(([^)]*)\))?", log)
check(loop is not None, "the log says how many runs the loop made")
loop_runs, made, returned = int(loop.group(1)), int(loop.group(2) or 0), int(loop.group(3) or 0)
check(made == len(asked), f"{made} run(s) after the loop, {len(asked)} asked for by the posterior")
check(made > 0, "the posterior asked for a run (the test can fail: a tier whose width were the data's would ask none)")
pairs = deciding_pairs(f"{work}/out")
check(loop.group(3) is not None, "after the posterior's runs the log says how the loop resumed")
check(0 < returned <= return_runs, f"{returned} run(s) back at the corrected optimum, at most {return_runs} (the test "
      "can fail: the posterior's runs moved the optimum here, so the resumed loop has somewhere to go)")
check(len(pairs) == loop_runs + made + returned <= max_evaluations + posterior_runs + return_runs,
      f"{len(pairs)} candidates at the tier = {loop_runs} of the loop + {made} asked + {returned} returned, at most "
      f"{max_evaluations} + {posterior_runs} + {return_runs}")
for a in asked:
    check(any(abs(p[0] - a[0]) <= 5e-4 * a[0] and abs(p[1] - a[1]) <= 5e-4 * a[1] for p in pairs),
          f"the pair asked for (mu_s {a[0]}, mu_r {a[1]}) is a candidate in simulations.csv")
report = open(f"{work}/out/report.md").read()
# Its map tier (check: a 2 x 2 grid at the cells' centres, no corners) does not span the search box.
span = re.search(r"The map's candidates span μs (\S+)–(\S+) and μr (\S+)–(\S+) of the search box \(μs (\S+)–(\S+),", report)
check(span is not None and float(span.group(1)) > float(span.group(5)) and "beyond that span the map extrapolates" in report,
      "report.md says the map's candidates stop short of the box, and that beyond them the map extrapolates")
said = re.search(r"After the loop, at most (\d+) more run\(s\).*?Made: (\d+); ([^;]+);", report, re.S)
check(said is not None and int(said.group(1)) == posterior_runs and int(said.group(2)) == made,
      "report.md says how many runs the posterior could ask for and how many were made")
stop = re.search(r"^-- posterior: .*(no more runs)$", log, re.M)
check(said is not None and (said.group(3) == "stopped at posterior_runs") == (stop is None and made == posterior_runs),
      f"report.md says why they stopped ({said.group(3) if said else '-'}), as the log does")

again = open(f"{work}/again.log").read()
check(" 0 simulations run now" in again, "the same command again runs nothing")
check(open(f"{work}/first.csv").read() == open(f"{work}/out/calibrated_parameters.csv").read(),
      "and writes the same table, byte for byte")

said = re.search(r"at most (\d+) more back at the corrected map's optimum.*?Made: (\d+);", report, re.S)
check(said is not None and int(said.group(1)) == return_runs and int(said.group(2)) == returned,
      "report.md says how many runs the resumed loop could make and how many it made")
no_return = open(f"{work}/no_return.log").read()
check(" 0 simulations run now" in no_return, "return_runs: 0 re-derives from the same store with 0 simulations")
check(len(deciding_pairs(f"{work}/no_return")) == loop_runs + made,
      f"return_runs: 0 keeps the loop's {loop_runs} runs and the {made} asked for")
none = open(f"{work}/none.log").read()
check(" 0 simulations run now" in none, "posterior_runs: 0 re-derives from the same store with 0 simulations")
check(len(deciding_pairs(f"{work}/none")) == loop_runs, f"posterior_runs: 0 keeps the loop's {loop_runs} runs alone")
check("After the loop" not in open(f"{work}/none/report.md").read(), "posterior_runs: 0: no word of runs after the loop")

def first_aim(log):
    m = re.search(r"^-- run 1 at tier 'check-posterior': angle \S+ measured.*?, (\S+)° predicted", log, re.M)
    return float(m.group(1)) if m else None
target = float(re.search(r"target (\S+) ±", log).group(1))
plain, aimed = first_aim(log), first_aim(open(f"{work}/aim.log").read())
check(plain is not None and aimed is not None and abs(aimed - target) <= abs(plain - target) + 0.01,
      f"angle_aim_sd 1: the first run aimed at {aimed}°, no farther from the target {target}° than without it ({plain}°)")
check("inside the angle's tolerance, at most at its centre (angle_aim_sd)" in open(f"{work}/aim/report.md").read(),
      "angle_aim_sd 1: report.md says how the loop's runs were aimed")
finish()
PY
