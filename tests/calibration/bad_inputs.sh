#!/usr/bin/env bash
# granucal calibrate refuses bad input before the first simulation: each case must exit
# non-zero within seconds, print one error naming the file, line and field, and leave no
# results behind.
#   usage: bad_inputs.sh GRANUCAL SOURCE_DIR WORK_DIR
set -uo pipefail
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work/data" "$work/configs"
cp "$src/experiments/data/repose_angle.csv" "$work/data/"
printf 'surface,rpm,csa_percent,csa_sd_percent\n' > "$work/data/occupied_area.csv"
for s in "spray-dried powder" Aluminium PP PTFE; do
  for r in 4 40 80 105 116; do echo "$s,$r,45,0.5" >> "$work/data/occupied_area.csv"; done
done
sed 's|\.\./experiments/data/|../data/|' "$src/configs/calibration.yaml" > "$work/configs/good.yaml"
fails=0
# expect NAME EXPECTED-TEXT -- ARGS...: non-zero exit, the text in stderr, under 20 s, and
# (in the sanitized build) nothing leaked on the way out (the command: calibrate, or $cmd
# when set for the call).
expect() {
  local name=$1 want=$2; shift 3
  local start=$SECONDS out
  out=$(timeout 20 "$bin" "${cmd:-calibrate}" "$@" 2>&1 >/dev/null); local code=$?
  if [ $code -eq 0 ] || [ $code -eq 124 ] || ! grep -qF -- "$want" <<< "$out" || grep -q LeakSanitizer <<< "$out"; then
    echo "FAIL $name: exit $code, wanted '$want' in: $out"; fails=$((fails + 1))
  else
    echo "ok   $name ($((SECONDS - start)) s): $(head -1 <<< "$out")"
  fi
}
edit() { # edit NAME SED-EXPRESSION: a copy of the good config with one change
  sed "$2" "$work/configs/good.yaml" > "$work/configs/$1.yaml"; echo "$work/configs/$1.yaml"
}
csv() { # csv NAME CONTENT: a config whose angle file is CONTENT
  printf '%b' "$2" > "$work/data/$1.csv"
  sed "s|repose_angle: ../data/repose_angle.csv|repose_angle: ../data/$1.csv|" "$work/configs/good.yaml" > "$work/configs/$1.yaml"
  echo "$work/configs/$1.yaml"
}
csa() { # csa NAME CONTENT: a config whose occupied-area file is CONTENT
  printf '%b' "$2" > "$work/data/$1.csv"
  sed "s|occupied_area: ../experiments/data/occupied_area.csv|occupied_area: ../data/$1.csv|" "$src/configs/calibration.yaml" |
    sed 's|\.\./experiments/data/|../data/|' > "$work/configs/$1.yaml"
  echo "$work/configs/$1.yaml"
}
out=(--out "$work/out")
expect "missing config" "nonexistent.yaml" -- "$work/configs/nonexistent.yaml" "${out[@]}"
expect "negative friction" "pour_mu_s.yaml:" -- "$(edit pour_mu_s 's/^pour_mu_s: 0.5/pour_mu_s: -0.5/')" "${out[@]}"
expect "fill above 100 %" "fill: 1.5 must be in (0, 1)" -- "$(edit fill 's/^fill: 0.43/fill: 1.5/')" "${out[@]}"
expect "text in a number" ": xi: Invalid FLOAT value" -- "$(edit xi 's/^xi: 0.7/xi: high/')" "${out[@]}"
expect "unknown key" "viscosity: Unexpected key" -- "$(edit key 's/^seed: 1/seed: 1\nviscosity: 2/')" "${out[@]}"
expect "unknown angle rule" "angle_rule: 'maybe'" -- "$(edit rule 's/angle_rule: misfit/angle_rule: maybe/')" "${out[@]}"
expect "negative CSA spread" "csa_sd_percent: -0.55 must be in [0, 50)" -- "$(edit csa_sd 's/csa_sd_percent: \[0.55,/csa_sd_percent: [-0.55,/')" "${out[@]}"
expect "fractional --jobs" "--jobs '2.5': expected a whole number in 1..1024" -- "$work/configs/good.yaml" --jobs 2.5 "${out[@]}"
expect "bound probes neither yes nor no" "bound_probes: Invalid ENUM value: perhaps" -- "$(edit probes 's/bound_probes: false/bound_probes: perhaps/')" "${out[@]}"
expect "design corners neither yes nor no" "design_corners: Invalid ENUM value: perhaps" -- "$(edit corners 's/design_corners: yes/design_corners: perhaps/')" "${out[@]}"
expect "CSA spreads not one per speed" "csa_sd_percent: 2 values for 3 speeds" -- "$(edit csa_sd_count 's/csa_sd_percent: \[0.55, 0.81, 1.37\]/csa_sd_percent: [0.55, 0.81]/')" "${out[@]}"
expect "averaging past max_time" "average_time: 9 must be >= 0 and fit with two windows" -- "$(edit avg 's/^    max_time: 1.5/    max_time: 1.5\n    average_time: 9/')" "${out[@]}"
expect "unknown fill method" "fill_method: 'shake': use pour or pack" -- "$(edit fillm '0,/^    max_time: 1.5/s//    max_time: 1.5\n    fill_method: shake/')" "${out[@]}"
expect "unknown steady rule" "steady_rule: 'eyeball': use windows or mser" -- "$(edit steady '0,/^    max_time: 1.5/s//    max_time: 1.5\n    steady_rule: eyeball/')" "${out[@]}"
expect "mser without its targets" "steady_rule mser needs steady_se_angle_deg and steady_se_csa_percent > 0 (got 0.2, 0)" -- "$(edit mser_se '0,/^    max_time: 1.5/s//    max_time: 1.5\n    steady_rule: mser\n    steady_se_angle_deg: 0.2/')" "${out[@]}"
expect "mser with an averaging time" "steady_rule: mser stops each run itself: give no average_time" -- "$(edit mser_avg '0,/^    max_time: 1.5/s//    max_time: 1.5\n    average_time: 0.5\n    steady_rule: mser\n    steady_se_angle_deg: 0.2\n    steady_se_csa_percent: 0.1/')" "${out[@]}"
expect "turned start at a speed not turned" "turned_start_rpm: 40 is not one of the tier's rpm" -- "$(edit turned_rpm 's/turned_start_rpm: \[4\]/turned_start_rpm: [40]/')" "${out[@]}"
expect "turned start of no time" "turned_start_time: -1 must be in (0, 600] s of turning" -- "$(edit turned_time 's/turned_start_time: 1.0/turned_start_time: -1/')" "${out[@]}"
expect "turned start without MSER's targets" "turned_start_rpm: a turned start's runs stop by MSER: give steady_se_angle_deg and steady_se_csa_percent > 0" -- "$(edit turned_se '/steady_se_csa_percent: 1.0/d')" "${out[@]}"
expect "turned speed with an averaging time" "average_time_per_rpm: 4 rpm starts turned and stops by MSER: give it an averaging time of 0" -- "$(edit turned_avg 's/    turned_start_time: 1.0/    turned_start_time: 1.0\n    average_time_per_rpm: [1.0, 0.5]/')" "${out[@]}"
# A tier the user asked for names the option, the file and the tiers it has; one the file names, its line.
tiers=$(sed -n 's/^  - name: \(.*\)/\1/p' "$work/configs/good.yaml" | paste -sd, | sed 's/,/, /g')
expect "unknown --tier" "--tier fast: not a tier of $work/configs/good.yaml; its tiers: $tiers" -- "$work/configs/good.yaml" --tier fast "${out[@]}"
expect "unknown tier in the file" "good_tier.yaml:$(grep -n '^tier:' "$work/configs/good.yaml" | cut -d: -f1): tier: 'fast' is not one of its tiers: $tiers" -- "$(edit good_tier 's/^tier: quick/tier: fast/')" "${out[@]}"
cmd=synthesize expect "synthesize: unknown --tier" "--tier fast: not a tier of $work/configs/good.yaml; its tiers: $tiers" -- "$work/configs/good.yaml" --tier fast "${out[@]}"
cmd=study expect "study: unknown rung" "--rungs L1000-slice9-avg8,L3-full: 'L3-full' is not a rung of $work/configs/good.yaml (fidelity.rungs); its rungs: L65536-slice40, " -- fidelity "$work/configs/good.yaml" --rungs L1000-slice9-avg8,L3-full "${out[@]}"
# A tier and a rung are one struct and one schema (cal_tier): a rung may not give a tier's own
# keys, and a tier may not leave out those it needs (optional in the schema, for the rungs).
cmd=study expect "rung with a tier's key" "grid: a key of a calibration tier: a rung takes the drum's" -- fidelity "$(edit rung_grid 's/{name: L4096-slice15, lambda/{name: L4096-slice15, grid: 3, lambda/')" --rungs L4096-slice15 --plan "${out[@]}"
expect "tier without seeds" "seeds: a calibration tier needs it" -- "$(edit no_seeds '0,/^    seeds: 2/{/^    seeds: 2/d}')" --plan "${out[@]}"
# A measured size table (gsd_table): its rows checked and named; not with the log-normal's keys; its basis required.
printf 'size_um,cumulative_percent\n100,0\n200,40\n300,30\n400,100\n' > "$work/configs/psd.csv"
expect "size table decreasing" "psd.csv:4: cumulative_percent: 30 is below the row above (40)" -- "$(edit psd 's/^median_diameter: .*/gsd_table: psd.csv\ngsd_basis: volume/; /^geometric_sd:/d; /^truncation_sigmas:/d')" "${out[@]}"
expect "size table and log-normal" "median_diameter: gsd_table gives the size distribution" -- "$(edit psd_both 's/^density: 1800 .*/density: 1800\ngsd_table: psd.csv\ngsd_basis: volume/')" "${out[@]}"
expect "size table without basis" "gsd_basis: 'absent'" -- "$(edit psd_basis 's/^median_diameter: .*/gsd_table: psd.csv/; /^geometric_sd:/d; /^truncation_sigmas:/d')" "${out[@]}"
expect "unknown material" "--material 'granite'" -- "$work/configs/good.yaml" --material granite "${out[@]}"
expect "unknown stage" "--stage 'polish'" -- "$work/configs/good.yaml" --stage polish "${out[@]}"
expect "empty CSV" "empty.csv:1: header" -- "$(csv empty '')" "${out[@]}"
expect "wrong columns" "cols.csv:1: header" -- "$(csv cols 'surface,rpm,angle\nPTFE,4,31\n')" "${out[@]}"
expect "NaN in CSV" "nan.csv:2: angle_deg" -- "$(csv nan 'surface,rpm,angle_deg,angle_sd_deg\nPTFE,4,nan,0.5\n')" "${out[@]}"
expect "negative rpm" "rpm.csv:2: rpm" -- "$(csv rpm 'surface,rpm,angle_deg,angle_sd_deg\nPTFE,-4,31.9,0.5\n')" "${out[@]}"
expect "truncated CSV" "trunc.csv:2: row" -- "$(csv trunc 'surface,rpm,angle_deg,angle_sd_deg\nPTFE,4,31')" "${out[@]}"
# A row with more fields than its header (issue 26), in either file, on its first data row.
expect "extra fields, angle file" "extra_angle.csv:2: row: has 7 fields, expected 4" -- "$(csv extra_angle 'surface,rpm,angle_deg,angle_sd_deg\nPTFE,4,31.9,0.5,1,2,3\nPP,4,32.2,0.5\n')" "${out[@]}"
expect "extra fields, CSA file" "extra_csa.csv:3: row: has 7 fields, expected 4" -- "$(csa extra_csa '# lab\nsurface,rpm,csa_percent,csa_sd_percent\nPTFE,4,45,0.5,1,2,3\nPTFE,40,50,0.5\n')" "${out[@]}"
expect "surface missing" "no row for surface 'PP'" -- "$(csv nopp 'surface,rpm,angle_deg,angle_sd_deg\nPTFE,4,31.9,0.5\nAluminium,4,34.2,0.5\nspray-dried powder,4,34.6,0.5\n')" "${out[@]}"
expect "unwritable results" "/proc/granucal" -- "$work/configs/good.yaml" --out /proc/granucal
expect "a plan over the budget" "over --budget-hours 0.001, which judges the expected figure: nothing was run" -- "$work/configs/good.yaml" --tier ci --budget-hours 0.001 "${out[@]}"
# Stage 1 alone has no drum run: its poured cylinders are predicted and refused too.
expect "stage 1 over the budget" "over --budget-hours 0.0001, which judges the expected figure" -- "$work/configs/good.yaml" --tier ci --stage stiffness --budget-hours 0.0001 "${out[@]}"
expect "a budget not a number" "--budget-hours 'soon'" -- "$work/configs/good.yaml" --budget-hours soon "${out[@]}"
expect "--data without its files" "nodata/repose_angle.csv: cannot open" -- "$work/configs/good.yaml" --data "$work/nodata" "${out[@]}"
expect "map tier of other speeds" "map_tier: 'quick' must turn the same rpm list" -- "$(edit map 's/map_tier: ci-map$/map_tier: quick/')" "${out[@]}"
# Levels (issue 37.2): a map tier may map with another, but never round in a cycle nor onto itself;
# each refused at the map_tier line of the first tier the check meets, with the chain it found.
line_of() { grep -n "$2" "$1" | head -1 | cut -d: -f1; }
self=$(edit map_self 's/map_tier: check$/map_tier: check-two-tier/')
expect "map tier itself" "map_self.yaml:$(line_of "$self" 'map_tier: check-two-tier$'): map_tier: 'check-two-tier' is this tier itself" -- "$self" "${out[@]}"
cycle=$(edit map_cycle 's/map_tier: check$/map_tier: check-levels/')
expect "map tiers in a cycle" "map_cycle.yaml:$(line_of "$cycle" 'map_tier: check-levels'): map_tier: the map tiers make a cycle (check-two-tier -> check-levels -> check-two-tier)" -- "$cycle" "${out[@]}"
# posterior_runs (issue 35.4): a count in [0, 16], and only on a tier with a corrected map to refine.
many=$(edit posterior_many 's/posterior_runs: 2$/posterior_runs: 17/')
expect "posterior runs out of range" "posterior_many.yaml:$(line_of "$many" 'posterior_runs: 17'): posterior_runs: 17 must be in [0, 16]" -- "$many" "${out[@]}"
alone=$(edit posterior_alone '/map_tier: ci-map$/d')
# (the standard tier's is the last posterior_runs line; the check tiers keep their map_tier)
expect "posterior runs without a map" "posterior_alone.yaml:$(grep -n 'posterior_runs: 2' "$alone" | tail -1 | cut -d: -f1): posterior_runs: only a tier with a map_tier" -- "$alone" "${out[@]}"
# return_runs: a count in [0, 16], and only after posterior_runs (runs to return from).
back=$(edit return_many 's/return_runs: 1$/return_runs: 17/')
expect "return runs out of range" "return_many.yaml:$(line_of "$back" 'return_runs: 17'): return_runs: 17 must be in [0, 16]" -- "$back" "${out[@]}"
back=$(edit return_alone '/posterior_runs: 2$/d')
expect "return runs without posterior runs" "return_alone.yaml:$(line_of "$back" 'return_runs: 1$'): return_runs: only a tier with posterior_runs" -- "$back" "${out[@]}"
# angle_aim_sd: standard deviations in [0, 3], and only on a tier whose runs a corrected map aims.
aim=$(edit aim_many 's/return_runs: 1$/return_runs: 1\n    angle_aim_sd: 4/')
expect "angle aim out of range" "aim_many.yaml:$(line_of "$aim" 'angle_aim_sd: 4'): angle_aim_sd: 4 must be in [0, 3] standard deviations" -- "$aim" "${out[@]}"
aim=$(edit aim_alone '/- name: check$/a\    angle_aim_sd: 1')
expect "angle aim without a map" "aim_alone.yaml:$(line_of "$aim" 'angle_aim_sd: 1'): angle_aim_sd: only a tier with a map_tier" -- "$aim" "${out[@]}"
aim=$(edit aim_misfit 's/return_runs: 1$/return_runs: 1\n    angle_rule: misfit\n    angle_aim_sd: 1/')
expect "angle aim under the misfit rule" "aim_misfit.yaml:$(line_of "$aim" 'angle_aim_sd: 1'): angle_aim_sd: angle_rule misfit weighs the angle in the misfit" -- "$aim" "${out[@]}"
# granucal synthesize (twin data): pairs and beds checked before the first run.
walls=(--wall aluminium=0.8,0.2 --wall PP=0.9,1e-4 --wall PTFE=0.9,1e-4)
cmd=synthesize expect "twin: a material without its pair" "no --wall PTFE=MU_S,MU_R" -- "$work/configs/good.yaml" --wall aluminium=0.8,0.2 --wall PP=0.9,1e-4 "${out[@]}"
cmd=synthesize expect "twin: a pair not a pair" "--wall 'PP=0.9': expected NAME=MU_S,MU_R, both > 0" -- "$work/configs/good.yaml" --wall PP=0.9 "${out[@]}"
cmd=synthesize expect "twin: a wall not in the config" "--wall granite: not a material" -- "$work/configs/good.yaml" "${walls[@]}" --wall granite=0.5,0.1 "${out[@]}"
cmd=synthesize expect "twin: on the candidates' own bed" "--seeds: 2 is a bed of" -- "$work/configs/good.yaml" "${walls[@]}" --tier ci --seeds 2,101 "${out[@]}"
# --plan checks every input as a run would (a bad one still fails), prints the plan, and
# stops with exit 0 before making the results folder.
expect "negative friction under --plan" "pour_mu_s.yaml:" -- "$work/configs/pour_mu_s.yaml" --plan "${out[@]}"
plan=$(timeout 20 "$bin" calibrate "$work/configs/good.yaml" --tier ci --jobs 2 --plan "${out[@]}" 2>&1 >/dev/null); code=$?
if [ $code -eq 0 ] && grep -q "^== plan: expected [0-9]* simulations, .* on 2 worker(s); worst case [0-9]* simulations, .* h on 2 worker" <<< "$plan" &&
   grep -qF -- "--plan: every input checked, nothing was run" <<< "$plan"; then
  echo "ok   --plan: $(head -1 <<< "$plan")"
