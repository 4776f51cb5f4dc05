"""scripts/shallow_water.py: the 1D dam break against Ritter's analytic solution, its volume, its input checks,
and scripts/validate.py's use of it on a made-up SPHERIC run."""
import importlib.util
import json
import math
import os
import subprocess
import sys

import pytest


def load(repo_root, name):
    spec = importlib.util.spec_from_file_location(name, os.path.join(repo_root, "scripts", name + ".py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_ritter_has_its_textbook_values(repo_root):
    sw = load(repo_root, "shallow_water")
    H = 0.55
    c0 = math.sqrt(9.81 * H)
    # At the dam the depth is 4H/9 at every t > 0; the front runs at 2 c0, the rarefaction's head at -c0.
    for t in (0.1, 0.5, 1.0):
        assert math.isclose(sw.ritter(H, 0.0, t), 4 * H / 9)
        assert sw.ritter(H, 2 * c0 * t * 1.001, t) == 0.0
        assert sw.ritter(H, -c0 * t * 1.001, t) == H


def test_dam_break_follows_ritter_until_the_reflection_and_keeps_its_volume(repo_root):
    sw = load(repo_root, "shallow_water")
    H, dam, length = 0.55, 1.992, 3.22
    gauges = [1.488, 0.992]
    ts, depth, (v0, v1) = sw.dam_break(H, dam, length, gauges, 1.0, cells=1500, every=0.05)
    assert math.isclose(v0, H * (length - dam), rel_tol=2e-3)
    assert abs(v1 - v0) <= 1e-9 * v0
    # The wave reflected at the back wall reaches x = 1.488 m after about 1.1 s: before it, Ritter within
    # 2 mm (0.4% of H); the first-order scheme smears the front itself, so the check starts at 0.3 s.
    checked = 0
    for k, t in enumerate(ts):
        if 0.3 <= t <= 1.0:
            for g in gauges:
                assert abs(depth[g][k] - sw.ritter(H, dam - g, t)) < 0.002, (t, g)
                checked += 1
    assert checked >= 28


def test_bad_input_is_refused_naming_the_values(repo_root):
    sw = load(repo_root, "shallow_water")
    with pytest.raises(ValueError, match="dam=4.0"):
        sw.dam_break(0.55, 4.0, 3.22, [1.0], 1.0)
    r = subprocess.run([sys.executable, os.path.join(repo_root, "scripts", "shallow_water.py"), "--height", "-1",
                        "--dam", "1", "--length", "2", "--at", "0.5"], capture_output=True, text=True)
    assert r.returncode == 1 and "H=-1.0" in r.stderr and "Traceback" not in r.stderr


def test_validate_reports_a_made_up_spheric_run_against_the_shallow_water_column(repo_root, tmp_path):
    # A run whose level at x = 1.488 m is 0.9 times the shallow-water depth of its own column (0.55 m,
    # dam at 1.992 m in a 3.22 m tank) and dry elsewhere: validate.py must report it 10% below.
    sw = load(repo_root, "shallow_water")
    ts, depth, _ = sw.dam_break(0.55, 1.992, 3.22, [1.488], 1.05, cells=1500, every=0.005)
    head = ["time", "level_x1488", "level_x0992", "level_x0496", "level_x2638"] + [f"P{k}" for k in range(1, 9)]
    rows = [",".join(head)]
    for t, h in zip(ts, depth[1.488]):
        rows.append(",".join([f"{t!r}", f"{0.9 * h!r}", "0", "0", "0.55"] + ["0"] * 8))
    (tmp_path / "probes.csv").write_text("\n".join(rows) + "\n")
    scene = {"fluids": [{"min": [1.992, 0, 0], "max": [3.22, 1, 0.55]}], "boundary": {"walls": {"max": [3.22, 1, 1]}}}
    (tmp_path / "run.json").write_text(json.dumps({"scene": scene}))
    r = subprocess.run([sys.executable, os.path.join(repo_root, "scripts", "validate.py"), "spheric", "--no-run",
                        "--out", str(tmp_path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    line = next(ln for ln in r.stdout.splitlines() if "shallow-water" in ln)
    assert "run -10.0%" in line, line
    assert (tmp_path / "validation.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_spheric_2d_mirrors_the_column_and_reports_a_made_up_run(repo_root, tmp_path):
    v = load(repo_root, "validate")
    # At 0.005 m the column is round(1.228 / 0.005) = 246 spacings, 1.23 m, against the wall at x = 0; the
    # gauge is 0.504 m downstream of it, the column gauge 0.582 m from the wall (3.22 - 2.638).
    edits = {e.split("=", 1)[0]: json.loads(e.split("=", 1)[1]) for e in v.spheric_2d_edits(0.005)}
    assert math.isclose(edits["/fluids/0/max"][0], 1.23) and edits["/fluids/0/max"][1] == 0.55
    probes = {p["name"]: p["at"][0] for p in edits["/probes"]}
    assert math.isclose(probes["level_x1488"], 1.734) and math.isclose(probes["level_x2638"], 0.582)
    assert math.isclose(edits["/solver/eos/stiffness"], 1000 * (10 * math.sqrt(2 * 9.81 * 0.55)) ** 2)
    # A run at 0.8 times the shallow-water depth of its own (mirrored) column: reported 20% below.
    sw = load(repo_root, "shallow_water")
    ts, depth, _ = sw.dam_break(0.55, 3.22 - 1.23, 3.22, [3.22 - 1.734], 1.0, cells=1500, every=0.005)
    rows = ["time,level_x1488,level_x2638"] + [f"{t!r},{0.8 * h!r},0.55" for t, h in zip(ts, depth[3.22 - 1.734])]
    (tmp_path / "probes.csv").write_text("\n".join(rows) + "\n")
    (tmp_path / "run.json").write_text(json.dumps({"scene": {"fluids": [{"min": [0, 0], "max": [1.23, 0.55]}]}}))
    r = subprocess.run([sys.executable, os.path.join(repo_root, "scripts", "validate.py"), "spheric-2d", "--no-run",
                        "--out", str(tmp_path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "run -20.0%, experiment " in r.stdout, r.stdout


def test_the_2d_surge_lies_just_below_the_shallow_water_depth(cellsph_binary, repo_root, tmp_path):
    # SPHERIC's column in 2D at 0.02 m (2 400 particles), run by validate.py: its level 0.504 m downstream of
    # the column over 0.3-1 s against the shallow-water dam break of the same column. A real surge is
    # shallower than the shallow-water depth (vertical accelerations at the front, friction at the floor):
    # the resolution series of docs/physics.md converges to 10% below it. The bound: below it, by less than
    # 15%. A model that drains the column too slowly or drags the surge along the floor falls outside.
    build = os.path.dirname(cellsph_binary)
    r = subprocess.run([sys.executable, os.path.join(repo_root, "scripts", "validate.py"), "spheric-2d",
                        "--spacing", "0.02", "--build", build, "--threads", "2", "--out", str(tmp_path / "run")],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    line = next(ln for ln in r.stdout.splitlines() if "shallow-water reference" in ln)
    rel = float(line.split("run ")[1].split("%")[0])
    assert -15.0 < rel < 0.0, line


def test_spheric_2d_refuses_a_run_without_its_scene_or_too_short(repo_root, tmp_path):
    script = os.path.join(repo_root, "scripts", "validate.py")
    (tmp_path / "probes.csv").write_text("time,level_x1488,level_x2638\n0,0,0.55\n0.1,0,0.55\n")
    r = subprocess.run([sys.executable, script, "spheric-2d", "--no-run", "--out", str(tmp_path)],
                       capture_output=True, text=True)
    assert r.returncode == 1 and "run.json: not found" in r.stderr and "Traceback" not in r.stderr, r.stderr
    (tmp_path / "run.json").write_text(json.dumps({"scene": {"fluids": [{"min": [0, 0], "max": [1.23, 0.55]}]}}))
    r = subprocess.run([sys.executable, script, "spheric-2d", "--no-run", "--out", str(tmp_path)],
                       capture_output=True, text=True)
    assert r.returncode == 1 and "ends at t = 0.1 s" in r.stderr and "Traceback" not in r.stderr, r.stderr
