"""Open an sph run in ParaView: the .pvd series coloured by a field, shown
as points the size of a particle spacing, the camera set like the PNG
frames (azimuth 30, elevation 20, fitted), at the last time step.

  paraview --script=tools/paraview/open_run.py        (with SPH_RUN=DIR)
  pvbatch tools/paraview/open_run.py DIR [--field F] [--screenshot OUT.png]
"""
import glob
import os
import sys

from paraview import simple as pv


def main(argv):
    run = os.environ.get("SPH_RUN", "")
    field = "pressure"
    shot = None
    args = list(argv)
    while args:
        a = args.pop(0)
        if a == "--field" and args:
            field = args.pop(0)
        elif a == "--screenshot" and args:
            shot = args.pop(0)
        else:
            run = a
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
    view = pv.GetActiveViewOrCreate("RenderView")
    view.ViewTime = times[-1]
    view.ViewSize = [1280, 720]
    view.Background = [236 / 255.0] * 3
    shown = pv.Show(reader, view)
    shown.SetRepresentationType("Points")
    shown.PointSize = 6
    shown.RenderPointsAsSpheres = 1
    pv.ColorBy(shown, ("POINTS", field))
    lut = pv.GetColorTransferFunction(field)
    if field in ("pressure", "J"):
        lut.ApplyPreset("Cool to Warm", True)
    else:
        lut.ApplyPreset("Viridis (matplotlib)", True)
    shown.RescaleTransferFunctionToDataRange(False, True)
    shown.SetScalarBarVisibility(view, True)
    view.CameraPosition = [0, 0, 1]
    view.CameraFocalPoint = [0, 0, 0]
    view.CameraViewUp = [0, 1, 0]
    view.ResetCamera()
    camera = view.GetActiveCamera()
    camera.Azimuth(30)
    camera.Elevation(20)
    view.ResetCamera()
    pv.Render(view)
    if shot:
        pv.SaveScreenshot(shot, view, ImageResolution=[1280, 720])
    print("opened %s: %d time steps, coloured by %s"
          % (pvds[0], len(times), field))


main(sys.argv[1:])
