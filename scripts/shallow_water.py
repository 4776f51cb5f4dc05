#!/usr/bin/python3
"""The dam break in the shallow-water equations: an independent reference for the depth of a surge.

Usage: scripts/shallow_water.py --height H --dam X0 --length L --at X [--at X ...] [--until T] [--every DT]
                                [--cells N]

A column of depth H fills x in [X0, L] of a flat tank [0, L] with walls at both ends and is released at
t = 0 (the dry bed lies at x < X0). The 1D Saint-Venant equations (depth h, discharge q = h u, no
friction, hydrostatic pressure) are solved with a first-order finite-volume scheme on N cells: HLL fluxes
with the dry-bed wave speeds (u - c, u + 2c next to a dry cell) and mirrored ghost cells at the walls.
Printed: the depth at every X against time, and Ritter's (1892) analytic solution of the infinite column,
h = (2 c0 - xi / t)^2 / (9 g) with c0 = sqrt(g H) and xi = X0 - X the distance downstream of the dam,
which holds until the wave reflected at the back wall arrives.

No SPH here and nothing shared with cellsph: scripts/validate.py uses it to say what depth the measured
drainage of a column gives at a gauge (docs/physics.md, SPHERIC Test 2, x = 1.488 m).
"""
import argparse
import math
import sys

import numpy as np

G = 9.81


def ritter(H, xi, t):
    """Depth of Ritter's dam break at distance xi downstream of the dam (xi < 0: inside the column)."""
    if t <= 0:
        return H if xi < 0 else 0.0
    c0 = math.sqrt(G * H)
    s = xi / t
    if s <= -c0:
        return H
    if s >= 2 * c0:
        return 0.0
    return (2 * c0 - s) ** 2 / (9 * G)


def dam_break(H, dam, length, gauges, t_end, cells=3000, every=0.005):
    """(times, {x: depths}, volume at the start and at the end) of the column [dam, length] of depth H."""
    if not (H > 0 and 0 < dam < length and t_end > 0 and cells >= 10):
        raise ValueError(f"shallow_water: needs H > 0, 0 < dam < length, t_end > 0, cells >= 10; got "
                         f"H={H}, dam={dam}, length={length}, t_end={t_end}, cells={cells}")
    dx = length / cells
    x = (np.arange(cells) + 0.5) * dx
    h = np.where(x >= dam, H, 0.0)
    q = np.zeros(cells)
    dry = 1e-9
    times, out = [0.0], {g: [float(np.interp(g, x, h))] for g in gauges}
    v0 = float(h.sum() * dx)
    t, next_sample = 0.0, every
    while t < t_end - 1e-12:
        # Mirrored ghost cells: the walls at 0 and L reflect the discharge.
        hl = np.concatenate(([h[0]], h))
        ql = np.concatenate(([-q[0]], q))
        hr = np.concatenate((h, [h[-1]]))
        qr = np.concatenate((q, [-q[-1]]))
        ul = np.where(hl > dry, ql / np.maximum(hl, dry), 0.0)
        ur = np.where(hr > dry, qr / np.maximum(hr, dry), 0.0)
        cl, cr = np.sqrt(G * hl), np.sqrt(G * hr)
        sl = np.where(hl > dry, np.minimum(ul - cl, ur - cr), ur - 2 * cr)
        sl = np.where(hr > dry, sl, ul - cl)
        sr = np.where(hr > dry, np.maximum(ul + cl, ur + cr), ul + 2 * cl)
        sr = np.where(hl > dry, sr, ur + cr)
        fl1, fl2 = ql, ql * ul + 0.5 * G * hl * hl
        fr1, fr2 = qr, qr * ur + 0.5 * G * hr * hr
        span = np.where(sr - sl > dry, sr - sl, 1.0)
        f1 = np.where(sl >= 0, fl1, np.where(sr <= 0, fr1, (sr * fl1 - sl * fr1 + sl * sr * (hr - hl)) / span))
        f2 = np.where(sl >= 0, fl2, np.where(sr <= 0, fr2, (sr * fl2 - sl * fr2 + sl * sr * (qr - ql)) / span))
        speed = float(np.max(np.maximum(np.abs(sl), np.abs(sr))))
        dt = min(0.45 * dx / speed, t_end - t, next_sample - t)
        h = h - dt / dx * (f1[1:] - f1[:-1])
        q = q - dt / dx * (f2[1:] - f2[:-1])
        q = np.where(h > dry, q, 0.0)
        h = np.maximum(h, 0.0)
        t += dt
        if t >= next_sample - 1e-12:
            times.append(t)
            for g in gauges:
                out[g].append(float(np.interp(g, x, h)))
            next_sample += every
    return times, out, (v0, float(h.sum() * dx))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--height", type=float, required=True)
    ap.add_argument("--dam", type=float, required=True)
    ap.add_argument("--length", type=float, required=True)
    ap.add_argument("--at", type=float, action="append", required=True)
    ap.add_argument("--until", type=float, default=1.0)
    ap.add_argument("--every", type=float, default=0.05)
    ap.add_argument("--cells", type=int, default=3000)
    a = ap.parse_args()
    try:
        times, out, _ = dam_break(a.height, a.dam, a.length, a.at, a.until, a.cells, a.every)
    except ValueError as e:
        sys.exit(str(e))
    print("t_s\t" + "\t".join(f"sw_x{g:g}\tritter_x{g:g}" for g in a.at))
    for k, t in enumerate(times):
        print(f"{t:.3f}\t" + "\t".join(f"{out[g][k]:.4f}\t{ritter(a.height, a.dam - g, t):.4f}" for g in a.at))
    return 0


if __name__ == "__main__":
    sys.exit(main())
