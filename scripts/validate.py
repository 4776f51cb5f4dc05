#!/usr/bin/python3
"""Runs a validation scene and compares its probes with the experiment (docs/physics.md, "Validation").

Usage: scripts/validate.py CASE [--spacing S] [--until T] [--build DIR] [--out RUN_DIR] [--no-run]
                           [--threads N] [--figure FILE.png] [--walls MODEL] [--set /POINTER=VALUE ...]
                           [--compare RUN_DIR [--compare-label TEXT]]

CASE is `lobovsky` (built-in scene lobovsky-2014: Lobovsky et al. 2014, H = 0.3 m, 2D), `lobovsky-gate`
(built-in scene lobovsky-2014-gate: the same column released by the experiment's gate, lifted at 4.5 m/s
from t = 0; --compare RUN_DIR draws another run, e.g. the instant release's, dashed), `spheric`
(built-in scene spheric-test2: SPHERIC Test 2, Kleefsman et al. 2005, 3D), `spheric-2d` (SPHERIC's
column in 2D, lobovsky-2014 edited: its surge at x = 1.488 m for t <= 1 s, before the box's reflection
arrives, against the experiment and the shallow-water dam break of scripts/shallow_water.py; cheap
enough for a resolution series) or `martin-moyce-a` /
`martin-moyce-b` (dam-break-2d's set-up against Martin & Moyce 1952's residual column height at the back
wall, tables [A] and [B] of data/validation/martin_moyce_1952.txt: [A] the scene's 1 m x 2 m column in its
4 m tank, tau = t sqrt(g / a) <= 2.5; [B] a 1 m square column in an 8 m tank, tau <= 6.3; the level on
the vertical 2 spacings from the back wall, one support length, against the table within 0.05 of the
column height, issue 14's target; --walls picks the wall model). The scene is run with
`cellsph run` at spacing S (support 2 S; the tank, the column and the wall sensors follow the spacing's
lattice, see below) until T, into RUN_DIR (default validate-CASE-S); --no-run only compares an existing
RUN_DIR. Then, against the data of data/validation/:
  - arrival time at every gauge outside the initial column: the first time the level reaches the
    threshold (Lobovsky 0.1 H = 0.03 m, SPHERIC 0.05 m: a film thinner than about half the support reads
    as dry, 0.04 m at the coarsest SPHERIC spacing), linearly interpolated between samples, for the run
    and for each measured curve;
  - level RMS error over the window (Lobovsky T = t sqrt(g/H) < 6, SPHERIC the first 2 s, or up to T if
    shorter) against the measured curve (Lobovsky: the mean of its two series, whose own half-difference
    is printed as the experiment's spread), as a fraction of the gauge's measured peak level in the window;
  - SPHERIC: the peak pressure and its time at every sensor over the first impact (t < 1 s), P1 being the
    issue's target; P1's impulse over 0.38-0.50 s (the impact's time integral, which the weakly
    compressible model's acoustic spikes do not change: docs/physics.md) and its mean over 0.45-1 s;
  - SPHERIC (and spheric-2d): the level at x = 1.488 m over 0.3-1 s against the shallow-water dam break of
    the same column, for the run and for the experiment (mean of level / reference - 1).
Prints one line per quantity with the issue's target and "met" or "MISSED"; writes the figure (default
RUN_DIR/validation.png; matplotlib from Debian). Exits 0 when it could compare, whatever the result
(a report, not a test: the CI bounds are in src/cellsph/scene/validation_test.cpp).

Geometry at other spacings (the scene files are written for their own spacing): a block or wall spans
round(L / S) spacings from its min corner (docs/scenes.md), so for SPHERIC the tank ends at x = W =
round(3.22 / S) S, the column is the round(1.228 / S) spacings before W (it ends at the wall), and a
pressure sensor is half a spacing outside the box's lattice face (round(0.161 / S) S from its corner).
"""
import argparse
import json
import math
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
G = 9.81

