#!/usr/bin/python3
"""Compares the stability verdict of a run over MPI ranks with the serial
run's (summary.json): the same stable flag, non-finite flag, first
indicator and its time, the same trip time of every indicator, the same
particle count and zig-zag judged particles, and the indicators' values (J
min and max, the largest checkerboard, stretch, pairs over and zig-zag
roughness; the momentum drifts, relative to sum m |v| themselves) within
REL_TOL relative (the ranks' sums are added in rank order). Prints the
largest relative difference. --skip KEY leaves out a value that measures
round-off itself (the checkerboard of a pressure uniform to round-off).
Usage: check_verdict.py SERIAL_DIR MPI_DIR REL_TOL [--skip KEY]..."""
import json
import math
import os
import sys


def fail(msg):
    print("check_verdict: " + msg)
    sys.exit(1)


def load(d):
    with open(os.path.join(d, "summary.json")) as f:
        return json.load(f)


def main():
    skip = sys.argv[5::2]
    if len(sys.argv) < 4 or sys.argv[4::2] != ["--skip"] * len(skip):
        fail(__doc__)
    a, b = load(sys.argv[1]), load(sys.argv[2])
    tol = float(sys.argv[3])
    for k in ("stable", "nan", "first_indicator", "tripped_at", "indicators",
              "particles", "zigzag_judged_particles", "reason"):
        if a.get(k) != b.get(k):
            fail("%s: serial %r, over ranks %r" % (k, a.get(k), b.get(k)))
    values = [("J", "min"), ("J", "max"), ("checkerboard_max",),
              ("fracture", "max_stretch_dp"), ("fracture", "pairs_over"),
              ("zigzag_max",), ("linear_momentum_drift",),
              ("angular_momentum_drift",)]
    worst = 0.0
    for path in values:
        if ".".join(path) in skip:
            continue
        x, y = a, b
        for k in path:
            x, y = x[k], y[k]
        if x is None or y is None:
            if x is not y:
                fail("%s: serial %r, over ranks %r" % (".".join(path), x, y))
            continue
        d = abs(x - y)  # the drifts: already relative to sum m |v|
        if "drift" not in path[0]:
            d /= max(abs(x), abs(y), 1e-300)
        if d > tol or math.isnan(d):
            fail("%s: serial %r, over ranks %r" % (".".join(path), x, y))
        worst = max(worst, d)
    print("check_verdict: %s at %s, as serial; values to %g relative"
          % (a["first_indicator"] or "stable", a["tripped_at"], worst))


main()
