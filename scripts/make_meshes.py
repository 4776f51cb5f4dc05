#!/usr/bin/env python3
"""Writes the example and test meshes of cellsph (made by us, no outside data):
  scenes/meshes/   the meshes the built-in scenes use (text formats: compiled into the program)
  data/meshes/     the meshes of the tests (src/cellsph/geometry/*_test.cpp, scene tests) and of the
                   modelling examples of docs/scenes.md, in every format Assimp reads for us, and broken
                   ones for the error tests.
Run from the repository root: scripts/make_meshes.py (deterministic: the same bytes every time)."""
import math
import os
import struct


def cube(lo=(0.0, 0.0, 0.0), hi=(1.0, 1.0, 1.0)):
    v = [(x, y, z) for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])]
    # vertex index = x + 2 y + 4 z; faces counter-clockwise seen from outside
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    t = []
    for a, b, c, d in quads:
        t += [(a, b, c), (a, c, d)]
    return v, t


def icosphere(level, radius=1.0, center=(0.0, 0.0, 0.0)):
    p = (1 + 5 ** 0.5) / 2
    v = [(-1, p, 0), (1, p, 0), (-1, -p, 0), (1, -p, 0), (0, -1, p), (0, 1, p), (0, -1, -p), (0, 1, -p),
         (p, 0, -1), (p, 0, 1), (-p, 0, -1), (-p, 0, 1)]
    v = [tuple(c / math.sqrt(sum(x * x for x in q)) for c in q) for q in v]
    t = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
         (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
         (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        mid = {}

        def m(a, b):
            k = (min(a, b), max(a, b))
            if k not in mid:
                q = [(v[a][i] + v[b][i]) / 2 for i in range(3)]
                n = math.sqrt(sum(x * x for x in q))
                v.append(tuple(x / n for x in q))
                mid[k] = len(v) - 1
            return mid[k]

        nt = []
        for a, b, c in t:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            nt += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        t = nt
    v = [tuple(center[i] + radius * q[i] for i in range(3)) for q in v]
    return v, t


def cylinder(n, radius, height, base=(0.0, 0.0, 0.0)):
    """Closed cylinder about +z: n segments, both caps fanned from their centres."""
    v = [(base[0], base[1], base[2]), (base[0], base[1], base[2] + height)]
    for k in range(n):
        a = 2 * math.pi * k / n
        v.append((base[0] + radius * math.cos(a), base[1] + radius * math.sin(a), base[2]))
        v.append((base[0] + radius * math.cos(a), base[1] + radius * math.sin(a), base[2] + height))
    t = []
    for k in range(n):
        b0, t0 = 2 + 2 * k, 3 + 2 * k
        b1, t1 = 2 + 2 * ((k + 1) % n), 3 + 2 * ((k + 1) % n)
        t += [(0, b1, b0), (1, t0, t1), (b0, b1, t1), (b0, t1, t0)]
    return v, t


def volume(v, t):
    s = 0.0
    for a, b, c in t:
        A, B, C = v[a], v[b], v[c]
        s += (A[0] * (B[1] * C[2] - B[2] * C[1]) + A[1] * (B[2] * C[0] - B[0] * C[2]) +
              A[2] * (B[0] * C[1] - B[1] * C[0]))
    return s / 6


def normal(A, B, C):
    u = [B[i] - A[i] for i in range(3)]
    w = [C[i] - A[i] for i in range(3)]
    n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
    l = math.sqrt(sum(x * x for x in n)) or 1
    return [x / l for x in n]


def fmt(x):
    return repr(float(x))


def stl_ascii(path, v, t, name="cellsph"):
    with open(path, "w", newline="\n") as f:
        f.write(f"solid {name}\n")
        for a, b, c in t:
            n = normal(v[a], v[b], v[c])
            f.write(f"  facet normal {' '.join(fmt(x) for x in n)}\n    outer loop\n")
            for q in (a, b, c):
                f.write(f"      vertex {' '.join(fmt(x) for x in v[q])}\n")
            f.write("    endloop\n  endfacet\n")
        f.write(f"endsolid {name}\n")


def stl_binary_bytes(v, t):
    out = bytearray(b"binary STL written by cellsph scripts/make_meshes.py".ljust(80, b" "))
    out += struct.pack("<I", len(t))
    for a, b, c in t:
        out += struct.pack("<3f", *normal(v[a], v[b], v[c]))
        for q in (a, b, c):
            out += struct.pack("<3f", *v[q])
        out += struct.pack("<H", 0)
    return bytes(out)


def obj(path, v, t):
    with open(path, "w", newline="\n") as f:
        f.write("# written by cellsph scripts/make_meshes.py\n")
        for q in v:
            f.write(f"v {' '.join(fmt(x) for x in q)}\n")
        for a, b, c in t:
            f.write(f"f {a + 1} {b + 1} {c + 1}\n")


def ply_ascii(path, v, t):
    with open(path, "w", newline="\n") as f:
        f.write(f"ply\nformat ascii 1.0\ncomment written by cellsph scripts/make_meshes.py\n"
                f"element vertex {len(v)}\nproperty float x\nproperty float y\nproperty float z\n"
                f"element face {len(t)}\nproperty list uchar int vertex_indices\nend_header\n")
        for q in v:
            f.write(" ".join(fmt(x) for x in q) + "\n")
        for a, b, c in t:
            f.write(f"3 {a} {b} {c}\n")


def ply_binary(path, v, t):
    head = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(v)}\nproperty float x\n"
            f"property float y\nproperty float z\nelement face {len(t)}\n"
            f"property list uchar int vertex_indices\nend_header\n").encode()
    body = b"".join(struct.pack("<3f", *q) for q in v)
    body += b"".join(struct.pack("<B3i", 3, a, b, c) for a, b, c in t)
    with open(path, "wb") as f:
        f.write(head + body)


