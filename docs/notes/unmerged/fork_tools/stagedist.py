#!/usr/bin/python3
# stagedist.py LOG TRUTH sx sy sz: per traced point, its distance to the truth at each stage
import sys, math, re
sys.path.insert(0, '/work/s46/fork/tools')
sp=[float(v) for v in sys.argv[3:6]]; vox=min(sp)
br={}
for l in open(sys.argv[2]):
    a=l.split(); br.setdefault(int(a[0]),[]).append(tuple(map(float,a[2:5])))
def near(p):
    best=(1e9,-1)
    for b,q in br.items():
        for j in range(len(q)-1):
            A=[q[j][i]*sp[i] for i in range(3)]; B=[q[j+1][i]*sp[i] for i in range(3)]; P=[p[i]*sp[i] for i in range(3)]
            ab=[B[i]-A[i] for i in range(3)]; L=sum(x*x for x in ab)
            t=0 if L==0 else max(0,min(1,sum((P[i]-A[i])*ab[i] for i in range(3))/L))
            d=math.sqrt(sum((P[i]-A[i]-t*ab[i])**2 for i in range(3)))/vox
            if d<best[0]: best=(d,b)
    return best
for l in open(sys.argv[1]):
    m=re.match(r'\[trace\] (\S+)\s+k (\d+) raw (\S+) -> (\S+) (\S+) (\S+)',l)
    if not m or m.group(1)=='round': continue
    p=tuple(map(float,m.group(4,5,6))); d,b=near(p)
    print(f"k {m.group(2):>4} raw {m.group(3):10} {m.group(1):14} ({p[0]:.2f},{p[1]:.2f},{p[2]:.2f}) {d:.2f} b{b}")
