#!/usr/bin/python3
"""Compares a run over MPI ranks with the serial run of the same scene,
reading the files with VTK's own readers (python3-paraview's vtkmodules):
the .pvd names a .pvtp per output time at the serial times; each .pvtp
(VTK's parallel PolyData reader) carries that time (TimeValue, the time
the reader reports when the .pvtp series is opened without the .pvd) and
lists RANKS pieces that read without a VTK error or warning
and together hold the serial particle count and arrays; every value equals
the serial one (matched by particle_id) within REL_TOL of the array's
largest magnitude; the PNG frames (rank 0, from the gathered particles)
and probes.csv (when the scene has them) equal the serial files; energy.csv
has the serial rows, the energies within REL_TOL and the momenta within REL_TOL
of the largest linear (angular) momentum component or of sum m |v| (sum m |v|
|x|), bounded below by 2 E_kin / |v|max (times |x|max) from the serial
velocities, where the momentum is round-off itself (sums over ranks in
another order). Prints the largest relative difference measured.
With --roundoff (a method whose global sums, summed in rank order, enter the
state): probes.csv values are within REL_TOL of their column's largest
magnitude and the frames only have the serial names (compare them
with sph imgdiff).
Usage: check_mpi.py SERIAL_DIR MPI_DIR SCENE RANKS REL_TOL [--roundoff]"""
import csv
import math
import os
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                "..", "io"))
from check_vtk import read_polydata  # noqa: E402


def fail(msg):
    sys.exit("check_mpi: " + msg)


def read(path):
    poly, problems = read_polydata(path)
    if problems:
        fail("VTK reported %s reading %s" % (problems, path))

    def values(a):  # plain lists, as check_vtk.py
        nc = a.GetNumberOfComponents()
        return [a.GetTuple(i) for i in range(a.GetNumberOfTuples())], nc

    arrays = {"Points": values(poly.GetPoints().GetData())}
    pd = poly.GetPointData()
    for i in range(pd.GetNumberOfArrays()):
        arrays[pd.GetArray(i).GetName()] = values(pd.GetArray(i))
    if "particle_id" not in arrays:
        fail("%s has no particle_id" % path)
    ids = [int(t[0]) for t in arrays["particle_id"][0]]
    return poly.GetNumberOfPoints(), ids, arrays


def pvtp_time(path):
    """the times VTK's parallel reader reports for a .pvtp on its own"""
    from vtkmodules.vtkCommonExecutionModel import \
        vtkStreamingDemandDrivenPipeline
    from vtkmodules.vtkIOXML import vtkXMLPPolyDataReader
    reader = vtkXMLPPolyDataReader()
    reader.SetFileName(path)
    reader.UpdateInformation()
    return reader.GetOutputInformation(0).Get(
        vtkStreamingDemandDrivenPipeline.TIME_STEPS())


def pvd(path):
    root = ET.parse(path).getroot()
    return [(float(d.get("timestep")), d.get("file"))
            for d in root.iter("DataSet")]


def rel_diff(a, b):
    """largest |a - b| over the largest |a| of an array"""
    scale = max((abs(x) for t in a for x in t), default=0.0) or 1.0
    return max((abs(x - y) for s, t in zip(a, b) for x, y in zip(s, t)),
               default=0.0) / scale