LOBOVSKY = {
    "scene": "lobovsky-2014",
    "data": "lobovsky2014_water_levels_H300.tsv",
    "H": 0.3,
    "gauges": {"h_x0300": 0.300, "h_x0865": 0.865, "h_x1114": 1.114, "h_x1363": 1.3625},
    "in_column": {"h_x0300"},
    "threshold": 0.03,  # [m], 0.1 H
}
# The same comparison for lobovsky-2014-gate: the column released by the experiment's gate (lifted at
# 4.5 m/s from t = 0, the experiment's time origin) instead of instantly.
LOBOVSKY_GATE = dict(LOBOVSKY, scene="lobovsky-2014-gate")
SPHERIC = {
    "scene": "spheric-test2",
    "data": "spheric_test2_kleefsman2005.tsv",
    "gauges": {"level_x1488": 1.488, "level_x0992": 0.992, "level_x0496": 0.496, "level_x2638": 2.638},
    "in_column": {"level_x2638"},
    "threshold": 0.05,  # [m]
    "sensors_front": [0.021, 0.061, 0.101, 0.141],  # P1-P4: z on the face x = 0.8245
    "sensors_top": [0.8035, 0.7635, 0.7235, 0.6835],  # P5-P8: x on the top z = 0.161
    "sensor_y": 0.471,
}
SPHERIC_2D = {"scene": "lobovsky-2014"}


class Table(dict):
    """Columns by name; a column the comparison needs and the file lacks stops the script naming both."""

    def __init__(self, path, head):
        super().__init__((h, []) for h in head)
        self.path = path

    def __missing__(self, name):
        sys.exit(f"{self.path}: no column '{name}' (it has: {', '.join(self)}); a run's probes.csv needs the "
                 "probes of the case's scene: run without --no-run, or with the scene the case names")


def read_table(path):
    """A tab- or comma-separated table: '#' lines are comments, the first other line the header."""
    lines = [ln.rstrip("\n") for ln in open(path) if ln.strip() and not ln.startswith("#")]
    if not lines:
        sys.exit(f"{path}: no header and no data")
    if len(lines) < 2:
        sys.exit(f"{path}: a header and no data rows")
    sep = "\t" if "\t" in lines[0] else ","
    head = [h.strip() for h in lines[0].split(sep)]
    cols = Table(path, head)
    for n, line in enumerate(lines[1:], start=2):
        fields = line.split(sep)
        if len(fields) != len(head):
            sys.exit(f"{path}: data line {n}: {len(fields)} fields, the header has {len(head)}")
        for h, v in zip(head, fields):
            try:
                cols[h].append(float(v) if v.strip() else math.nan)
            except ValueError:
                sys.exit(f"{path}: data line {n}, column '{h}': not a number: '{v}'")
    return head, cols


def interp(ts, vs, t):
    """Linear interpolation of (ts, vs) at t (ts ascending); the end values outside."""
    if t <= ts[0]:
        return vs[0]
    if t >= ts[-1]:
        return vs[-1]
    lo, hi = 0, len(ts) - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if ts[mid] <= t:
            lo = mid
        else:
            hi = mid
    f = (t - ts[lo]) / (ts[hi] - ts[lo]) if ts[hi] > ts[lo] else 0.0
    return vs[lo] + f * (vs[hi] - vs[lo])


def arrival(ts, vs, threshold):
    """First time the series reaches threshold, linearly interpolated; None if it never does."""
    for k, v in enumerate(vs):
        if not math.isnan(v) and v >= threshold:
            if k == 0:
                return ts[0]
            v0 = vs[k - 1] if not math.isnan(vs[k - 1]) else 0.0
            return ts[k - 1] + (threshold - v0) / (v - v0) * (ts[k] - ts[k - 1])
    return None


def rms_error(ts, vs, ref_t, ref_v, t_end):
    """RMS of (run - reference) over the run's samples with t <= t_end (NaN samples read as dry, 0)."""
    d = [(0.0 if math.isnan(v) else v) - interp(ref_t, ref_v, t) for t, v in zip(ts, vs) if t <= t_end]
    return math.sqrt(sum(x * x for x in d) / len(d)) if d else math.nan


def peak(ts, vs, t_end):
    best = (math.nan, -math.inf)
    for t, v in zip(ts, vs):
        if t <= t_end and not math.isnan(v) and v > best[1]:
            best = (t, v)
    return best


