"""Opens the project's outputs the way a user does, with ParaView itself
(run by pvpython or pvbatch; docs/output.md): every .xmf given, with both
readers ParaView offers for XDMF (XDMFReader, and Xdmf3ReaderS, the one
OpenDataFile picks), at every time of the series. At each time every particle must be a vertex
cell (or the Points representation draws nothing) and every vector
array must have 3 components; WarpByVector by each of them must run, and a
Calculator mag(VECTOR) must give, at every point, the norm of the vector the
reader gave (checked against the reader's own array, so a reader that drops
or pads components wrongly fails). One frame of each file is rendered to
OUTDIR and must not be blank. (ParaView 5.11 aborted pvpython on the
2-component vectors the files had before: vtkWarpVector.cxx:236.)

usage: pvpython pv_check.py OUTDIR FILE.xmf...   (exit 0: all good, 1: failures)
"""
import math
import os
import sys

from paraview import servermanager
from paraview.simple import (Calculator, ColorBy, CreateView, Delete, Hide, MergeBlocks, Render,
                             SaveScreenshot, Show, WarpByVector, XDMFReader, Xdmf3ReaderS)
from vtkmodules.numpy_interface import dataset_adapter as dsa
from vtkmodules.vtkIOImage import vtkPNGReader

VECTORS = ('velocity', 'displacement', 'load_acceleration')
failures = []


def fail(msg):
    failures.append(msg)
    print('FAIL ' + msg, flush=True)


def fetch(proxy, t):
    """The proxy's output at time t as one dataset (composite data merged)."""
    proxy.UpdatePipeline(t)
    merged = MergeBlocks(Input=proxy)
    merged.UpdatePipeline(t)
    data = dsa.WrapDataObject(servermanager.Fetch(merged))
    Delete(merged)
    return data


def check_time(label, reader, t):
    data = fetch(reader, t)
    n = data.GetNumberOfPoints()
    if n == 0:
        fail(f'{label} t={t:g}: no points')
        return
    # without cells the Points and Surface representations draw nothing
    # (Xdmf3ReaderS on an implicit Polyvertex topology)
    if data.GetNumberOfCells() != n:
        fail(f'{label} t={t:g}: {data.GetNumberOfCells()} cells for {n} points, want one '
             'vertex cell per particle')
    vectors = [a for a in VECTORS if a in data.PointData.keys()]
    if not vectors:
        fail(f'{label} t={t:g}: none of {VECTORS} among {list(data.PointData.keys())}')
    for name in vectors:
        vec = data.PointData[name]
        if vec.ndim != 2 or vec.shape[1] != 3:
            fail(f'{label} t={t:g}: {name} has shape {vec.shape}, want ({n}, 3)')
            continue
        warp = WarpByVector(Input=reader, Vectors=['POINTS', name])
        warped = fetch(warp, t)
        Delete(warp)
        if warped.GetNumberOfPoints() != n:
            fail(f'{label} t={t:g}: WarpByVector({name}) gave {warped.GetNumberOfPoints()} '
                 f'points of {n}')
        calc = Calculator(Input=reader, ResultArrayName='mag_' + name, Function=f'mag({name})')
        mag = fetch(calc, t).PointData['mag_' + name]
        Delete(calc)
        want = [math.sqrt(sum(c * c for c in v)) for v in vec]
        if mag is None or len(mag) != n:
            fail(f'{label} t={t:g}: Calculator mag({name}) gave no array')
            continue
        worst = max(abs(a - b) for a, b in zip(mag, want))
        scale = max(max(want), 1e-300)
        if not worst <= 1e-12 * scale:
            fail(f'{label} t={t:g}: mag({name}) differs from |{name}| by {worst:g} '
                 f'(max |{name}| {scale:g})')


def times_of(reader):
    """The series' times (a single time comes as a number, none as empty)."""
    tv = reader.TimestepValues
    if isinstance(tv, (int, float)):
        return [float(tv)]
    return [float(t) for t in tv] or [0.0]


def render(label, reader, view, png):
    """The last time, warped, as points coloured by the vector's magnitude."""
    t = times_of(reader)[-1]
    view.ViewTime = t
    name = next(a for a in VECTORS if a in reader.PointData.keys())
    warp = WarpByVector(Input=reader, Vectors=['POINTS', name])
    shown = Show(warp, view)
    shown.SetRepresentationType('Points')
    shown.PointSize = 3
    ColorBy(shown, ('POINTS', name, 'Magnitude'))
    view.ResetCamera()
    Render(view)
    SaveScreenshot(png, view, ImageResolution=[320, 240])
    Hide(warp, view)
    Delete(warp)
    img = vtkPNGReader()
    img.SetFileName(png)
    img.Update()
    px = img.GetOutput().GetPointData().GetScalars()
    if px is None:
        fail(f'{label}: no image in {png}')
        return
    lo, hi = px.GetRange(0)
    if lo == hi:
        fail(f'{label}: the rendered frame {png} is blank (one colour)')


def main():
    outdir, files = sys.argv[1], sys.argv[2:]
    if not files:
        sys.exit(__doc__)
    os.makedirs(outdir, exist_ok=True)
    view = CreateView('RenderView')  # one for all: a view per file upsets Xvfb's GLX at exit
    view.ViewSize = [320, 240]
    view.OrientationAxesVisibility = 0  # a blank frame then has one colour
    for path in map(os.path.abspath, files):  # Xdmf3ReaderS aborts on some relative paths
        for rname, make in (('XDMFReader', lambda p: XDMFReader(FileNames=[p])),
                            ('Xdmf3ReaderS', lambda p: Xdmf3ReaderS(FileName=[p]))):
            label = f'{os.path.basename(os.path.dirname(path))}/{os.path.basename(path)} ' \
                    f'[{rname}]'
            reader = make(path)
            times = times_of(reader)
            nfail = len(failures)
            for t in times:
                check_time(label, reader, t)
            png = os.path.join(outdir, label.replace('/', '_').replace(' ', '_')
                               .replace('[', '').replace(']', '') + '.png')
            render(label, reader, view, png)
            print(f'{"ok  " if len(failures) == nfail else "FAIL"} {label}: {len(times)} times',
                  flush=True)
            Delete(reader)
    Delete(view)  # left to the interpreter's exit, it segfaults pvbatch 5.11 under Xvfb
    print(f'pv_check: {len(failures)} failure(s)')
    sys.exit(1 if failures else 0)


if __name__ == '__main__':
    main()