def main():
    roundoff = sys.argv[6:] == ["--roundoff"]
    if len(sys.argv) != 6 + roundoff:
        fail(__doc__)
    serial, par, scene, ranks, tol = sys.argv[1:4] + [int(sys.argv[4]),
                                                      float(sys.argv[5])]
    s_series, p_series = (pvd(os.path.join(d, scene + ".pvd"))
                          for d in (serial, par))
    if [t for t, _ in s_series] != [t for t, _ in p_series]:
        fail("output times differ: %s vs %s" % (s_series, p_series))
    worst = vmax = rmax = 0.0
    for (t, sf), (_, pf) in zip(s_series, p_series):
        if not pf.endswith(".pvtp"):
            fail("%s is not a .pvtp" % pf)
        pieces = [p.get("Source") for p in
                  ET.parse(os.path.join(par, pf)).getroot().iter("Piece")]
        if len(pieces) != ranks:
            fail("%s lists %d pieces, not %d" % (pf, len(pieces), ranks))
        for p in pieces:
            if not os.path.exists(os.path.join(par, p)):
                fail("%s names the missing %s" % (pf, p))
        if pvtp_time(os.path.join(par, pf)) != (t,):
            fail("%s: VTK reads the time %s, the .pvd says %r"
                 % (pf, pvtp_time(os.path.join(par, pf)), t))
        ns, sids, sa = read(os.path.join(serial, sf))
        np_, pids, pa = read(os.path.join(par, pf))
        if ns != np_ or sorted(sids) != sorted(pids):
            fail("%s: %d particles, serial %d" % (pf, np_, ns))
        if {k: v[1] for k, v in sa.items()} != {k: v[1] for k, v in pa.items()}:
            fail("%s: arrays %s, serial %s" % (pf, sorted(pa), sorted(sa)))
        at = {pid: i for i, pid in enumerate(pids)}
        vmax = max([vmax] + [math.sqrt(sum(x * x for x in v))
                             for v in sa.get("velocity", ([], 3))[0]])
        rmax = max([rmax] + [math.sqrt(sum(x * x for x in v))
                             for v in sa["Points"][0]])
        for name, (vals, _) in sa.items():
            mine = [pa[name][0][at[pid]] for pid in sids]
            d = rel_diff(vals, mine)
            worst = max(worst, d)
            if d > tol:
                fail("%s at t = %g: %s differs from serial by %g (relative)"
                     % (pf, t, name, d))
    frames, pframes = (sorted(os.listdir(os.path.join(d, "frames")))
                       if os.path.isdir(os.path.join(d, "frames")) else []
                       for d in (serial, par))
    if frames != pframes:
        fail("frames/ holds %s, serial %s" % (pframes, frames))
    for f in frames if not roundoff else []:
        with open(os.path.join(serial, "frames", f), "rb") as a, \
                open(os.path.join(par, "frames", f), "rb") as b:
            if a.read() != b.read():
                fail("frames/%s differs from the serial run's" % f)
    probes = [os.path.exists(os.path.join(d, "probes.csv"))
              for d in (serial, par)]
    if probes[0] != probes[1]:
        fail("probes.csv written by one run only")
    pdiff = 0.0
    if probes[0] and roundoff:
        pa_, pb_ = (columns(os.path.join(d, "probes.csv"), "probes.csv")
                    for d in (serial, par))
        if pa_[0] != pb_[0] or pa_[1][0] != pb_[1][0]:
            fail("probes.csv rows, columns or times differ")
        pdiff = max(rel_diff([(x,) for x in u], [(x,) for x in v])
                    for u, v in zip(pa_[1], pb_[1]))
        if pdiff > tol:
            fail("probes.csv: values differ by %g (relative)" % pdiff)
    elif probes[0]:
        with open(os.path.join(serial, "probes.csv")) as a, \
                open(os.path.join(par, "probes.csv")) as b:
            if a.read() != b.read():
                fail("probes.csv differs from the serial run's")
    (head, ca), (head_b, cb) = (columns(os.path.join(d, "energy.csv"),
                                        "energy.csv") for d in (serial, par))
    if head != head_b or ca[0] != cb[0]:
        fail("energy.csv rows, columns or times differ")
    ediff = mdiff = 0.0
    for c in range(1, len(head)):
        if c < 4:
            ediff = max(ediff, rel_diff([(x,) for x in ca[c]],
                                        [(x,) for x in cb[c]]))
        else:  # relative to the group's largest component or sum m |v|
            g = range(4, 7) if c < 7 else range(7, len(head))
            scale = max(abs(x) for k in g for x in ca[k])
            # sum m |v| >= 2 E_kin / |v|max: the scale of a round-off sum
            if vmax > 0.0:
                p = 2.0 * max(ca[1]) / vmax
                scale = max(scale, p if c < 7 else p * rmax)
            scale = scale or 1.0
            mdiff = max(mdiff, max(abs(x - y) for x, y in zip(ca[c], cb[c]))
                        / scale)
    if ediff > tol:
        fail("energy.csv: energies differ by %g (relative)" % ediff)
    if mdiff > tol:
        fail("energy.csv: momenta differ by %g (relative)" % mdiff)
    print("check_mpi: %d ranks, %d frames, %d particles: fields max relative "
          "difference %g, energies %g, momenta %g"
          % (ranks, len(s_series), ns, worst, ediff, mdiff)
          + (", probes %g" % pdiff if roundoff else ""))


def columns(path, name):
    """the header and the columns of a CSV file as floats"""
    with open(path) as f:
        rows = list(csv.reader(f))
    if len(rows) < 2 or any(len(r) != len(rows[0]) for r in rows):
        fail("%s has no rows or ragged ones" % name)
    return rows[0], [[float(r[c]) for r in rows[1:]]
                     for c in range(len(rows[0]))]


if __name__ == "__main__":
    main()
