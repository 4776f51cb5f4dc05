"""scripts/wall_cling.py on made-up frames whose clinging particles are known."""
import os
import subprocess
import sys


def write_run(path, extra):
    """A 2D tank 1 m wide: water 0.3 m deep on a 0.02 m lattice (mass 0.4, density 1000), plus `extra`
    particles (x, y); one frame at t = 0.6 s."""
    path.mkdir()
    rows = ["x,y,vx,vy,density,mass,kind,id"]
    pts = [((i + 0.5) * 0.02, (j + 0.5) * 0.02) for i in range(50) for j in range(15)] + extra
    for k, (x, y) in enumerate(pts):
        rows.append(f"{x},{y},0,0,1000,0.4,0,{k}")
    (path / "frame_00001.csv").write_text("\n".join(rows) + "\n")
    (path / "frames.csv").write_text("frame,time,csv\n1,0.6,frame_00001.csv\n")


def run(repo_root, folder):
    return subprocess.run([sys.executable, os.path.join(repo_root, "scripts", "wall_cling.py"), str(folder),
                           "--time", "0.6", "--spacing", "0.02", "--support", "0.04", "--walls", "0,1"],
                          capture_output=True, text=True)


def test_counts_particles_hanging_on_a_wall(repo_root, tmp_path):
    # Three particles 0.01 m from the wall at x = 0, at 0.5-0.7 m (over 5 spacings above the 0.3 m
    # surface), and one at 0.36 m (3 spacings above it: not clinging); none at x = 1.
    write_run(tmp_path / "cling", [(0.01, 0.5), (0.01, 0.6), (0.01, 0.7), (0.01, 0.36)])
    r = run(repo_root, tmp_path / "cling")
    assert r.returncode == 1, r.stderr
    lines = r.stdout.splitlines()
    assert "wall x = 0:" in lines[1] and lines[1].endswith("clinging (> 5 spacings above the surface) 3"), lines
    assert "free surface 0.3" in lines[1], lines[1]
    assert lines[2].endswith("clinging (> 5 spacings above the surface) 0"), lines
    write_run(tmp_path / "clean", [])
    r = run(repo_root, tmp_path / "clean")
    assert r.returncode == 0, r.stdout + r.stderr


def test_a_frame_without_masses_is_refused_by_name(repo_root, tmp_path):
    write_run(tmp_path / "run", [])
    f = tmp_path / "run" / "frame_00001.csv"
    f.write_text("\n".join(",".join(line.split(",")[:5]) for line in f.read_text().splitlines()) + "\n")
    r = run(repo_root, tmp_path / "run")
    assert r.returncode == 1 and "Traceback" not in r.stderr
    assert "frame_00001.csv: no column 'mass'" in r.stderr, r.stderr
    r = run(repo_root, tmp_path / "nowhere")
    assert r.returncode == 1 and "frames.csv: not found" in r.stderr, r.stderr
