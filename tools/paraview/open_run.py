"""Open an sph run in ParaView: the .pvd series (serial or over MPI ranks)
coloured by a field, each particle a sphere one particle spacing across
(the median nearest-neighbour distance of the first state), on the light
grey of the PNG frames, a 2D scene face-on in parallel projection and a 3D
one from azimuth 30, elevation 20, fitted to the bodies, at the last time
step.

  pvbatch tools/paraview/open_run.py DIR [--field F] [--screenshot OUT.png]
          [--size WxH]     (headless, without X: under xvfb-run -a -s
                            '-screen 0 1280x1024x24 -noreset')
  paraview --script=tools/paraview/open_run.py        (with SPH_RUN=DIR)
"""
import glob
import math
import os
import sys

from paraview import servermanager
from paraview import simple as pv
from vtkmodules.vtkCommonCore import vtkIdList
from vtkmodules.vtkCommonDataModel import vtkPolyData, vtkStaticPointLocator

BACKGROUND = [236 / 255.0] * 3
INK = [0.1, 0.1, 0.1]
FILL_W, FILL_H = 0.75, 0.9  # the bodies' share of the frame's width, height
LEFT = 0.1  # the bodies' centre that far left of the middle, clear of the bar


def parse(argv):
    opt = {"run": os.environ.get("SPH_RUN", ""), "field": "pressure",
           "shot": None, "size": [1280, 720],
           "gui": pv.GetActiveView() is not None}  # the GUI made a view
    args = list(argv)
    while args:
        a = args.pop(0)
        if a == "--field" and args:
            opt["field"] = args.pop(0)
        elif a == "--screenshot" and args:
            opt["shot"] = args.pop(0)
        elif a == "--size" and args:
            w, _, h = args.pop(0).partition("x")
            if not (w.isdigit() and h.isdigit() and int(w) > 0 and int(h) > 0):
                sys.exit("open_run.py: --size takes WxH, e.g. 1280x720")
            opt["size"] = [int(w), int(h)]
        elif a.startswith("--"):
            sys.exit("open_run.py: unknown option %s" % a)
        else:
            opt["run"] = a
    return opt


def polydata(reader, time):
    """The reader's points at TIME as one vtkPolyData (pieces merged)."""
    merged = pv.MergeBlocks(Input=reader)
    merged.UpdatePipeline(time)
    data = servermanager.Fetch(merged)
    pv.Delete(merged)
    out = vtkPolyData()
    out.SetPoints(data.GetPoints())
    return out