else
  echo "FAIL --plan: exit $code: $plan"; fails=$((fails + 1))
fi
# An unknown option, or a missing value, of any command: one line naming it and where the options are.
for c in calibrate simulate measure "study fidelity" synthesize; do
  for bad in --frobnicate "--out"; do
    msg=$(timeout 20 "$bin" $c $bad 2>&1 >/dev/null); code=$?
    if [ $code -eq 2 ] && [ "$(wc -l <<< "$msg")" -eq 1 ] && grep -qF -- "'$bad'; see \`granucal $c --help\`" <<< "$msg"; then
      echo "ok   $c $bad: $msg"
    else echo "FAIL $c $bad: exit $code, wanted one line naming '$bad' and \`granucal $c --help\`: $msg"; fails=$((fails + 1)); fi
  done
done
# A bad value of any command's option (calib/cli/cal_options.c reads them all from each command's
# table): one line naming the option, the value and what it accepts, exit 2; the help lists it.
usage_error() { # usage_error WANT ARGS...: exit 2, one line on stderr holding WANT
  local want=$1; shift
  msg=$(timeout 20 "$bin" "$@" 2>&1 >/dev/null); code=$?
  if [ $code -eq 2 ] && [ "$(wc -l <<< "$msg")" -eq 1 ] && grep -qF -- "$want" <<< "$msg"; then echo "ok   $*: $msg"
  else echo "FAIL $*: exit $code, wanted one line with '$want': $msg"; fails=$((fails + 1)); fi
}
for c in calibrate "study fidelity" synthesize; do
  usage_error "granucal $c: --jobs '0': expected a whole number in 1..1024" $c --jobs 0
  help=$(timeout 20 "$bin" $c --help); code=$?
  if [ $code -eq 0 ] && grep -q -- "--jobs N .*accepts a whole number in 1..1024" <<< "$(tr -s ' \n' ' ' <<< "$help")"; then
    echo "ok   $c --help: lists --jobs with its range"
  else echo "FAIL $c --help: exit $code, no '--jobs N ... accepts a whole number in 1..1024'"; fails=$((fails + 1)); fi
