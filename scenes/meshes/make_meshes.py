#!/usr/bin/python3
"""Writes the meshes of the shipped scenes beside this script (public
domain, CC0: made here, no third-party data):
  oring.obj  an O-ring: a torus about the y axis, centre line radius 10 mm,
             cross-section radius 2 mm (a 24 x 4 mm seal), 64 x 24 segments,
             in millimetres (the scene reads it with units: mm)
  dogbone.svg a flat tensile specimen (after ISO 37 type 2, simplified to
             straight tapers): 75 mm long, 12.5 mm wide grips, a 25 mm
             gauge 4 mm wide, as an SVG path in mm
Run: scenes/meshes/make_meshes.py"""
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def torus(R, r, nu, nv):
    v = []
    for i in range(nu):
        a = 2 * math.pi * i / nu
        for j in range(nv):
            b = 2 * math.pi * j / nv
            rho = R + r * math.cos(b)
            v.append((rho * math.cos(a), r * math.sin(b), -rho * math.sin(a)))
    f = []
    idx = lambda i, j: (i % nu) * nv + (j % nv)
    for i in range(nu):
        for j in range(nv):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            f += [(a, b, c), (a, c, d)]
    return v, f


def volume(v, f):
    s = 0.0
    for i, j, k in f:
        a, b, c = v[i], v[j], v[k]
        s += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
              + a[2] * (b[0] * c[1] - b[1] * c[0]))
    return s / 6.0


def dogbone():
    # half outline, x >= 0 (mm): grip end, grip, taper, gauge
    half = [(37.5, 6.25), (25.0, 6.25), (12.5, 2.0)]
    pts = [(x, y) for x, y in half] + [(-x, y) for x, y in reversed(half)]
    pts += [(-x, -y) for x, y in half] + [(x, -y) for x, y in reversed(half)]
    d = "M " + " L ".join("%g %g" % (x, -y) for x, y in pts) + " Z"
    with open(os.path.join(HERE, "dogbone.svg"), "w") as out:
        out.write('<?xml version="1.0"?>\n<!-- tensile specimen, mm '
                  '(scenes/meshes/make_meshes.py; CC0) -->\n'
                  '<svg xmlns="http://www.w3.org/2000/svg" viewBox="-40 -10 80 20">\n'
                  '  <path d="%s"/>\n</svg>\n' % d)
    print("dogbone.svg: %d points" % len(pts))


def main():
    dogbone()
    v, f = torus(10.0, 2.0, 64, 24)
    vol = volume(v, f)
    assert vol > 0, "the triangles must face outwards"
    with open(os.path.join(HERE, "oring.obj"), "w") as out:
        out.write("# O-ring, torus about y: R = 10 mm, r = 2 mm, 64 x 24 segments "
                  "(scenes/meshes/make_meshes.py; CC0)\n")
        for p in v:
            out.write("v %.6f %.6f %.6f\n" % p)
        for t in f:
            out.write("f %d %d %d\n" % tuple(i + 1 for i in t))
    print("oring.obj: %d triangles, volume %.4f mm^3 (torus %.4f)"
          % (len(f), vol, 2 * math.pi ** 2 * 10.0 * 4.0))


if __name__ == "__main__":
    main()