def impulse(ts, ps, a=0.38, b=0.50):
    """The time integral of ps over the samples in [a, b] (trapezoids; a sample with no fluid reads 0)."""
    pts = [(t, 0.0 if math.isnan(p) else p) for t, p in zip(ts, ps) if a <= t <= b]
    return sum((t1 - t0) * (p0 + p1) / 2 for (t0, p0), (t1, p1) in zip(pts, pts[1:]))


def lround(x):
    """C's lround for x >= 0 (halves away from zero, as the scene reader counts spacings; Python's
    round() takes halves to even)."""
    return math.floor(x + 0.5)


def spheric_geometry(s):
    """The --set edits that place SPHERIC Test 2's tank, column and sensors on the lattice of spacing s."""
    n_tank = lround(3.22 / s)
    w = n_tank * s
    x0 = w - lround(1.228 / s) * s
    face = 0.6635 + lround(0.161 / s) * s
    top = lround(0.161 / s) * s
    c = SPHERIC
    probes = [{"name": n, "kind": "layer", "at": [x, 0.5, 0]} for n, x in c["gauges"].items()]
    probes += [{"name": f"P{k + 1}", "kind": "pressure", "at": [face + s / 2, c["sensor_y"], z]}
               for k, z in enumerate(c["sensors_front"])]
    probes += [{"name": f"P{k + 5}", "kind": "pressure", "at": [x, c["sensor_y"], top + s / 2]}
               for k, x in enumerate(c["sensors_top"])]
    return [f"/fluids/0/min=[{x0!r}, 0, 0]", f"/fluids/0/max=[{w!r}, 1.0, 0.55]",
            f"/boundary/walls/max=[{w!r}, 1.0, 1.0]", "/probes=" + json.dumps(probes)]


def martin_moyce(table):
    """Table [A] or [B]'s residual height: (tau, H) pairs, the second table of the section."""
    out, section, tables, numbers = [], None, 0, False
    for line in open(os.path.join(ROOT, "data", "validation", "martin_moyce_1952.txt")):
        if line.startswith("# ["):
            section, tables, numbers = line[2:5], 0, False
        elif not line.strip() or line.startswith("#"):
            numbers = False
        else:
            if not numbers:
                tables += 1
            numbers = True
            if section == table and tables == 2:
                tau, h = map(float, line.split()[:2])
                out.append((tau, h))
    return out


MM = {"A": {"height": 2.0, "tank": 4.0, "tau_max": 2.5}, "B": {"height": 1.0, "tank": 8.0, "tau_max": 7.0}}


def run_scene(a, case):
    scene = case["scene"] if isinstance(case, dict) and "scene" in case else "dam-break-2d"
    cmd = [os.path.join(a.build, "cellsph"), "run", scene, "--until", str(a.until), "--out", a.out,
           "--fps", "1", "--threads", str(a.threads), "--quiet",
           "--set", f"/spacing={a.spacing!r}", "--set", f"/solver/support={2 * a.spacing!r}"]
    if case is SPHERIC:
        for e in spheric_geometry(a.spacing):
            cmd += ["--set", e]
    if case is SPHERIC_2D:
        for e in spheric_2d_edits(a.spacing):
            cmd += ["--set", e]
    if case in ("A", "B"):
        m = MM[case]
        probe = [{"name": "wall", "kind": "level", "at": [2 * a.spacing, 0]}]
        cmd += ["--set", f"/fluids/0/max=[1.0, {m['height']}]", "--set", f"/boundary/walls/max/0={m['tank']}",
                "--set", f"/domain/max/0={m['tank'] + 0.5}", "--set", f"/boundary/model={a.walls}",
                "--set", "/probes_every=0.005", "--set", "/probes=" + json.dumps(probe)]
    for e in a.set:
        cmd += ["--set", e]
    print("validate.py: " + " ".join(cmd if case not in (SPHERIC, SPHERIC_2D) else cmd[:17]) + " ...", flush=True)
    r = subprocess.run(cmd)
    if r.returncode != 0:
        sys.exit(f"validate.py: cellsph run failed (exit {r.returncode})")