done
usage_error "granucal simulate: --checkpoint-every '-1': expected wall seconds in [0, 86400]" simulate "$src/configs/drum.yaml" --checkpoint-every -1
usage_error "granucal study fidelity: --seeds '17': expected a whole number in 1..16" study fidelity --seeds 17
usage_error "granucal measure: --radius 'wide': expected a radius in pixels > 0" measure photo.png --radius wide
usage_error "granucal synthesize: --k-n '0': expected a stiffness in N/m > 0" synthesize --k-n 0
usage_error "granucal calibrate: --stage 'polish': expected all, stiffness, granule or wall" calibrate --stage polish
usage_error "granucal simulate: no SCENE.yaml given; see \`granucal simulate --help\`" simulate
usage_error "granucal calibrate: unexpected argument 'b.yaml'; see \`granucal calibrate --help\`" calibrate a.yaml b.yaml
# A wall lining the drum config does not have: the error lists those it has.
drum_walls=$(sed -n 's/^  - {name: \([^,]*\),.*/\1/p' "$src/configs/drum.yaml" | paste -sd, | sed 's/,/, /g')
cmd=simulate expect "unknown wall material" "wall = 'Steel': not 'granules' nor a name under materials; the walls are: granules, $drum_walls" -- "$src/configs/drum.yaml" --set wall=Steel --out "$work/out"
# measure prints JSON: a number it does not have (the spread of one measured photo) is null, not nan.
json=$(cd "$src" && timeout 60 "$bin" measure results/measure/photo.png "$work/no_such_photo.png" 2>/dev/null)
if python3 -c 'import json, sys
bad = lambda c: sys.exit("not JSON: " + c)
rows = [json.loads(l, parse_constant=bad) for l in sys.stdin.read().splitlines()]
assert rows[-1]["measured"] == 1 and rows[-1]["angle_sd_deg"] is None and rows[-1]["csa_sd_percent"] is None, rows[-1]' <<< "$json"; then
  echo "ok   measure: strict JSON, null for the spread of one photo: $(tail -1 <<< "$json")"
