#!/usr/bin/env python3
# rawout.py DUMP PREFIX SPACING: per path, raw route voxels OUTSIDE the path's own tubes (dist > own radius), with the tube they lie in
import sys, math
d, pre, sp = sys.argv[1], sys.argv[2], [float(x) for x in sys.argv[3].split(',')]
vox = min(sp)
T = {}
for l in open(f"{d}/{pre}_truth.txt"):
    b, p, x, y, z, r = l.split(); T.setdefault(int(b), [int(p), []])[1].append((float(x), float(y), float(z), float(r)))
def mm(a, b): return math.sqrt(sum(((a[i]-b[i])*sp[i])**2 for i in range(3)))
def dist(q, b): return min((mm(q, t)/vox, t[3]/vox) for t in T[b][1])
paths = {}
for l in open(f"{d}/{pre}_raw.txt"):
    i, x, y, z = map(int, l.split()); paths.setdefault(i, []).append((x, y, z))
for i, vs in sorted(paths.items()):
    end = vs[-1]
    tb = min(T, key=lambda b: dist(end, b)[0])
    own = []; b = tb
    while b >= 0: own.append(b); b = T[b][0]
    out = []
    for k, v in enumerate(vs):
        do = min(dist(v, b) for b in own)
        if do[0] > do[1]:
            oth = min(((dist(v, b), b) for b in T if b not in own), default=((99, 0), -1))
            tag = "in" if oth[0][0] < oth[0][1] else "bg"
            out.append(f"{k}{v}:{do[0]:.1f}/r{do[1]:.1f}({tag} b{oth[1]} {oth[0][0]:.1f})")
    print(f"path {i} -> b{tb} own {own[::-1]} n {len(vs)} raw out {len(out)}: " + " ".join(out))