def verdict(ok):
    return "met" if ok else "MISSED"


def compare_lobovsky(run_dir, t_end):
    c = LOBOVSKY
    _, data = read_table(os.path.join(ROOT, "data", "validation", c["data"]))
    _, sim = read_table(os.path.join(run_dir, "probes.csv"))
    scale_t = math.sqrt(c["H"] / G)
    dt = [T * scale_t for T in data["T"]]
    window = min(6 * scale_t, sim["time"][-1])
    print(f"Lobovsky et al. 2014 (H = 0.3 m), window t <= {window:.3f} s (T <= {window / scale_t:.2f})")
    curves, rows = {}, []
    for g in c["gauges"]:
        series = [k for k in data if k == g or k.startswith(g + "_")]
        meas = [[v * c["H"] for v in data[k]] for k in series]
        mean = [sum(vs) / len(vs) for vs in zip(*meas)]
        curves[g] = (dt, meas, series)
        in_w = [m for t, m in zip(dt, mean) if t <= window]
        top = max(in_w)
        err = rms_error(sim["time"], sim[g], dt, mean, window)
        spread = 0.0
        if len(meas) == 2:
            d = [(u - v) / 2 for t, u, v in zip(dt, *meas) if t <= window]
            spread = math.sqrt(sum(x * x for x in d) / len(d))
        line = (f"  {g}: level RMS error {err:.4f} m = {100 * err / top:.1f}% of the peak {top:.3f} m "
                f"(target 10%: {verdict(err <= 0.1 * top)}; the two series differ by {100 * spread / top:.1f}%)")
        rows.append({"gauge": g, "rms": err, "peak": top, "rms_frac": err / top})
        if g not in c["in_column"]:
            t_sim = arrival(sim["time"], sim[g], c["threshold"])
            t_exp = [arrival(dt, m, c["threshold"]) for m in meas]
            t_ref = sum(t_exp) / len(t_exp)
            if t_sim is None:
                line += f"\n    arrival ({c['threshold']} m): never in the run; experiment {t_ref:.3f} s: MISSED"
            else:
                rel = (t_sim - t_ref) / t_ref
                line += (f"\n    arrival ({c['threshold']} m): {t_sim:.3f} s, experiment {t_ref:.3f} s (series "
                         + ", ".join(f"{t:.3f}" for t in t_exp) + f"): {100 * rel:+.1f}% "
                         f"(target 5%: {verdict(abs(rel) <= 0.05)})")
                rows[-1].update(arrival=t_sim, arrival_exp=t_ref, arrival_rel=rel)
        print(line)
    return sim, curves, rows, window


