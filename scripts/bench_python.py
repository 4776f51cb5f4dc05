#!/usr/bin/python3
"""Neighbour search from Python: cellsph.neighbors against SciPy's cKDTree and the `cellsph neighbors`
program, on one random point set (issue 16's performance check; figures in docs/python.md).

    PYTHONPATH=build/release/python /usr/bin/python3 scripts/bench_python.py            # 10^6 points
    PYTHONPATH=build/release/python /usr/bin/python3 scripts/bench_python.py --n 20000  # a quick look

Points: n uniform random points in the unit cube (3D, float64), mean spacing s = n^(-1/3), radius r = 2 s
(about 33 neighbours each). Every time is NumPy points in -> CSR arrays out, wall clock:
  cellsph      cellsph.neighbors(points, radius=r, threads=T): validation, search, arrays
  cli          `cellsph neighbors --threads T --stats`: its build_ms + query_ms (the search alone, CSV
               reading and writing excluded), same points (written with 17 digits: the same doubles)
  scipy-ball   cKDTree(points) + query_ball_point(points, r, workers=T) + lists -> CSR (self kept)
  scipy-sdm    cKDTree(points) + sparse_distance_matrix(tree, r, output_type="coo_matrix") -> tocsr()
  scipy-pairs  cKDTree(points) + query_pairs(r, output_type="ndarray") -> symmetric CSR (sorted rows)
cellsph and cli: the fastest of --repeat runs, taken in turns; SciPy paths: the fastest of --scipy-repeat runs (default
1: they take seconds to minutes). The fastest run is the one least disturbed by other work on the machine;
the load average is printed before and after. "binding overhead": for the same calls on a
cellsph.NeighborSearch, wall time minus the library's own build_ms + query_ms (argument checks, the
uniform support array, handing the vectors to NumPy).
"""
import argparse
import itertools
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def timed(f):
    t0 = time.perf_counter()
    r = f()
    return time.perf_counter() - t0, r


def scipy_ball(points, r, threads):
    from scipy.spatial import cKDTree

    tree = cKDTree(points)
    lists = tree.query_ball_point(points, r, workers=threads, return_sorted=True)
    counts = np.fromiter(map(len, lists), dtype=np.int64, count=len(lists))
    offsets = np.zeros(len(lists) + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    indices = np.fromiter(itertools.chain.from_iterable(lists), dtype=np.int64, count=int(offsets[-1]))
    return offsets, indices


def scipy_sdm(points, r, threads):
    from scipy.spatial import cKDTree

    tree = cKDTree(points)
    m = tree.sparse_distance_matrix(tree, r, output_type="coo_matrix").tocsr()
    return m.indptr, m.indices


def scipy_pairs(points, r, threads):
    from scipy.spatial import cKDTree

    pairs = cKDTree(points).query_pairs(r, output_type="ndarray")
    i = np.concatenate([pairs[:, 0], pairs[:, 1]])
    j = np.concatenate([pairs[:, 1], pairs[:, 0]])
    order = np.lexsort((j, i))
    counts = np.bincount(i, minlength=len(points))
    offsets = np.zeros(len(points) + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    return offsets, j[order]


def cli_search_seconds(binary, csv_path, out_dir, r, threads):
    out = subprocess.run([binary, "neighbors", "--input", csv_path, "--radius", repr(r), "--threads", str(threads),
                          "--stats", "--counts", "--output", os.path.join(out_dir, "counts.csv")],
                         check=True, capture_output=True, text=True)
    m = re.search(r"build_ms=([\d.]+) query_ms=([\d.]+) pairs=(\d+)", out.stderr)
    return (float(m.group(1)) + float(m.group(2))) / 1000, int(m.group(3))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--scipy-repeat", type=int, default=1)
    ap.add_argument("--build", default=os.path.join(HERE, "..", "build", "release"))
    ap.add_argument("--skip", default="", help="comma list of SciPy paths to skip: ball,sdm,pairs")
    a = ap.parse_args()
    sys.path.insert(0, os.path.join(a.build, "python"))
    import cellsph

    rng = np.random.default_rng(2026)
    points = rng.random((a.n, 3))
    spacing = a.n ** (-1 / 3)
    r = 2 * spacing
    print(f"# {a.n} points, 3D float64, uniform in the unit cube; r = 2 spacings = {r:.6g}; {a.threads} threads")
    print(f"# load before: {os.getloadavg()}")

    # cellsph and the CLI alternate, so that both see the same share of a busy machine.
    t_cellsph = t_cli = float("inf")
    with tempfile.TemporaryDirectory() as tmp:
        csv_path = os.path.join(tmp, "points.csv")
        np.savetxt(csv_path, points, fmt="%.17g", delimiter=",", header="x,y,z", comments="")
        for _ in range(a.repeat):
            t, (offsets, indices) = timed(lambda: cellsph.neighbors(points, radius=r, threads=a.threads))
            t_cellsph, pairs = min(t_cellsph, t), len(indices)
            del offsets, indices
            t, cli_pairs = cli_search_seconds(os.path.join(a.build, "cellsph"), csv_path, tmp, r, a.threads)
            t_cli = min(t_cli, t)
            assert cli_pairs == pairs, (cli_pairs, pairs)
    overhead = []
    for _ in range(a.repeat):
        ns = cellsph.NeighborSearch(threads=a.threads)
        t, result = timed(lambda: (ns.build(points, radius=r), ns.find_all()))
        overhead.append(t - (ns.stats["build_ms"] + ns.stats["query_ms"]) / 1000)
        del result
    print(f"cellsph      {t_cellsph:9.3f} s   {pairs} pairs ({pairs / a.n:.1f} per point); "
          f"binding overhead {1000 * min(overhead):.1f} to {1000 * max(overhead):.1f} ms")
    print(f"cli          {t_cli:9.3f} s   (build_ms + query_ms of --stats)")

    results = {}
    skip = set(filter(None, a.skip.split(",")))
    for name, f in (("ball", scipy_ball), ("sdm", scipy_sdm), ("pairs", scipy_pairs)):
        if name in skip:
            continue
        best = float("inf")
        for _ in range(a.scipy_repeat):
            t, (o, i) = timed(lambda: f(points, r, a.threads))
            extra = len(i) - pairs  # query_ball_point and sparse_distance_matrix list each point as its own
            assert extra in (0, a.n), (name, len(i), pairs)
            best = min(best, t)
            del o, i
        results[name] = best
        print(f"scipy-{name:<6} {best:9.3f} s   {pairs + extra} entries")

    print(f"# load after: {os.getloadavg()}")
    print(f"cellsph / cli search time: {t_cellsph / t_cli:.3f} (target <= 1.15)")
    if results:
        best = min(results, key=results.get)
        print(f"fastest SciPy path: scipy-{best}; SciPy / cellsph: {results[best] / t_cellsph:.1f}x (target >= 10)")


if __name__ == "__main__":
    main()
