#!/usr/bin/python3
"""far.py PREFIX sx sy sz [thr]: per refined point farther than thr voxels (min spacing) from every truth
branch, its own nearest branch, distance, and the raw voxel (same path, same index scaled) distances.
PREFIX: dump/TAG/thin_SEED (files PREFIX.txt, PREFIX_truth.txt, PREFIX_raw.txt)."""
import sys, math
from collections import defaultdict
pre = sys.argv[1]; sp = [float(x) for x in sys.argv[2:5]]; thr = float(sys.argv[5]) if len(sys.argv) > 5 else 1.0
vox = min(sp)
pts = defaultdict(list)
for l in open(pre + '.txt'):
    a = l.split(); pts[int(a[0])].append(tuple(map(float, a[1:4])))
br = defaultdict(list); par = {}
for l in open(pre + '_truth.txt'):
    a = l.split(); b = int(a[0]); par[b] = int(a[1]); br[b].append((tuple(map(float, a[2:5])), float(a[5])))
raw = defaultdict(list)
for l in open(pre + '_raw.txt'):
    a = l.split(); raw[int(a[0])].append(tuple(map(float, a[1:4])))
def d2seg(p, a, b):
    P = [p[i]*sp[i] for i in range(3)]; A = [a[i]*sp[i] for i in range(3)]; B = [b[i]*sp[i] for i in range(3)]
    ab = [B[i]-A[i] for i in range(3)]; L = sum(x*x for x in ab)
    t = 0 if L == 0 else max(0, min(1, sum((P[i]-A[i])*ab[i] for i in range(3))/L))
    return math.sqrt(sum((P[i]-A[i]-t*ab[i])**2 for i in range(3)))/vox, t
def near(p):
    best = (1e9, -1, -1)
    for b, q in br.items():
        for j in range(len(q)-1):
            d, t = d2seg(p, q[j][0], q[j+1][0])
            if d < best[0]: best = (d, b, j + t)
    return best
for i in sorted(pts):
    P = pts[i]; R = raw[i]
    for k, p in enumerate(P):
        d, b, j = near(p)
        if d > thr:
            r = R[min(len(R)-1, round(k * (len(R)-1) / max(1, len(P)-1)))] if R else None
            dr = near(r) if r else None
            print(f"path {i} pt {k}/{len(P)} ({p[0]:.1f},{p[1]:.1f},{p[2]:.1f}) {d:.2f} off b{b}@{j:.1f}"
                  + (f"  raw~({r[0]:.0f},{r[1]:.0f},{r[2]:.0f}) {dr[0]:.2f} b{dr[1]}@{dr[2]:.1f}" if r else ""))
print("branches:", {b: (par[b], len(q), tuple(round(x,1) for x in q[0][0]), round(q[0][1]/vox, 2)) for b, q in br.items()})