def compare_spheric(run_dir, t_end):
    c = SPHERIC
    _, data = read_table(os.path.join(ROOT, "data", "validation", c["data"]))
    _, sim = read_table(os.path.join(run_dir, "probes.csv"))
    dt = data["t_s"]
    window = min(2.0, sim["time"][-1])
    print(f"SPHERIC Test 2 (Kleefsman et al. 2005), window t <= {window:.3f} s")
    rows = []
    for g in c["gauges"]:
        in_w = [v for t, v in zip(dt, data[g]) if t <= window]
        top = max(in_w)
        err = rms_error(sim["time"], sim[g], dt, data[g], window)
        line = (f"  {g}: level RMS error {err:.4f} m = {100 * err / top:.1f}% of the peak {top:.3f} m "
                f"(target 10%: {verdict(err <= 0.1 * top)})")
        rows.append({"gauge": g, "rms": err, "peak": top, "rms_frac": err / top})
        if g not in c["in_column"]:
            t_sim = arrival(sim["time"], sim[g], c["threshold"])
            t_exp = arrival(dt, data[g], c["threshold"])
            if t_sim is None:
                line += f"\n    arrival ({c['threshold']} m): never in the run; experiment {t_exp:.3f} s: MISSED"
            else:
                line += (f"\n    arrival ({c['threshold']} m): {t_sim:.3f} s, experiment {t_exp:.3f} s: "
                         f"{t_sim - t_exp:+.3f} s (target 0.02 s: {verdict(abs(t_sim - t_exp) <= 0.02)})")
                rows[-1].update(arrival=t_sim, arrival_exp=t_exp)
        print(line)
    impact = min(1.0, sim["time"][-1])
    for k in range(1, 9):
        name = f"P{k}"
        ts, ps = peak(sim["time"], sim[name], impact)
        te, pe = peak(dt, data[name], impact)
        if math.isnan(ts):
            print(f"  {name}: no fluid at the sensor up to t = {impact:g} s; experiment peak {pe:.0f} Pa at {te:.3f} s")
            continue
        line = f"  {name}: peak {ps:.0f} Pa at {ts:.3f} s, experiment {pe:.0f} Pa at {te:.3f} s (t <= {impact:g} s)"
        if k == 1:
            line += (f": time {ts - te:+.3f} s (target 0.02 s: {verdict(abs(ts - te) <= 0.02)}), pressure "
                     f"{100 * (ps - pe) / pe:+.1f}% (target 25%: {verdict(abs(ps - pe) <= 0.25 * pe)})")
            rows.append({"gauge": name, "peak_time": ts, "peak_time_exp": te, "peak": ps, "peak_exp": pe})
        print(line)
    if sim["time"][-1] >= SW_WINDOW[1]:
        shallow_water_check(run_dir, sim, data)
    if sim["time"][-1] >= 0.5:
        js, je = impulse(sim["time"], sim["P1"]), impulse(dt, data["P1"])
        print(f"  P1: impulse over 0.38-0.50 s (the first impact's time integral) {js:.0f} Pa s, experiment "
              f"{je:.0f} Pa s: {100 * (js - je) / je:+.1f}%")
    if sim["time"][-1] >= 1.0:
        def mean(ts, ps):
            v = [p for t, p in zip(ts, ps) if 0.45 <= t <= 1.0 and not math.isnan(p)]
            return sum(v) / len(v)
        ms, me = mean(sim["time"], sim["P1"]), mean(dt, data["P1"])
        print(f"  P1: mean over 0.45-1 s (the load after the impact) {ms:.0f} Pa, experiment {me:.0f} Pa: "
              f"{100 * (ms - me) / me:+.1f}%")
    return sim, data, rows, window


SW_WINDOW = (0.3, 1.0)  # [s]: the surge at x = 1.488 m before the box's reflection reaches it (about 1.0 s)


def below_shallow_water(ts, levels, height, dam, length, x):
    """(mean of level / reference - 1 over SW_WINDOW, the reference's (times, depths)): a gauge at x against
    the shallow-water dam break of a column of depth `height` over [dam, length] (scripts/shallow_water.py)."""
    if HERE not in sys.path:
        sys.path.insert(0, HERE)
    import shallow_water
    sw_t, depth, _ = shallow_water.dam_break(height, dam, length, [x], SW_WINDOW[1] + 0.05, cells=1500)
    rel = [interp(ts, levels, t) / interp(sw_t, depth[x], t) - 1 for t in ts if SW_WINDOW[0] <= t <= SW_WINDOW[1]]
    return (sum(rel) / len(rel) if rel else math.nan), (sw_t, depth[x])


def shallow_water_check(run_dir, sim, data):
    """x = 1.488 m against the shallow-water dam break of each side's own column: the run's column from its
    run.json and the first reading of its column gauge, the experiment's from the data's. Stores the
    reference series as sim["sw_level_x1488"] and data["sw_level_x1488"] for the figure."""
    g, x = "level_x1488", SPHERIC["gauges"]["level_x1488"]
    path = os.path.join(run_dir, "run.json")
    if not os.path.exists(path):
        print(f"  {g}: no shallow-water comparison ({path} not found: it gives the run's column)")
        return
    with open(path) as f:
        scene = json.load(f)["scene"]
    sides = {"run": (sim, "time", scene["fluids"][0]["min"][0], scene["boundary"]["walls"]["max"][0]),
             "experiment": (data, "t_s", 1.992, 3.22)}
    parts = []
    for side, (cols, tkey, dam, length) in sides.items():
        height = cols["level_x2638"][0]
        rel, cols["sw_" + g] = below_shallow_water(cols[tkey], cols[g], height, dam, length, x)
        parts.append(f"{side} {100 * rel:+.1f}% (column {height:.3f} m, dam at x = {dam:g} m)")
    print(f"  {g} against the shallow-water dam break of the same column over {SW_WINDOW[0]:g}-{SW_WINDOW[1]:g} s "
          f"(mean level / reference - 1): " + "; ".join(parts))


