#!/usr/bin/python3
"""Writes the test meshes of tests/unit/test_mesh.c and tests/cli (run from
anywhere: the files land beside this script). Made here, public domain
(CC0), like the rest of the test data:
  cube.stl          unit cube [0,1]^3, 12 triangles, ASCII STL, outward
  cube_binary.stl   the same, binary STL
  cube_mm.stl       the same 1000 units across (units: mm)
  cube_hole.stl     one triangle removed (11)
  cube_dup_flip.stl one triangle duplicated, another flipped (13)
  cube_inverted.stl every triangle flipped (negative volume)
  sheet.stl         an open square sheet (no inside)
  cube_top.stl      the unit cube's face z = 1 alone (2 triangles: a
                    selection's surface)
  ell.stl           an L-shaped prism (non-convex), 20 triangles
  ell_moved.stl     the same turned 90 degrees about z, moved by (2, 1, 0.5)
  icosphere.obj     a sphere of radius 0.5 about (0.5, 0.5, 0.5), 1280
                    triangles (an icosahedron split 3 times), OBJ
Usage: make_meshes.py [--big N OUT.stl]: instead, an icosphere of at least N
triangles as binary STL (the fill benchmark, tools/mesh_bench.sh)."""
import math
import os
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def quad(a, b, c, d):
    return [(a, b, c), (a, c, d)]


def cube(side=1.0):
    s = side
    P = lambda x, y, z: (x * s, y * s, z * s)
    t = []
    t += quad(P(0, 0, 0), P(0, 1, 0), P(1, 1, 0), P(1, 0, 0))  # -z
    t += quad(P(0, 0, 1), P(1, 0, 1), P(1, 1, 1), P(0, 1, 1))  # +z
    t += quad(P(0, 0, 0), P(1, 0, 0), P(1, 0, 1), P(0, 0, 1))  # -y
    t += quad(P(0, 1, 0), P(0, 1, 1), P(1, 1, 1), P(1, 1, 0))  # +y
    t += quad(P(0, 0, 0), P(0, 0, 1), P(0, 1, 1), P(0, 1, 0))  # -x
    t += quad(P(1, 0, 0), P(1, 1, 0), P(1, 1, 1), P(1, 0, 1))  # +x
    return t


def flip(tri):
    return (tri[0], tri[2], tri[1])


def volume(tris):
    v = 0.0
    for a, b, c in tris:
        v += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
              + a[2] * (b[0] * c[1] - b[1] * c[0]))
    return v / 6.0


def normal(a, b, c):
    u = [b[k] - a[k] for k in range(3)]
    w = [c[k] - a[k] for k in range(3)]
    n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
    r = math.sqrt(sum(x * x for x in n)) or 1.0
    return [x / r for x in n]


def write_ascii(path, tris):
    with open(path, "w") as f:
        f.write("solid sph\n")
        for a, b, c in tris:
            f.write(" facet normal %.9g %.9g %.9g\n  outer loop\n" % tuple(normal(a, b, c)))
            for p in (a, b, c):
                f.write("   vertex %.9g %.9g %.9g\n" % tuple(p))
            f.write("  endloop\n endfacet\n")
        f.write("endsolid sph\n")


def write_binary(path, tris):
    with open(path, "wb") as f:
        f.write(b"binary STL written by sph tests/data/meshes/make_meshes.py".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for a, b, c in tris:
            f.write(struct.pack("<12fH", *normal(a, b, c), *a, *b, *c, 0))


def ell():
    poly = [(0, 0), (1, 0), (1, 0.5), (0.5, 0.5), (0.5, 1), (0, 1)]  # CCW
    h = 0.5
    t = []
    fan = [(3, 4, 5), (3, 5, 0), (3, 0, 1), (3, 1, 2)]  # from the reflex corner
    for i, j, k in fan:
        t.append(tuple((poly[m][0], poly[m][1], h) for m in (i, j, k)))
        t.append(tuple((poly[m][0], poly[m][1], 0.0) for m in (i, k, j)))
    for i in range(len(poly)):
        p, q = poly[i], poly[(i + 1) % len(poly)]
        t += quad((p[0], p[1], 0.0), (q[0], q[1], 0.0), (q[0], q[1], h), (p[0], p[1], h))
    return t


def icosphere(levels, r=0.5, c=(0.5, 0.5, 0.5)):
    g = (1 + math.sqrt(5)) / 2
    v = [(-1, g, 0), (1, g, 0), (-1, -g, 0), (1, -g, 0), (0, -1, g), (0, 1, g),
         (0, -1, -g), (0, 1, -g), (g, 0, -1), (g, 0, 1), (-g, 0, -1), (-g, 0, 1)]
    v = [tuple(x / math.sqrt(1 + g * g) for x in p) for p in v]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(levels):
        mid = {}

        def m(i, j):
            key = (min(i, j), max(i, j))
            if key not in mid:
                p = [(v[i][k] + v[j][k]) / 2 for k in range(3)]
                n = math.sqrt(sum(x * x for x in p))
                v.append(tuple(x / n for x in p))
                mid[key] = len(v) - 1
            return mid[key]

        f = [t for a, b, cc in f for t in
             ((a, m(a, b), m(a, cc)), (b, m(b, cc), m(a, b)), (cc, m(a, cc), m(b, cc)),
              (m(a, b), m(b, cc), m(a, cc)))]
    v = [tuple(c[k] + r * p[k] for k in range(3)) for p in v]
    return v, f


def main():
    if len(sys.argv) == 4 and sys.argv[1] == "--big":
        want, levels = int(sys.argv[2]), 0
        while 20 * 4 ** levels < want:
            levels += 1
        v, f = icosphere(levels)
        write_binary(sys.argv[3], [tuple(v[i] for i in t) for t in f])
        print("%s: %d triangles" % (sys.argv[3], len(f)))
        return
    out = lambda name: os.path.join(HERE, name)
    c = cube()
    assert len(c) == 12 and abs(volume(c) - 1.0) < 1e-15
    write_ascii(out("cube.stl"), c)
    write_binary(out("cube_binary.stl"), c)
    write_ascii(out("cube_mm.stl"), cube(1000.0))
    write_ascii(out("cube_hole.stl"), c[:7] + c[8:])
    dup = list(c)
    dup[5] = flip(dup[5])
    dup.append(c[0])
    write_ascii(out("cube_dup_flip.stl"), dup)
    write_ascii(out("cube_inverted.stl"), [flip(t) for t in c])
    write_ascii(out("cube_top.stl"), c[2:4])
    write_ascii(out("sheet.stl"), quad((0, 0, 0.5), (1, 0, 0.5), (1, 1, 0.5), (0, 1, 0.5)))
    e = ell()
    assert abs(volume(e) - 0.375) < 1e-15, volume(e)
    write_ascii(out("ell.stl"), e)
    moved = [tuple((2 - p[1], 1 + p[0], 0.5 + p[2]) for p in t) for t in e]
    write_ascii(out("ell_moved.stl"), moved)
    v, f = icosphere(3)
    with open(out("icosphere.obj"), "w") as fo:
        fo.write("# icosphere, radius 0.5 about (0.5, 0.5, 0.5): tests/data/meshes/make_meshes.py\n")
        for p in v:
            fo.write("v %.9g %.9g %.9g\n" % p)
        for t in f:
            fo.write("f %d %d %d\n" % tuple(i + 1 for i in t))
    tris = [tuple(v[i] for i in t) for t in f]
    print("icosphere: %d triangles, volume %.6g (sphere %.6g)"
          % (len(f), volume(tris), 4 / 3 * math.pi * 0.125))


if __name__ == "__main__":
    main()