def spacing(poly):
    """The median distance from a particle of POLY (a sample of 2000 at
    most) to its nearest neighbour."""
    n = poly.GetNumberOfPoints()
    if n < 2:
        return 0.0
    loc = vtkStaticPointLocator()
    loc.SetDataSet(poly)
    loc.BuildLocator()
    ids = vtkIdList()
    step = max(1, n // 2000)
    d = []
    for i in range(0, n, step):
        p = poly.GetPoint(i)
        loc.FindClosestNPoints(2, p, ids)
        j = ids.GetId(1) if ids.GetId(0) == i else ids.GetId(0)
        q = poly.GetPoint(j)
        d.append(math.dist(p, q))
    d.sort()
    return d[len(d) // 2]


def fit_camera(view, bounds, is2d, radius):
    """A 2D scene face-on in parallel projection, a 3D one in perspective
    from azimuth 30, elevation 20; either filling FILL_W of the frame's
    width or FILL_H of its height, the bounds' every corner inside, LEFT
    of the frame's width left of the middle (the colour bar's side free)."""
    lo = [bounds[2 * k] - radius for k in range(3)]
    hi = [bounds[2 * k + 1] + radius for k in range(3)]
    centre = [(a + b) / 2 for a, b in zip(lo, hi)]
    aspect = view.ViewSize[0] / float(view.ViewSize[1])
    view.CameraFocalPoint = centre
    view.CameraViewUp = [0, 1, 0]
    if is2d:
        view.CameraParallelProjection = 1
        size = max(hi[0] - lo[0], hi[1] - lo[1])
        view.CameraPosition = [centre[0], centre[1], centre[2] + 2 * size]
        view.CameraParallelScale = max((hi[1] - lo[1]) / 2 / FILL_H,
                                       (hi[0] - lo[0]) / 2 / FILL_W / aspect)
        view.GetActiveCamera().SetWindowCenter(2 * LEFT, 0)
        return
    view.CameraParallelProjection = 0
    view.CameraPosition = [centre[0], centre[1], centre[2] + 1]
    camera = view.GetActiveCamera()
    camera.Azimuth(30)
    camera.Elevation(20)
    camera.OrthogonalizeViewUp()
    pos, up = camera.GetPosition(), camera.GetViewUp()
    back = [p - c for p, c in zip(pos, centre)]
    norm = math.sqrt(sum(b * b for b in back))
    back = [b / norm for b in back]
    right = [up[1] * back[2] - up[2] * back[1],
             up[2] * back[0] - up[0] * back[2],
             up[0] * back[1] - up[1] * back[0]]
    tv = math.tan(math.radians(camera.GetViewAngle()) / 2)
    th = tv * aspect
    dist = 0.0
    for corner in [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                   for z in (lo[2], hi[2])]:
        r = [c - m for c, m in zip(corner, centre)]
        along = sum(a * b for a, b in zip(r, back))
        across = abs(sum(a * b for a, b in zip(r, right)))
        high = abs(sum(a * b for a, b in zip(r, up)))
        dist = max(dist, along + across / (FILL_W * th),
                   along + high / (FILL_H * tv))
    view.CameraPosition = [c + dist * b for c, b in zip(centre, back)]
    view.CameraViewUp = list(up)
    camera.SetWindowCenter(2 * LEFT, 0)


def main(argv):
    opt = parse(argv)
    run, field = opt["run"], opt["field"]
    pvds = sorted(glob.glob(os.path.join(run, "*.pvd")))
    if not pvds:
        sys.exit("open_run.py: no .pvd in '%s'" % run)
    reader = pv.PVDReader(FileName=pvds[0])
    reader.UpdatePipelineInformation()
    times = list(reader.TimestepValues) if reader.TimestepValues else [0.0]
    arrays = reader.PointData.keys()
    if field not in arrays:
        sys.exit("open_run.py: no point array '%s' (the run has: %s)"
                 % (field, ", ".join(arrays)))
    dx = spacing(polydata(reader, times[0]))
    view = pv.GetActiveViewOrCreate("RenderView")
    if opt["shot"] or not opt["gui"]:  # the GUI's view keeps its size
        view.ViewSize = opt["size"]
    pv.GetTimeKeeper().Time = times[-1]  # the GUI's views follow it
    view.ViewTime = times[-1]
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0  # else the palette's wins
    view.Background = BACKGROUND
    view.OrientationAxesLabelColor = INK
    shown = pv.Show(reader, view)
    shown.SetRepresentationType("Point Gaussian")
    shown.ShaderPreset = "Sphere"
    shown.ScaleByArray = 0
    shown.GaussianRadius = dx / 2 if dx > 0 else 1.0
    pv.ColorBy(shown, ("POINTS", field))
    lut = pv.GetColorTransferFunction(field)
    if field in ("pressure", "J"):
        lut.ApplyPreset("Cool to Warm", True)
    else:
        lut.ApplyPreset("Viridis (matplotlib)", True)
    shown.RescaleTransferFunctionToDataRange(False, True)
    shown.SetScalarBarVisibility(view, True)
    bar = pv.GetScalarBar(lut, view)
    bar.TitleColor = INK
    bar.LabelColor = INK
    reader.UpdatePipeline(times[-1])
    bounds = reader.GetDataInformation().GetBounds()
    is2d = bounds[5] - bounds[4] <= 1e-9 * max(bounds[1] - bounds[0],
                                               bounds[3] - bounds[2], 1e-300)
    pv.Render(view)  # paraview.simple resets the camera on its first render
    fit_camera(view, bounds, is2d, dx / 2)
    pv.Render(view)
    if opt["shot"]:
        pv.SaveScreenshot(opt["shot"], view, ImageResolution=opt["size"])
    print("opened %s: %d time steps (%g to %g s), coloured by %s, %s, "
          "spacing %.6g m" % (pvds[0], len(times), times[0], times[-1], field,
                              "2D" if is2d else "3D", dx))


# the GUI's Python (paraview --script) has no arguments of its own
main(getattr(sys, "argv", [""])[1:])
