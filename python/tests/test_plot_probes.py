"""scripts/plot_probes.py: draws a run's probes.csv over a data table, and names what it cannot match."""
import os
import subprocess
import sys


def run(repo_root, *args):
    return subprocess.run([sys.executable, os.path.join(repo_root, "scripts", "plot_probes.py"), *args],
                          capture_output=True, text=True)


def test_plots_probes_over_scaled_data(repo_root, tmp_path):
    (tmp_path / "probes.csv").write_text("time,gauge,p\n0,0.5,\n0.1,0.45,3900\n0.2,0.4,3800\n")
    (tmp_path / "data.tsv").write_text("# a comment\nT\th_a\n0\t1\n1\t0.8\n")
    out = tmp_path / "plot.png"
    r = run(repo_root, str(tmp_path), "--out", str(out), "--data", str(tmp_path / "data.tsv"), "--match",
            "gauge=h_a", "--time-scale", "0.2", "--value-scale", "0.5")
    assert r.returncode == 0, r.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_names_a_probe_or_column_it_cannot_find(repo_root, tmp_path):
    (tmp_path / "probes.csv").write_text("time,gauge\n0,0.5\n")
    (tmp_path / "data.tsv").write_text("T\th_a\n0\t1\n")
    r = run(repo_root, str(tmp_path), "--data", str(tmp_path / "data.tsv"), "--match", "gauge=h_b")
    assert r.returncode != 0 and "no column 'h_b'" in r.stderr
    r = run(repo_root, str(tmp_path), "--data", str(tmp_path / "data.tsv"), "--match", "level=h_a")
    assert r.returncode != 0 and "no probe column 'level'" in r.stderr
    r = run(repo_root, str(tmp_path / "missing"))
    assert r.returncode != 0 and "not found" in r.stderr
