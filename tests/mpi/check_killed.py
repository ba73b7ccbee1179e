#!/usr/bin/python3
"""Checks the folder of a run over MPI ranks that was killed mid-run: every
file under its final name is whole (what is being written is under its
.part name). The .pvd lists files that exist; every .pvtp and every piece
<scene>_NNNN_pR.vtp on disk reads with VTK's readers without an error or
warning, each .pvtp lists RANKS pieces that exist and hold PARTICLES
together; every PNG frame ends with its IEND chunk; every checkpoint
manifest's own CRC-32 holds and the pieces it names are there with its
sizes and checksums; energy.csv and probes.csv rows have the header's
columns (the last line may be torn: they are streams); no summary.json.
Usage: check_killed.py DIR SCENE RANKS PARTICLES"""
import glob
import os
import re
import struct
import sys
import xml.etree.ElementTree as ET
import zlib

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                "..", "io"))
from check_vtk import read_polydata  # noqa: E402

problems = []


def fail(msg):
    problems.append(msg)


def points(path):
    poly, seen = read_polydata(path)
    if seen:
        fail("VTK reported %s reading %s" % (seen, path))
    return poly.GetNumberOfPoints()


def manifest(path, d):
    text = open(path, "rb").read()
    at = text.rfind(b"\ncrc ")
    if at < 0 or "%08x" % zlib.crc32(text[:at + 1]) != \
            text[at + 5:].strip().decode():
        fail("%s: its crc line does not hold" % path)
        return
    for line in text[:at].decode().splitlines():
        m = re.match(r"piece (\d+) (\S+) (\d+) ([0-9a-f]+)$", line)
        if not m:
            continue
        piece = os.path.join(d, m.group(2))
        if not os.path.exists(piece):
            fail("%s names the missing %s" % (path, m.group(2)))
            continue
        data = open(piece, "rb").read()
        if len(data) != int(m.group(3)) or \
                "%08x" % struct.unpack("<I", data[-4:])[0] != m.group(4):
            fail("%s: %s is not the piece it names" % (path, m.group(2)))


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    d, scene, ranks, particles = sys.argv[1:3] + [int(x) for x in
                                                   sys.argv[3:5]]
    if os.path.exists(os.path.join(d, "summary.json")):
        fail("the killed run has a summary.json")
    root = ET.parse(os.path.join(d, scene + ".pvd")).getroot()
    for ds in root.iter("DataSet"):
        if not os.path.exists(os.path.join(d, ds.get("file"))):
            fail(".pvd lists the missing %s" % ds.get("file"))
    pvtps = sorted(glob.glob(os.path.join(d, scene + "_[0-9]*.pvtp")))
    for p in pvtps:
        pieces = [x.get("Source") for x in ET.parse(p).getroot().iter("Piece")]
        if len(pieces) != ranks or not all(
                os.path.exists(os.path.join(d, x)) for x in pieces):
            fail("%s lists %s" % (p, pieces))
        elif points(p) != particles:
            fail("%s holds %d particles, not %d" % (p, points(p), particles))
    vtps = glob.glob(os.path.join(d, scene + "_[0-9]*_p[0-9]*.vtp"))
    total = sum(points(v) for v in vtps)
    pngs = glob.glob(os.path.join(d, "frames", "*.png"))
    for f in pngs:
        if not open(f, "rb").read().endswith(b"IEND\xaeB`\x82"):
            fail("%s does not end with IEND" % f)
    sphm = glob.glob(os.path.join(d, "checkpoint_*.sphm"))
    for m in sphm:
        manifest(m, d)
    for csv in ("energy.csv", "probes.csv"):
        lines = open(os.path.join(d, csv)).read().split("\n")
        cols = lines[0].count(",")
        for i, line in enumerate(lines[1:-1]):
            if line.count(",") != cols:
                fail("%s line %d is torn: %r" % (csv, i + 2, line))
    for p in problems:
        print("FAIL:", p)
    print("check_killed: %d .pvtp, %d pieces (%d points), %d PNG, %d "
          "manifests, %d .part files; %d problems" % (
              len(pvtps), len(vtps), total, len(pngs), len(sphm),
              len(glob.glob(os.path.join(d, "*.part")) +
                  glob.glob(os.path.join(d, "frames", "*.part"))),
              len(problems)))
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
