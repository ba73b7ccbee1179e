#!/usr/bin/python3
"""Reads what `sph run` wrote with VTK's own XML reader (the vtkmodules of
Debian's python3-paraview, ParaView's own VTK) and checks it: the .pvd is
a Collection with increasing times and every file present; every .vtp
reads without a VTK error or warning (each in its own process: a
malformed header can abort the reader); point counts, array names and
component counts; binary and ASCII runs hold identical values; points
equal initial_position + displacement; each file's TimeValue field data
equals its .pvd time; the probe particle's values equal probes.csv.
Usage: check_vtk.py BINARY_DIR ASCII_DIR SCENE_NAME or check_vtk.py
--series DIR SCENE_NAME: the .pvd and every file it lists read cleanly
with the same point count (e.g. after a killed run)."""
import csv
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

EXPECTED = {"pressure": 1, "velocity": 3, "displacement": 3,
            "initial_position": 3, "J": 1, "stress": 9, "body_id": 1,
            "particle_id": 1, "acceleration": 3}


def watch(reader):
    """The list that the errors and warnings VTK reports while `reader`
    runs are appended to."""
    from vtkmodules.vtkCommonCore import vtkCommand
    problems = []
    for event in (vtkCommand.ErrorEvent, vtkCommand.WarningEvent):
        reader.AddObserver(event, lambda obj, ev: problems.append(ev))
        reader.GetExecutive().AddObserver(event,
                                          lambda obj, ev: problems.append(ev))
    return problems


def read_polydata(path):
    """A .vtp or a .pvtp (its pieces) read whole: the output and the errors
    and warnings VTK reported (tests/mpi/check_mpi.py, check_killed.py)."""
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLPPolyDataReader
    reader = (vtkXMLPPolyDataReader() if path.endswith(".pvtp")
              else vtkXMLPolyDataReader())
    problems = watch(reader)
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput(), problems


def read_one(path):
    """Child process: read a file, print its arrays as repr() or fail."""
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
    reader = vtkXMLPolyDataReader()
    problems = watch(reader)
    reader.SetFileName(path)
    reader.Update()
    if problems:
        sys.exit("VTK reported %s reading %s" % (problems, path))
    poly = reader.GetOutput()

    def values(a):  # plain lists: repr() to the parent process
        nc = a.GetNumberOfComponents()
        return [list(a.GetTuple(i)) if nc > 1 else a.GetTuple(i)[0]
                for i in range(a.GetNumberOfTuples())]

    out = {"npoints": poly.GetNumberOfPoints(),
           "nverts": poly.GetNumberOfVerts(),
           "points": values(poly.GetPoints().GetData())}
    tv = poly.GetFieldData().GetArray("TimeValue")
    out["time"] = tv.GetTuple1(0) if tv is not None else None
    pd = poly.GetPointData()
    for i in range(pd.GetNumberOfArrays()):
        a = pd.GetArray(i)
        out[a.GetName()] = (a.GetNumberOfComponents(), values(a))
    print(repr(out))


def read(path):
    r = subprocess.run([sys.executable, __file__, "--one", path],
                       capture_output=True, text=True)
    if r.returncode != 0:
        fail("%s: %s %s" % (path, r.stdout[-500:], r.stderr[-2000:]))
        return None
    return eval(r.stdout)  # our own repr() of lists and numbers


failures = 0


def fail(msg):
    global failures
    failures += 1
    print("FAIL:", msg)


def frames(d, name):
    root = ET.parse(os.path.join(d, name + ".pvd")).getroot()
    if root.get("type") != "Collection":
        fail("%s.pvd is not a Collection" % name)
    sets = root.find("Collection").findall("DataSet")
    times = [float(s.get("timestep")) for s in sets]
    if any(b <= a for a, b in zip(times, times[1:])):
        fail("pvd times do not increase: %s" % times)
    files = [os.path.join(d, s.get("file")) for s in sets]
    for f in files:
        if not os.path.exists(f):
            fail("pvd lists a missing file %s" % f)
    return times, files


