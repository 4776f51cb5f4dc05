#!/usr/bin/env python3
"""Surge front of a 2D dam-break run against Koshizuka & Oka (1996).

Usage: scripts/dam_break_front.py RUN_DIR SPACING [T_MAX]

RUN_DIR is the --out directory of `cellsph run` with CSV frames (--format csv); the front at a frame is
the largest x of a fluid particle (kind 0) plus half a spacing, interpolated linearly in time between
frames to each published time up to T = t sqrt(2 g / a) = T_MAX (default 3, a = 1 m). Prints one line
per point and the worst relative error; exits 1 if any point is off by more than 10%.
"""
import csv
import math
import os
import sys


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    run, spacing = sys.argv[1], float(sys.argv[2])
    t_max = float(sys.argv[3]) if len(sys.argv) == 4 else 3.0
    here = os.path.dirname(os.path.abspath(__file__))
    ref_path = os.path.join(here, "..", "data", "validation", "koshizuka_oka_1996_front.tsv")
    ref = []
    with open(ref_path) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                t, x = map(float, line.split())
                ref.append((t, x))
    index = os.path.join(run, "frames.csv")
    if not os.path.exists(index):
        sys.exit(f"{index}: not found (run `cellsph run ... --format csv --out {run}` first)")
    fronts = []
    with open(index) as f:
        for row in csv.DictReader(f):
            if "csv" not in row or not row["csv"]:
                sys.exit(f"{index}: no 'csv' column: run with --format csv")
            with open(os.path.join(run, row["csv"])) as g:
                r = csv.reader(g)
                head = next(r)
                ix, ik = head.index("x"), head.index("kind")
                front = max(float(q[ix]) for q in r if q[ik] == "0")
            fronts.append((float(row["time"]), front + spacing / 2))
    g_factor = math.sqrt(2 * 9.81 / 1.0)
    worst, failed = 0.0, 0
    for t, x in ref:
        if t * g_factor > t_max + 1e-9:
            break
        sim = None
        for (t0, x0), (t1, x1) in zip(fronts, fronts[1:]):
            if t0 <= t <= t1:
                sim = x0 + (x1 - x0) * (t - t0) / (t1 - t0)
                break
        if sim is None:
            sys.exit(f"{run}: no frames around t = {t} s (run at least until {t} s)")
        err = (sim - x) / x
        worst = max(worst, abs(err))
        failed += abs(err) > 0.1
        print(f"T = {t * g_factor:4.2f}  experiment {x:6.3f} m  simulated {sim:6.3f} m  error {100 * err:+5.1f}%")
    print(f"worst error {100 * worst:.1f}%, {failed} point(s) beyond 10%")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