def spheric_2d_edits(s):
    """The --set edits that turn lobovsky-2014 into SPHERIC Test 2's column in 2D at spacing s: the column
    (1.228 m on the lattice x 0.55 m) against the wall at x = 0, the 3.22 m tank with a roof at 1 m, the
    sound speed of its height, and the gauges mirrored: x = 1.488 m (0.504 m downstream of the column)
    and x = 2.638 m (in the column, 0.582 m from its wall)."""
    col = lround(1.228 / s) * s
    probes = [{"name": "level_x1488", "kind": "layer", "at": [col + 0.504, 0]},
              {"name": "level_x2638", "kind": "layer", "at": [0.582, 0]}]
    return [f"/fluids/0/max=[{col!r}, 0.55]", "/boundary/walls/max=[3.22, 1.0]", "/boundary/walls/open_top=false",
            "/domain/max=[3.72, 3.0]", f"/solver/eos/stiffness={1000 * 100 * 2 * G * 0.55!r}",
            "/probes=" + json.dumps(probes)]


def compare_spheric_2d(run_dir):
    """The 2D column's surge at x = 1.488 m against the shallow-water reference and the experiment, t <= 1 s
    (before the box's reflection reaches that gauge in 3D)."""
    _, data = read_table(os.path.join(ROOT, "data", "validation", SPHERIC["data"]))
    _, sim = read_table(os.path.join(run_dir, "probes.csv"))
    path = os.path.join(run_dir, "run.json")
    if not os.path.exists(path):
        sys.exit(f"{path}: not found (it gives the run's column; run without --no-run first)")
    if sim["time"][-1] < SW_WINDOW[0]:
        sys.exit(f"{os.path.join(run_dir, 'probes.csv')}: ends at t = {sim['time'][-1]:g} s, before the "
                 f"comparison's window {SW_WINDOW[0]:g}-{SW_WINDOW[1]:g} s")
    with open(path) as f:
        col = json.load(f)["scene"]["fluids"][0]["max"][0]
    g = "level_x1488"
    # Mirrored into shallow_water's frame: the column over [3.22 - col, 3.22], the gauge 0.504 m below it.
    rel, sim["sw_" + g] = below_shallow_water(sim["time"], sim[g], sim["level_x2638"][0], 3.22 - col, 3.22,
                                              3.22 - col - 0.504)
    rel_e, data["sw_" + g] = below_shallow_water(data["t_s"], data[g], data["level_x2638"][0], 1.992, 3.22, 1.488)
    end = min(SW_WINDOW[1], sim["time"][-1])
    top = max(v for t, v in zip(data["t_s"], data[g]) if t <= end)
    err = rms_error(sim["time"], sim[g], data["t_s"], data[g], end)
    print(f"SPHERIC Test 2's column in 2D, x = 1.488 m, t <= {end:g} s:\n"
          f"  level RMS error against the experiment {err:.4f} m = {100 * err / top:.1f}% of its peak {top:.3f} m\n"
          f"  mean level / shallow-water reference - 1 over {SW_WINDOW[0]:g}-{SW_WINDOW[1]:g} s: run "
          f"{100 * rel:+.1f}%, experiment {100 * rel_e:+.1f}%")
    return sim, data


def compare_martin_moyce(run_dir, table):
    m = MM[table]
    _, sim = read_table(os.path.join(run_dir, "probes.csv"))
    worst = 0.0
    print(f"Martin & Moyce 1952, table [{table}] (column 1 m x {m['height']:g} m, tank {m['tank']:g} m), "
          "residual height at the back wall H = h / column height")
    pts = []
    for tau, h_ref in martin_moyce(f"[{table}]"):
        t = tau / math.sqrt(G)
        if tau <= 0 or tau > m["tau_max"] or t > sim["time"][-1]:
            continue
        h = interp(sim["time"], sim["wall"], t) / m["height"]
        worst = max(worst, abs(h - h_ref))
        pts.append((tau, h_ref, h))
        print(f"  tau = {tau:4.2f} (t = {t:.3f} s): Martin & Moyce {h_ref:.2f}, run {h:.3f} ({h - h_ref:+.3f})")
    print(f"  worst {worst:.3f} (target 0.05: {verdict(worst <= 0.05)})")
    return sim, pts


