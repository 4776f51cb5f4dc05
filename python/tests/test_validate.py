"""scripts/validate.py: its measures on series with known answers, and a comparison of a made-up run."""
import importlib.util
import json
import math
import os
import subprocess
import sys


def load(repo_root):
    spec = importlib.util.spec_from_file_location("validate", os.path.join(repo_root, "scripts", "validate.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_arrival_rms_and_peak_on_known_series(repo_root):
    v = load(repo_root)
    t = [0.0, 0.1, 0.2, 0.3]
    # A level rising 0, 0, 0.04, 0.08: 0.03 is reached three quarters of the way from 0.1 to 0.2.
    assert math.isclose(v.arrival(t, [0, 0, 0.04, 0.08], 0.03), 0.175)
    assert v.arrival(t, [0, 0.01, 0.02, 0.0], 0.03) is None
    # Run 0.01 above a reference given on a coarser grid: RMS 0.01; samples after t_end are left out.
    ref_t, ref_v = [0.0, 0.3], [0.0, 0.3]
    assert math.isclose(v.rms_error(t, [0.01, 0.11, 0.21, 5.0], ref_t, ref_v, 0.2), 0.01)
    assert v.peak(t, [1, math.nan, 3, 9], 0.25) == (0.2, 3)
    assert v.interp([0, 1, 2], [0, 10, 0], 1.5) == 5
    # The impulse: a triangle 0 -> 2000 -> 0 Pa over 0.4-0.48 s is 80 Pa s; samples outside [0.38, 0.5] and
    # a sample without fluid (0) add nothing.
    ts = [0.30, 0.40, 0.44, 0.48, 0.49, 0.60]
    assert math.isclose(v.impulse(ts, [9e9, 0, 2000, 0, math.nan, 9e9]), 80.0)


def test_spheric_geometry_follows_the_lattice(repo_root):
    v = load(repo_root)
    edits = v.spheric_geometry(0.04)
    # 3.22 / 0.04 = 80.5 rounds to 81 spacings: the tank and the column end at 3.24; the column is
    # round(1.228 / 0.04) = 31 spacings; the box's face is 4 spacings from its corner at 0.6635.
    value = {e.split("=", 1)[0]: json.loads(e.split("=", 1)[1]) for e in edits}
    assert math.isclose(value["/fluids/0/min"][0], 2.0) and math.isclose(value["/fluids/0/max"][0], 3.24)
    assert math.isclose(value["/boundary/walls/max"][0], 3.24)
    p1 = next(p for p in value["/probes"] if p["name"] == "P1")
    assert math.isclose(p1["at"][0], 0.6635 + 0.16 + 0.02) and p1["at"][1:] == [0.471, 0.021]


def test_compares_a_made_up_lobovsky_run(repo_root, tmp_path):
    # A run that is the experiment's first series at x = 0.865 m delayed by 0.01 s and dry elsewhere: the
    # comparison must report that gauge's arrival 0.01 s after the series' and the dry gauges as never
    # arriving.
    v = load(repo_root)
    _, data = v.read_table(os.path.join(repo_root, "data", "validation", "lobovsky2014_water_levels_H300.tsv"))
    scale = math.sqrt(0.3 / 9.81)
    rows = ["time,h_x0300,h_x0865,h_x1114,h_x1363"]
    for k in range(0, 211):
        t = 0.005 * k
        h = v.interp([T * scale for T in data["T"]], [a * 0.3 for a in data["h_x0865_a"]], t - 0.01)
        rows.append(f"{t},0.3,{h},0,0")
    (tmp_path / "probes.csv").write_text("\n".join(rows) + "\n")
    r = subprocess.run([sys.executable, os.path.join(repo_root, "scripts", "validate.py"), "lobovsky",
                        "--no-run", "--out", str(tmp_path), "--spacing", "0.02"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    line = next(ln for ln in r.stdout.splitlines() if "arrival" in ln and "experiment" in ln)
    t_sim = float(line.split("):")[1].split("s,")[0])
    t_exp = float(line.split("(series")[1].split(",")[0])
    assert abs(t_sim - t_exp - 0.01) < 0.002, line
    assert r.stdout.count("never in the run") == 2
    assert (tmp_path / "validation.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_lobovsky_gate_compares_and_draws_a_second_run(repo_root, tmp_path):
    # lobovsky-gate is compared like lobovsky; --compare draws another run's levels beside it and refuses
    # a folder without probes.csv, or a case other than Lobovsky's.
    rows = ["time,h_x0300,h_x0865,h_x1114,h_x1363"] + [f"{0.005 * k},0.3,0,0,0" for k in range(211)]
    for d in ("gate", "instant"):
        (tmp_path / d).mkdir()
        (tmp_path / d / "probes.csv").write_text("\n".join(rows) + "\n")
    script = os.path.join(repo_root, "scripts", "validate.py")
    base = [sys.executable, script, "lobovsky-gate", "--no-run", "--out", str(tmp_path / "gate")]
    r = subprocess.run(base + ["--compare", str(tmp_path / "instant")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert r.stdout.count("never in the run") == 3
    assert (tmp_path / "gate" / "validation.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    r = subprocess.run(base + ["--compare", str(tmp_path / "missing")], capture_output=True, text=True)
    assert r.returncode != 0 and "--compare" in r.stderr and "probes.csv" in r.stderr
    r = subprocess.run([sys.executable, script, "martin-moyce-a", "--no-run", "--out", str(tmp_path / "gate"),
                        "--compare", str(tmp_path / "instant")], capture_output=True, text=True)
    assert r.returncode != 0 and "--compare" in r.stderr


def test_a_run_without_a_needed_column_or_rows_is_refused_by_name(repo_root, tmp_path):
    # A probes.csv from another scene (no gauge h_x1363) or with a header only: exit 1 with one line
    # naming the file and the column, not a Python traceback.
    script = os.path.join(repo_root, "scripts", "validate.py")
    rows = ["time,h_x0300,h_x0865,h_x1114"] + [f"{0.005 * k},0.3,0,0" for k in range(211)]
    (tmp_path / "probes.csv").write_text("\n".join(rows) + "\n")
    r = subprocess.run([sys.executable, script, "lobovsky", "--no-run", "--out", str(tmp_path)],
                       capture_output=True, text=True)
    assert r.returncode == 1, r.stderr
    assert "Traceback" not in r.stderr
    assert "probes.csv: no column 'h_x1363'" in r.stderr, r.stderr
    (tmp_path / "probes.csv").write_text(rows[0] + ",h_x1363\n")
    r = subprocess.run([sys.executable, script, "lobovsky", "--no-run", "--out", str(tmp_path)],
                       capture_output=True, text=True)
    assert r.returncode == 1 and "Traceback" not in r.stderr
    assert "probes.csv: a header and no data rows" in r.stderr, r.stderr
