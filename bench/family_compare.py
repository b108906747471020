#!/usr/bin/env python3
"""Compare two vessel family sweeps (bench/family_sweep.sh), line by line, by seed.

A seed meets the issue's bounds (issue 21) when every target is reached, >= 98 % of refined points lie
within 1 voxel of the truth, the mean is <= 0.3 voxel and the radius error <= 0.5 voxel. Prints every line
that moved (LOST / GAINED when the verdict changed) and the counts per group.
    bench/family_compare.py OLD.txt [NEW.txt]
"""
import os
import re
import sys

LINE = re.compile(r"^\[(family|variant) seed (\d+): (\w[\w ]*?),")
FIG = re.compile(r"mean ([\d.]+) vox, within 1 vox ([\d.]+)%.*?radius error ([\d.]+) vox")
REACHED = re.compile(r"(\d+)/(\d+) reached")
NEIGHBOUR = re.compile(r"on a neighbour (\d+)")


def parse(path):
    out = {}
    with open(path) as f:
        for line in f:
            m = LINE.match(line)
            g = FIG.search(line)
            if not m or not g:
                continue
            mean, share, radius = (float(x) for x in g.groups())
            r = REACHED.search(line)
            reached = r is None or r.group(1) == r.group(2)
            n = NEIGHBOUR.search(line)
            met = reached and share >= 98.0 and mean <= 0.3 and radius <= 0.5
            key = (m.group(1), int(m.group(2)))
            out[key] = dict(kind=m.group(3), met=met, share=share, mean=mean, radius=radius,
                            neighbour=int(n.group(1)) if n else 0, line=line.strip())
    return out


def group(key):
    prefix, seed = key
    if prefix == "variant":
        return "variants" if seed < 1000 else "given"
    return "thin" if seed < 1000 else "thin forced"


def summary(d, name):
    groups = {}
    for k, v in d.items():
        g = groups.setdefault(group(k), [0, 0, []])
        g[0] += v["met"]
        g[1] += 1
        if not v["met"]:
            g[2].append(f"{k[1]} ({v['share']:.1f} %, mean {v['mean']:.3f})")
    for g, (met, n, miss) in sorted(groups.items()):
        print(f"{name} {g}: {met}/{n} met" + (f"; not met: {', '.join(miss)}" if miss else ""))


def main():
    if len(sys.argv) < 2 or any(not os.path.isfile(f) for f in sys.argv[1:3]):
        print(__doc__.strip(), file=sys.stderr)
        return 2
    a = parse(sys.argv[1])
    summary(a, "A")
    if len(sys.argv) < 3:
        return
    b = parse(sys.argv[2])
    summary(b, "B")
    same = 0
    for k in sorted(set(a) | set(b), key=lambda k: (group(k), k[1])):
        if k not in a or k not in b:
            print(f"only in {'A' if k in a else 'B'}: {k[0]} {k[1]}")
            continue
        x, y = a[k], b[k]
        if x["line"] == y["line"]:
            same += 1
            continue
        tag = "LOST" if x["met"] and not y["met"] else "GAINED" if y["met"] and not x["met"] else "moved"
        print(f"{tag:6} {k[1]:>6} {x['kind']:<9} share {x['share']:.1f} -> {y['share']:.1f}, mean {x['mean']:.3f} -> "
              f"{y['mean']:.3f}, radius {x['radius']:.3f} -> {y['radius']:.3f}, neighbour {x['neighbour']} -> "
              f"{y['neighbour']}")
    print(f"{same} of {len(set(a) & set(b))} lines identical")


if __name__ == "__main__":
    sys.exit(main())