def figure(path, case, sim, ref, window, title, other=None):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        sys.exit("validate.py: needs matplotlib (apt-get install python3-matplotlib)")
    if case in ("A", "B"):
        fig, ax = plt.subplots(1, 1, figsize=(6, 3.6))
        scale = math.sqrt(G)  # tau = t sqrt(g / a), a = 1 m
        ax.plot([t * scale for t in sim["time"]], [v / MM[case]["height"] for v in sim["wall"]], "C0-",
                label="cellsph, level 2 spacings from the wall")
        ax.plot([p[0] for p in ref], [p[1] for p in ref], "ko", ms=4, label="Martin & Moyce 1952")
        ax.set_xlabel("tau = t sqrt(g / a)")
        ax.set_ylabel("residual height / column height")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    elif case is SPHERIC_2D:
        fig, ax = plt.subplots(1, 1, figsize=(6, 3.6))
        g = "level_x1488"
        m = [i for i, t in enumerate(ref["t_s"]) if t <= sim["time"][-1]]
        ax.plot([ref["t_s"][i] for i in m], [ref[g][i] for i in m], "k-", lw=0.6, label="experiment")
        ax.plot(sim["time"], sim[g], "C0-", lw=1.2, label="cellsph, 2D")
        ax.plot(*sim["sw_" + g], "C0:", lw=1.0, label="shallow water, the run's column")
        ax.plot(*ref["sw_" + g], "k:", lw=1.0, label="shallow water, the experiment's column")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("level at x = 1.488 m [m]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    elif case in (LOBOVSKY, LOBOVSKY_GATE):
        fig, axes = plt.subplots(2, 2, figsize=(9, 5.5), sharex=True)
        for ax, g in zip(axes.flat, case["gauges"]):
            dt, meas, series = ref[g]
            for m, s, style in zip(meas, series, ("k.", "kx")):
                ax.plot([t for t in dt if t <= window * 1.3], m[:sum(t <= window * 1.3 for t in dt)], style, ms=2.5,
                        label=f"experiment {s}")
            ax.plot(sim["time"], sim[g], "C0-", lw=1.4, label=f"cellsph ({case['scene']})")
            if other:
                ax.plot(other[1]["time"], other[1][g], "C1--", lw=1.0, label=other[0])
            ax.set_title(f"level at x = {case['gauges'][g]} m", fontsize=9)
            ax.set_ylabel("level [m]")
            ax.grid(alpha=0.3)
        axes[0, 0].legend(fontsize=7)
        for ax in axes[1]:
            ax.set_xlabel("time since the gate started [s]")
    else:
        fig, axes = plt.subplots(4, 2, figsize=(10, 9), sharex=True)
        names = list(case["gauges"]) + ["P1", "P3", "P5", "P7"]
        for k, (ax, g) in enumerate(zip(axes.T.flat, names)):
            m = [i for i, t in enumerate(ref["t_s"]) if t <= max(window, sim["time"][-1]) + 0.1]
            ax.plot([ref["t_s"][i] for i in m], [ref[g][i] for i in m], "k-", lw=0.6, label="experiment")
            ax.plot(sim["time"], sim[g], "C0-", lw=1.2, label="cellsph")
            if "sw_" + g in sim:
                ax.plot(*sim["sw_" + g], "C0:", lw=1.0, label="shallow water, the run's column")
                ax.plot(*ref["sw_" + g], "k:", lw=1.0, label="shallow water, the experiment's column")
            ax.set_title(f"level at x = {case['gauges'][g]} m" if k < 4 else f"pressure {g}", fontsize=9)
            ax.set_ylabel("level [m]" if k < 4 else "p [Pa]")
            ax.grid(alpha=0.3)
        axes[0, 0].legend(fontsize=7)
        for ax in axes[-1]:
            ax.set_xlabel("time [s]")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    print(f"validate.py: wrote {path}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case", choices=["lobovsky", "lobovsky-gate", "spheric", "spheric-2d", "martin-moyce-a",
                                     "martin-moyce-b"])
    ap.add_argument("--walls", default="adami", choices=["adami", "akinci", "dynamic"])
    ap.add_argument("--set", action="append", default=[], help="a further scene edit, as cellsph run's --set")
    ap.add_argument("--spacing", type=float)
    ap.add_argument("--until", type=float)
    ap.add_argument("--build", default=os.path.join(ROOT, "build", "release"))
    ap.add_argument("--out")
    ap.add_argument("--no-run", action="store_true")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--figure")
    ap.add_argument("--compare", metavar="RUN_DIR", help="Lobovsky: also draw this run's levels (dashed)")
    ap.add_argument("--compare-label", default="other run", help="the legend of --compare's run")
    a = ap.parse_args()
    case = {"lobovsky": LOBOVSKY, "lobovsky-gate": LOBOVSKY_GATE, "spheric": SPHERIC, "spheric-2d": SPHERIC_2D,
            "martin-moyce-a": "A",
            "martin-moyce-b": "B"}[a.case]
    if a.spacing is None:
        a.spacing = {"lobovsky": 0.005, "lobovsky-gate": 0.005, "spheric": 0.02, "spheric-2d": 0.005}.get(a.case, 0.05)
    if not a.spacing > 0:
        sys.exit(f"--spacing: must be > 0, got {a.spacing}")
    if a.until is None:
        a.until = {"lobovsky": 6 * math.sqrt(LOBOVSKY["H"] / G), "lobovsky-gate": 6 * math.sqrt(LOBOVSKY["H"] / G),
                   "spheric": 2.0, "spheric-2d": SW_WINDOW[1],
                   "martin-moyce-a": 2.5 / math.sqrt(G), "martin-moyce-b": 6.35 / math.sqrt(G)}[a.case]
    a.out = a.out or f"validate-{a.case}-{a.spacing:g}"
    if a.compare and case not in (LOBOVSKY, LOBOVSKY_GATE):
        sys.exit("--compare: only for the lobovsky cases")
    if a.compare and not os.path.exists(os.path.join(a.compare, "probes.csv")):
        sys.exit(f"--compare: {os.path.join(a.compare, 'probes.csv')}: not found")
    if not a.no_run:
        run_scene(a, case)
    if not os.path.exists(os.path.join(a.out, "probes.csv")):
        sys.exit(f"{os.path.join(a.out, 'probes.csv')}: not found (run without --no-run first)")
    if case in ("A", "B"):
        sim, ref = compare_martin_moyce(a.out, case)
        window = None
        title = (f"dam-break-2d set-up, {a.walls} walls, spacing {a.spacing:g} m, against Martin & Moyce "
                 f"1952 [{case}]")
    elif case in (LOBOVSKY, LOBOVSKY_GATE):
        sim, ref, _, window = compare_lobovsky(a.out, a.until)
        title = (f"{case['scene']}, 2D WCSPH, spacing {a.spacing:g} m (H / {0.3 / a.spacing:.0f}), "
                 "against Lobovsky et al. 2014 (two series)")
    elif case is SPHERIC_2D:
        sim, ref = compare_spheric_2d(a.out)
        window = None
        title = f"SPHERIC Test 2's column in 2D (lobovsky-2014 edited), spacing {a.spacing:g} m"
    else:
        sim, ref, _, window = compare_spheric(a.out, a.until)
        title = f"spheric-test2, 3D WCSPH, spacing {a.spacing:g} m, against Kleefsman et al. 2005"
    other = None
    if a.compare:
        other = (a.compare_label, read_table(os.path.join(a.compare, "probes.csv"))[1])
    figure(a.figure or os.path.join(a.out, "validation.png"), case, sim, ref, window, title, other)
    return 0


if __name__ == "__main__":
    sys.exit(main())
