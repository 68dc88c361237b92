# SPDX-License-Identifier: MIT
"""What the calibration tests' Python checks share: an ok/FAIL line per check, the tally that sets
the exit code, and a tier's whole-number key read from the config's own block."""
import re
import sys

fails = []


def check(ok, what):
    """One check, printed 'ok   ...' or 'FAIL ...'; a failure is kept for finish()."""
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        fails.append(what)


def tier_int(config, tier, key):
    """The whole-number `key` of tier `tier` in the YAML file `config`, from that tier's block."""
    block = re.search(rf"^  - name: {re.escape(tier)}\n((?:    .*\n|\s*#.*\n)*)", open(config).read(), re.M).group(1)
    return int(re.search(rf"^    {re.escape(key)}: (\d+)", block, re.M).group(1))


def finish():
    """Exit 1 if any check failed, else 0, after saying how many failed."""
    print(f"{len(fails)} failure(s)")
    sys.exit(1 if fails else 0)
