#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The standard twin's rule (twin_standard_rule.py) on made-up calibrations whose verdicts are known,
so that the rule is tested before the twin it judges has ended: a friction inside both intervals and
narrow passes; one outside its credible interval, one outside its not-excluded interval, and one whose
credible interval spans more than half its range where a measurement moves with it each fail; a wide
interval where no measurement moves passes; a stage without a sensitivity table fails.

usage: test_twin_standard_rule.py WORK_DIR
"""
import os
import subprocess
import sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
from twin_standard_rule import judge, sensitivities  # noqa: E402

fails = 0


def check(ok, what):
    global fails
    print(("ok   " if ok else "FAIL ") + what)
    fails += not ok


bounds = {"mu_s_min": 0.1, "mu_s_max": 1.0, "mu_r_min": 1e-5, "mu_r_max": 0.5}


def row(parameter, credible, not_excluded):
    return {"parameter": parameter, "credible_min": credible[0], "credible_max": credible[1],
            "not_excluded_min": not_excluded[0], "not_excluded_max": not_excluded[1]}


# mu_s: range 0.9; an interval 0.6-0.9 is 0.33 of it.
f, share, _ = judge(row("mu_s", (0.6, 0.9), (0.5, 1.0)), 0.8, bounds, 12.0)
check(not f and abs(share - 0.3 / 0.9) < 1e-12, f"inside both, a third of the range: passes ({f})")
f, _, _ = judge(row("mu_s", (0.85, 0.95), (0.5, 1.0)), 0.8, bounds, 12.0)
check(f == ["outside the credible interval"], f"outside the credible interval: fails ({f})")
f, _, _ = judge(row("mu_s", (0.6, 0.9), (0.85, 1.0)), 0.8, bounds, 12.0)
check(f == ["outside the interval not excluded"], f"outside the interval not excluded: fails ({f})")
f, share, _ = judge(row("mu_s", (0.2, 0.9), (0.1, 1.0)), 0.8, bounds, 12.0)
check(len(f) == 1 and f[0].startswith("credible interval 0.78"), f"wide where a measurement moves: fails ({f})")
f, _, told = judge(row("mu_s", (0.2, 0.9), (0.1, 1.0)), 0.8, bounds, 0.4)
check(not f and not told, f"wide where no measurement moves by a spread: passes, not told ({f})")
# mu_r on log10: 1e-5..0.5 is 4.70 decades; 1e-4..1e-3 is one of them, 0.21.
f, share, _ = judge(row("mu_r", (1e-4, 1e-3), (1e-5, 0.5)), 3e-4, bounds, 5.0)
check(not f and abs(share - 1 / 4.69897) < 1e-4, f"mu_r measured in decades: {share:.3f} of the range")
f, _, _ = judge(row("mu_r", (1e-4, 1e-3), (1e-5, 0.5)), 3e-4, bounds, None)
check(f == ["no sensitivity table for its stage"], f"no sensitivity table: fails ({f})")
# The printed six digits: a truth equal to an end as printed is inside.
f, _, _ = judge(row("mu_s", (0.8000001, 0.9), (0.5, 1.0)), 0.8, bounds, 12.0)
check(not f, f"an end equal to the truth within the CSV's six digits: inside ({f})")

report = """# x
## granule-granule (surface 'spray-dried powder' in the data)
What each measurement can tell (its change ...):

| measurement | data spread | across μs | across μr |
|---|---|---|---|
| angle at 4 rpm | 0.559 | +63.20 | -31.93 |
| CSA at 116 rpm | 0.461 | -0.50 | +70.75 |

## PP (surface 'PP' in the data)
no table here
"""
s = sensitivities(report)
check(s == {"granule-granule": {"mu_s": 63.2, "mu_r": 70.75}}, f"the sensitivity tables read per stage: {s}")

# The whole script on a made-up folder: exit 1 when a friction fails, and --expect compares.
work = sys.argv[1]
os.makedirs(work, exist_ok=True)
with open(f"{work}/config.yaml", "w") as f_:
    f_.write("granule: {mu_s_min: 0.1, mu_s_max: 1.0, mu_r_min: 0.001, mu_r_max: 0.5}\n"
             "wall: {mu_s_min: 0.1, mu_s_max: 1.0, mu_r_min: 0.00001, mu_r_max: 0.5}\n")
with open(f"{work}/report.md", "w") as f_:
    f_.write(report)
header = "contact,material,parameter,value,status,not_excluded_min,not_excluded_max,credible_min,credible_max\n"
with open(f"{work}/calibrated_parameters.csv", "w") as f_:
    f_.write(header + "granule-granule,,mu_s,0.8,calibrated,0.5,1,0.7,0.9\n"
                      "granule-granule,,mu_r,0.2,calibrated,0.1,0.3,0.15,0.25\n")
with open(f"{work}/truth.csv", "w") as f_:
    f_.write("contact,material,parameter,value\ngranule-granule,,mu_s,0.8\ngranule-granule,,mu_r,0.2\n")
script = os.path.join(here, "twin_standard_rule.py")
run = subprocess.run([sys.executable, script, work, f"{work}/truth.csv"], capture_output=True, text=True)
check(run.returncode == 0 and run.stdout.count("| pass |") == 2, f"a twin that passes: exit 0 ({run.stderr.strip()})")
with open(f"{work}/verdict.md", "w") as f_:
    f_.write(run.stdout)
again = subprocess.run([sys.executable, script, work, f"{work}/truth.csv", "--expect", f"{work}/verdict.md"],
                       capture_output=True, text=True)
check(again.returncode == 0, "--expect: the same verdict regenerated")
with open(f"{work}/truth.csv", "w") as f_:
    f_.write("contact,material,parameter,value\ngranule-granule,,mu_s,0.95\ngranule-granule,,mu_r,0.2\n")
run = subprocess.run([sys.executable, script, work, f"{work}/truth.csv"], capture_output=True, text=True)
check(run.returncode == 1 and "FAIL: outside the credible interval" in run.stdout, "a truth outside: exit 1, said")
again = subprocess.run([sys.executable, script, work, f"{work}/truth.csv", "--expect", f"{work}/verdict.md"],
                       capture_output=True, text=True)
check(again.returncode == 1, "--expect: a changed verdict differs")
with open(f"{work}/failing.md", "w") as f_:
    f_.write(run.stdout)
again = subprocess.run([sys.executable, script, work, f"{work}/truth.csv", "--expect", f"{work}/failing.md"],
                       capture_output=True, text=True)
check(again.returncode == 0, "--expect: a committed failing verdict regenerated is the same, exit 0")
print(f"{fails} failure(s)")
sys.exit(1 if fails else 0)
