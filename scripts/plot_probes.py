#!/usr/bin/python3
"""Plots a run's probes.csv, one panel per probe, optionally against measured data.

Usage: scripts/plot_probes.py RUN_DIR [--out FILE.png] [--data FILE.tsv] [--match PROBE=COLUMN ...]
                              [--time-scale S] [--value-scale V]

RUN_DIR holds probes.csv (`cellsph run` with `probes` in the scene). With --data, a tab- or comma-separated
table (lines starting with '#' are comments, the first other line is the header, the first column is time)
is drawn over the probes: `--match gauge=h_x0865_a` puts the data column h_x0865_a on the panel of probe
`gauge` (repeatable; by default a data column whose name equals a probe's is matched). Data times are
multiplied by --time-scale and values by --value-scale to give seconds and the probe's unit (e.g. a table in
T = t sqrt(g/H) and h/H: --time-scale 0.1749 --value-scale 0.3 for H = 0.3 m). Needs matplotlib
(Debian: python3-matplotlib). Writes RUN_DIR/probes.png unless --out is given.
"""
import argparse
import csv
import math
import os
import sys


def read_probes(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows or rows[0][0] != "time":
        sys.exit(f"{path}: not a probes file (its header must start with 'time')")
    head, data = rows[0], rows[1:]
    cols = {name: [] for name in head}
    for n, row in enumerate(data, start=2):
        if len(row) != len(head):
            sys.exit(f"{path}, line {n}: {len(row)} fields, the header has {len(head)}")
        for name, v in zip(head, row):
            cols[name].append(float(v) if v else math.nan)
    return head, cols


def read_table(path):
    lines = []
    with open(path) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                lines.append(line.rstrip("\n"))
    if not lines:
        sys.exit(f"{path}: no header and no data")
    sep = "\t" if "\t" in lines[0] else ","
    head = [h.strip() for h in lines[0].split(sep)]
    cols = {h: [] for h in head}
    for n, line in enumerate(lines[1:], start=2):
        fields = line.split(sep)
        if len(fields) != len(head):
            sys.exit(f"{path}: data line {n}: {len(fields)} fields, the header has {len(head)}")
        for h, v in zip(head, fields):
            try:
                cols[h].append(float(v))
            except ValueError:
                sys.exit(f"{path}: data line {n}, column '{h}': not a number: '{v}'")
    return head, cols


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run")
    ap.add_argument("--out")
    ap.add_argument("--data")
    ap.add_argument("--match", action="append", default=[])
    ap.add_argument("--time-scale", type=float, default=1.0)
    ap.add_argument("--value-scale", type=float, default=1.0)
    a = ap.parse_args()
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        sys.exit("plot_probes.py: needs matplotlib (apt-get install python3-matplotlib)")
    path = os.path.join(a.run, "probes.csv")
    if not os.path.exists(path):
        sys.exit(f"{path}: not found (add `probes` to the scene, docs/scenes.md)")
    head, probes = read_probes(path)
    names = head[1:]
    matches = {}
    data_head, data = [], {}
    if a.data:
        data_head, data = read_table(a.data)
        for name in names:
            if name in data:
                matches.setdefault(name, []).append(name)
        for m in a.match:
            probe, _, column = m.partition("=")
            if probe not in names:
                sys.exit(f"--match {m}: no probe column '{probe}' in {path} (have: {', '.join(names)})")
            if column not in data:
                sys.exit(f"--match {m}: no column '{column}' in {a.data} (have: {', '.join(data_head)})")
            matches.setdefault(probe, []).append(column)
    fig, axes = plt.subplots(len(names), 1, figsize=(8, 2.2 * len(names)), sharex=True, squeeze=False)
    for ax, name in zip(axes[:, 0], names):
        ax.plot(probes["time"], probes[name], label=f"cellsph {name}")
        for column in matches.get(name, []):
            t = [v * a.time_scale for v in data[data_head[0]]]
            ax.plot(t, [v * a.value_scale for v in data[column]], "k.", ms=3, label=f"data {column}")
        ax.set_ylabel(name)
        ax.legend(loc="best", fontsize=8)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    fig.tight_layout()
    out = a.out or os.path.join(a.run, "probes.png")
    fig.savefig(out, dpi=110)
    print(f"plot_probes.py: wrote {out}")


if __name__ == "__main__":
    main()
