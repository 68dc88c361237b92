#!/usr/bin/env python3
"""What a calibration's drum runs spent their time on, phase by phase, from its committed store (issue 37.1;
a measurement, not a test): no simulation is run.

Each drum record (store/*.yaml) gives its key (lambda, rpm, the averaging time after the steady test),
its simulated time of turning, the wall time of that turning, and the wall time of the bed's fill where
this run made the bed (a bed is poured and settled once per granule pair and seed, then turned at every
speed; the others read it). The turn is split at the simulated time where averaging began: before it,
the transient and the steady test's two windows; after it, the averaging. Wall time is shared between them
in proportion to simulated time (one step size per run, the same granules throughout).

A run that starts from a turned bed (its key names start=turned[...]) is stopped by MSER, which cuts the
transient itself and keeps no split in the record: its whole turn is counted as "turn under MSER", and the
turned bed it was charged (fill_wall_time_s: the bed poured and turned first, once a seed and stage) as
"turned bed". Only the records the run used are read (RESULTS_DIR/simulations.csv), where that file is
there: a store may hold others' records too.

    usage: phase_costs.py RESULTS_DIR [--lambda L]   (prints a Markdown table)
"""
import argparse
import csv
import glob
import os
import re
from collections import defaultdict


def read_record(path):
    record = {}
    with open(path) as f:
        for line in f:
            m = re.match(r"^(\w+): '?(.*?)'?$", line.rstrip("\n"))
            if m:
                record[m.group(1)] = m.group(2)
    return record


def key_number(key, name):
    m = re.search(r"\b%s=([0-9.eE+-]+)" % name, key)
    return float(m.group(1)) if m else None


def used_records(results):
    """The record hashes the run used (simulations.csv), or None to read every record."""
    path = os.path.join(results, "simulations.csv")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return {row["record"] for row in csv.DictReader(f)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results")
    parser.add_argument("--lambda", dest="lam", type=float, default=None, help="only drums at this lambda")
    args = parser.parse_args()
    rows = defaultdict(lambda: defaultdict(float))
    used = used_records(args.results)
    for path in sorted(glob.glob(os.path.join(args.results, "store", "*.yaml"))):
        if used is not None and os.path.basename(path)[:-len(".yaml")] not in used:
            continue
        r = read_record(path)
        key = r.get("key", "")
        if not key.startswith("drum ") or r.get("status") != "ok":
            continue
        lam = key_number(key, "lambda")
        if args.lam is not None and lam != args.lam:
            continue
        rpm = key_number(key, "rpm")
        simulated = float(r["simulated_time_s"])
        turn_wall = float(r["wall_time_s"])
        fill_wall = float(r.get("fill_wall_time_s", 0) or 0)
        turned = "start=turned[" in key
        averaged = min(key_number(key, "average_time") or 0.0, simulated) if r.get("steady") == "true" else 0.0
        row = rows[(lam, rpm, "turned, MSER" if turned else "level")]
        row["runs"] += 1
        row["fills"] += fill_wall > 0
        row["fill_wall"] += fill_wall
        row["transient_sim"] += simulated - averaged
        row["averaging_sim"] += averaged
        row["transient_wall"] += turn_wall * (simulated - averaged) / simulated
        row["averaging_wall"] += turn_wall * averaged / simulated
    total = sum(r["fill_wall"] + r["transient_wall"] + r["averaging_wall"] for r in rows.values())
    print("| λ | rpm | start | runs | beds filled or turned here | fill or turned bed (core-s) | transient + steady "
          "test (turned: the whole turn under MSER): s simulated a run, core-s | averaging: s simulated a run, core-s "
          "| share of all drum core-s |")
    print("|---:|---:|---|---:|---:|---:|---:|---:|---:|")
    for (lam, rpm, start), r in sorted(rows.items()):
        n = r["runs"]
        own = r["fill_wall"] + r["transient_wall"] + r["averaging_wall"]
        print("| %g | %g | %s | %d | %d | %.0f | %.2f s, %.0f | %.2f s, %.0f | %.1f %% |" % (
            lam, rpm, start, n, r["fills"], r["fill_wall"], r["transient_sim"] / n, r["transient_wall"],
            r["averaging_sim"] / n, r["averaging_wall"], 100 * own / total))
    phases = {p: sum(r[p] for r in rows.values()) for p in ("fill_wall", "transient_wall", "averaging_wall")}
    print()
    print("All drums: %.2f core-hours: fill %.1f %%, transient and steady test %.1f %%, averaging %.1f %%." % (
        total / 3600, 100 * phases["fill_wall"] / total, 100 * phases["transient_wall"] / total,
        100 * phases["averaging_wall"] / total))


if __name__ == "__main__":
    main()