def close(a, b, tol):
    return abs(a - b) <= tol * max(1.0, abs(a), abs(b))


def main():
    bdir, adir, name = sys.argv[1:4]
    tb, fb = frames(bdir, name)
    ta, fa = frames(adir, name)
    if tb != ta or len(fb) < 2:
        fail("binary and ASCII runs list different frames")
    probes = list(csv.DictReader(open(os.path.join(bdir, "probes.csv"))))
    for k, (path_b, path_a) in enumerate(zip(fb, fa)):
        b, a = read(path_b), read(path_a)
        if b is None or a is None:
            continue
        n = b["npoints"]
        # each file carries its own time, read by VTK (TimeValue)
        for d in (b, a):
            if d["time"] is None or not close(d["time"], tb[k], 1e-15):
                fail("%s: TimeValue %s, the .pvd says %r" %
                     (path_b, d["time"], tb[k]))
        if n != a["npoints"] or b["nverts"] != n:
            fail("%s: %d points, %d verts" % (path_b, n, b["nverts"]))
        for arr, nc in EXPECTED.items():
            if arr not in b or b[arr][0] != nc:
                fail("%s: array %s missing or not %d components" %
                     (path_b, arr, nc))
                continue
            if b[arr][1] != a[arr][1]:
                fail("%s: %s differs between binary and ASCII" % (path_b, arr))
        if b["points"] != a["points"]:
            fail("%s: points differ between binary and ASCII" % path_b)
        # points = initial position + displacement
        X, U = b["initial_position"][1], b["displacement"][1]
        # creation order whatever the storage order: ids 0..n-1 and the
        # box lattice with x slowest, z fastest
        if [int(v) for v in b["particle_id"][1]] != list(range(n)):
            fail("%s: particle_id is not 0..%d in order" % (path_b, n - 1))
        if any(tuple(X[j]) >= tuple(X[j + 1]) for j in range(n - 1)):
            fail("%s: particles are not listed in creation order" % path_b)
        for p, x0, u in zip(b["points"], X, U):
            if any(not close(p[c], x0[c] + u[c], 1e-12) for c in range(3)):
                fail("%s: point %s != X + u" % (path_b, p))
                break
        # the probe particle: nearest to the probe in the reference state
        row = probes[k]
        if not close(float(row["time [s]"]), tb[k], 1e-12):
            fail("probe time %s vs frame time %s" % (row["time [s]"], tb[k]))
        at = (0.5, 6.0, 0.5)
        i = min(range(n), key=lambda j: sum((X[j][c] - at[c]) ** 2
                                            for c in range(3)))
        for c, s in enumerate("xyz"):
            for field in ("displacement", "velocity"):
                unit = "m" if field == "displacement" else "m/s"
                want = float(row["tip.%s_%s [%s]" % (field, s, unit)])
                if not close(b[field][1][i][c], want, 1e-12):
                    fail("%s: tip %s_%s %r vs probes.csv %r" %
                         (path_b, field, s, b[field][1][i][c], want))
    print("%d frames checked, %d problems" % (len(fb), failures))
    print("%d passed, %d failed" % (1 if failures == 0 else 0,
                                    1 if failures else 0))
    sys.exit(1 if failures else 0)


def series():
    d, name = sys.argv[2:4]
    _, files = frames(d, name)
    counts = set()
    for path in files:
        r = read(path)
        if r is not None:
            counts.add(r["npoints"])
    if len(counts) > 1:
        fail("frames hold different point counts %s" % counts)
    print("%d frames of %s read cleanly, %d problems" %
          (len(files), d, failures))
    sys.exit(1 if failures or not files else 0)


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--one":
        read_one(sys.argv[2])
    elif len(sys.argv) == 4 and sys.argv[1] == "--series":
        series()
    else:
        main()
