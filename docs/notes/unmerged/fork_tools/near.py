#!/usr/bin/python3
"""near.py PREFIX sx sy sz x y z R [paths]: truth points, raw and refined points within R voxels (mm/minspacing) of (x,y,z)."""
import sys, math
from collections import defaultdict
pre=sys.argv[1]; sp=[float(v) for v in sys.argv[2:5]]; c=[float(v) for v in sys.argv[5:8]]; R=float(sys.argv[8])
paths=set(int(v) for v in sys.argv[9].split(',')) if len(sys.argv)>9 else None
vox=min(sp)
def dist(p): return math.sqrt(sum(((p[i]-c[i])*sp[i])**2 for i in range(3)))/vox
for l in open(pre+'_truth.txt'):
    a=l.split(); p=list(map(float,a[2:5]))
    if dist(p)<=R: print('T b%s par %s (%.1f,%.1f,%.1f) r %.2f' % (a[0],a[1],*p,float(a[5])/vox))
cnt=defaultdict(int)
for l in open(pre+'_raw.txt'):
    a=l.split(); i=int(a[0]); k=cnt[i]; cnt[i]+=1; p=list(map(float,a[1:4]))
    if (paths is None or i in paths) and dist(p)<=R: print('R path %d k %d (%.0f,%.0f,%.0f)' % (i,k,*p))
cnt=defaultdict(int)
for l in open(pre+'.txt'):
    a=l.split(); i=int(a[0]); k=cnt[i]; cnt[i]+=1; p=list(map(float,a[1:4]))
    if (paths is None or i in paths) and dist(p)<=R: print('P path %d k %d (%.2f,%.2f,%.2f) r %.2f' % (i,k,*p,float(a[4])/vox))