else echo "FAIL measure: not strict JSON with null spreads: $json"; fails=$((fails + 1)); fi
# synthesize --plan and study --plan: the plan (expected and worst case), exit 0, nothing run or made.
for c in "synthesize $work/configs/good.yaml --tier ci ${walls[*]}" "study fidelity $work/configs/good.yaml --rungs L4096-slice15"; do
  msg=$(timeout 20 "$bin" $c --jobs 2 --plan "${out[@]}" 2>&1 >/dev/null); code=$?
  if [ $code -eq 0 ] && grep -q "^== plan: .*expected [0-9.e+]* core-hours, .* h on 2 worker(s); worst case [0-9.e+]* core-hours" <<< "$msg" &&
     grep -q -- "--plan: .*nothing was run" <<< "$msg"; then echo "ok   ${c%% *} --plan: $(grep '^== plan: ' <<< "$msg" | tail -1)"
  else echo "FAIL ${c%% *} --plan: exit $code: $msg"; fails=$((fails + 1)); fi
done
# study without --rungs: the whole ladder's plan, then a line asking for --yes, exit 2, nothing run.
msg=$(timeout 20 "$bin" study fidelity "$work/configs/good.yaml" --jobs 2 "${out[@]}" 2>&1 >/dev/null); code=$?
if [ $code -eq 2 ] && grep -q "^== plan: study fidelity" <<< "$msg" && grep -q "^   L8-full " <<< "$msg" &&
   [ "$(tail -1 <<< "$msg")" = "granucal study: no --rungs: the plan above is the whole ladder; run it with --yes, or choose rungs with --rungs A,B (nothing was run)" ]; then
  echo "ok   study without --rungs: $(tail -1 <<< "$msg")"
else echo "FAIL study without --rungs: exit $code: $msg"; fails=$((fails + 1)); fi
[ -e "$work/out" ] && { echo "FAIL: a refused run left $work/out behind"; fails=$((fails + 1)); }
echo "$fails failure(s)"
exit $((fails > 0))
