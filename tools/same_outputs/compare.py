#!/usr/bin/env python3
"""compare.py BASE NEW [--ignore GLOB ...] [--only SCENE ...]: every file of
BASE's runs equals NEW's byte for byte, except summary.json's timings and
provenance and scene_used.yaml's two comment lines. --ignore skips files
whose name matches GLOB (e.g. '*.png' for a change meant to alter frames
only); --only compares the named scenes. Prints one line per scene and
'N passed, N failed'."""
import fnmatch, json, os, sys
args = sys.argv[1:]
ignore = []; only = []
while '--ignore' in args:
    i = args.index('--ignore'); ignore.append(args[i + 1]); del args[i:i + 2]
while '--only' in args:
    i = args.index('--only'); only.append(args[i + 1]); del args[i:i + 2]
base, new = args[0], args[1]
def skipped(f): return any(fnmatch.fnmatch(os.path.basename(f), g) for g in ignore)
def norm_summary(b):
    d = json.loads(b)
    d.pop('sph', None); d.pop('wall_seconds', None); d.pop('render_thread_seconds', None)
    for k in ('terms', 'sinks'):
        if k in d: d[k] = sorted(d[k].keys())
    return d
def rc(root, n):
    try:
        return [l for l in open(os.path.join(root, n + '.log')).read().split('\n') if l.startswith('verdict') or 'sph:' in l]
    except OSError: return None
ok = bad = 0
for n in sorted(os.listdir(base)):
    b = os.path.join(base, n); m = os.path.join(new, n)
    if not os.path.isdir(b) or (only and n not in only): continue
    probs = []
    files = set()
    for r, _, fs in os.walk(b):
        for f in fs: files.add(os.path.relpath(os.path.join(r, f), b))
    nfiles = set()
    if os.path.isdir(m):
        for r, _, fs in os.walk(m):
            for f in fs: nfiles.add(os.path.relpath(os.path.join(r, f), m))
    files -= {'.sph.lock', '.sph.manifest'}; nfiles -= {'.sph.lock', '.sph.manifest'}
    files = {f for f in files if not skipped(f)}; nfiles = {f for f in nfiles if not skipped(f)}
    if files != nfiles: probs.append('files differ: only base %s, only new %s' % (sorted(files - nfiles)[:5], sorted(nfiles - files)[:5]))
    for f in sorted(files & nfiles):
        x = open(os.path.join(b, f), 'rb').read(); y = open(os.path.join(m, f), 'rb').read()
        if f == 'summary.json':
            if norm_summary(x) != norm_summary(y): probs.append(f)
        elif f == 'scene_used.yaml':
            if x.split(b'\n')[2:] != y.split(b'\n')[2:]: probs.append(f)
        elif x != y: probs.append(f)
    if probs: bad += 1; print('FAIL', n, probs[:6])
    else: ok += 1; print('ok  ', n, len(files), 'files')
print('%d passed, %d failed' % (ok, bad))
sys.exit(1 if bad else 0)
