#!/usr/bin/python3
"""Particles clinging to the vertical walls of a 2D tank in one frame of a cellsph run (CSV frames).

For each wall x = X (--walls X1,X2,...): the local free surface is the highest height at which
phi(y) = sum_j V_j W(|(X + 4 s n, y) - x_j|) crosses 1/2 (V_j = m_j / rho_j, the cubic spline of
support --support; n points into the fluid), as the level probes define it (docs/scenes.md), four
spacings out from the wall. A particle clings when it is within 2 spacings of the wall and more than 5
spacings above that surface (issue 14's criterion). Prints, per wall: the surface, the highest particle
within 2 spacings of the wall, and the number clinging.

    scripts/wall_cling.py RUN_DIR --time 0.6 --spacing 0.02 --support 0.04 --walls 0,4
"""
import argparse
import csv
import math
import pathlib
import sys

import numpy as np


def cubic_w(r, h):
    q = r / h
    sigma = 40.0 / (7.0 * math.pi * h * h)
    w = np.where(q <= 0.5, 6 * (q**3 - q**2) + 1, 2 * np.clip(1 - q, 0, None) ** 3)
    return sigma * np.where(q <= 1, w, 0.0)


def frame_at(run, t):
    if not (run / "frames.csv").exists():
        sys.exit(f"{run / 'frames.csv'}: not found (RUN must be the output folder of a cellsph run)")
    with open(run / "frames.csv") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{run / 'frames.csv'}: no frames")
    best = min(rows, key=lambda r: abs(float(r["time"]) - t))
    name = best.get("csv") or next(v for k, v in best.items() if v.endswith(".csv"))
    return float(best["time"]), run / name


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", type=pathlib.Path)
    ap.add_argument("--time", type=float, required=True)
    ap.add_argument("--spacing", type=float, required=True)
    ap.add_argument("--support", type=float, required=True)
    ap.add_argument("--walls", required=True, help="x of the vertical walls, comma separated")
    a = ap.parse_args()
    t, path = frame_at(a.run, a.time)
    with open(path) as f:
        rd = csv.DictReader(f)
        rows = [r for r in rd]
    if not rows:
        sys.exit(f"{path}: no particles")
    keys = rows[0].keys()
    kx = "x" if "x" in keys else "position_x"
    ky = "y" if "y" in keys else "position_y"
    for k in (kx, ky, "mass", "density"):
        if k not in keys:
            sys.exit(f"{path}: no column '{k}' (it has: {', '.join(keys)}); write the frames with "
                     "--format csv and every field")
    fluid = [r for r in rows if int(float(r.get("kind", 0))) == 0]
    x = np.array([float(r[kx]) for r in fluid])
    y = np.array([float(r[ky]) for r in fluid])
    vol = np.array([float(r["mass"]) / float(r["density"]) for r in fluid])
    s = a.spacing
    total = 0
    print(f"{path.name} (t = {t:.4f} s), {len(fluid)} fluid particles")
    for wall in (float(w) for w in a.walls.split(",")):
        inward = 1.0 if x.mean() > wall else -1.0
        xs = wall + inward * 4 * s
        surface = None
        for yy in np.arange(y.max() + a.support, y.min() - a.support, -s / 4):
            phi = float(np.sum(vol * cubic_w(np.hypot(x - xs, y - yy), a.support)))
            if phi >= 0.5:
                surface = yy
                break
        band = np.abs(x - wall) < 2 * s
        top = float(y[band].max()) if band.any() else float("nan")
        level = surface if surface is not None else 0.0
        cling = int(np.sum(band & (y > level + 5 * s)))
        total += cling
        print(f"wall x = {wall:g}: free surface {level:.3f} m, highest particle within 2 spacings {top:.3f} m, "
              f"clinging (> 5 spacings above the surface) {cling}")
    return 0 if total == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