def main():
    os.makedirs("scenes/meshes", exist_ok=True)
    os.makedirs("data/meshes", exist_ok=True)
    d = "data/meshes/"
    # The glass of the built-in scene oil-glass: 0.1 m radius, 0.3 m tall, 48 segments, standing on z = 0.
    gv, gt = cylinder(48, 0.1, 0.3)
    obj("scenes/meshes/glass.obj", gv, gt)
    # The pier of the built-in scene dam-break-pier: an icosphere (level 2) of radius 0.1 m.
    pv, pt = icosphere(2, 0.1)
    obj("scenes/meshes/boulder.obj", pv, pt)

    cv, ct = cube()
    stl_ascii(d + "cube-ascii.stl", cv, ct, "cube")
    with open(d + "cube-binary.stl", "wb") as f:
        f.write(stl_binary_bytes(cv, ct))
    obj(d + "cube.obj", cv, ct)
    ply_ascii(d + "cube-ascii.ply", cv, ct)
    ply_binary(d + "cube-binary.ply", cv, ct)
    sv, st = icosphere(4)  # unit sphere, 5120 triangles
    with open(d + "sphere.stl", "wb") as f:
        f.write(stl_binary_bytes(sv, st))
    yv, yt = cylinder(64, 0.5, 1.0)
    stl_ascii(d + "cylinder.stl", yv, yt, "cylinder")
    # Broken ones.
    obj(d + "open-cube.obj", cv, ct[:-1])  # the last triangle missing: an open mesh
    flipped = list(ct)
    flipped[3] = (flipped[3][0], flipped[3][2], flipped[3][1])
    obj(d + "flipped-triangle-cube.obj", cv, flipped)
    flat = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
    obj(d + "zero-volume.obj", flat, [(0, 1, 2), (0, 2, 1)])
    with open(d + "truncated.stl", "wb") as f:
        f.write(stl_binary_bytes(cv, ct)[:84 + 50 * 7 + 20])
    with open(d + "garbage.stl", "wb") as f:
        f.write(bytes((i * 97 + 13) % 251 for i in range(1000)))
    with open(d + "garbage.obj", "w") as f:
        f.write("this is not a mesh\nf 1 2 x\nv 1 2\n")
    print("sphere mesh volume / 4/3 pi:", volume(sv, st) / (4 / 3 * math.pi))
    print("cylinder mesh volume / pi r^2 h:", volume(yv, yt) / (math.pi * 0.25))


if __name__ == "__main__":
    main()
