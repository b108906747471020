#!/usr/bin/env python3
"""Two volscissors binaries timed on the same real traces, alternated, in one run (issue 21, session 39 cache702).

The machines these sessions share move 2-10x with the other jobs, so main's binary (A) and a change's (B) are
timed in the same rounds, their order swapped every round (a trend in the load falls on both), and compared by
per-round ratio B/A. Each run's wall seconds and its CPU seconds (user + system, from wait4) are printed; then per
trace and binary the median with the spread (min - max), and the median of the per-round ratios. With --check, each
trace's reports of A and B (first round) must be identical but for "seconds" (exit status 1 if not).

Traces (defaults, the docs/notes/tracking.md real sets): carotid - the carotid MRA must-keep's five given dim targets
from root 18,23,10 (bench/trace_must_keep.sh, all at once); headcta - head CTA 196,96,5 --auto-terminals 6;
3dra144 / 3dra189 - head_3dra 144,90,118 / 189,133,97 --auto-terminals 6; headcta5 (not a default) - the head CTA
must-keep's five given dim targets from 196,96,5.

  /usr/bin/python3 bench/trace_time_ab.py --a MAIN_BIN --b BIN [--data DIR] [--rounds 7] [--traces carotid,headcta]
      [--check] [--out DIR]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

TRACES = {
    "carotid": ("neck_mra_carotid_vtk/carotid.vtk",
                ["--root", "18,23,10", "--target", "72,11,28", "--target", "52,44,32", "--target", "38,4,39",
                 "--target", "72,39,3", "--target", "64,33,3"]),
    "headcta": ("head_cta_avm/AVM.nii.gz", ["--root", "196,96,5", "--auto-terminals", "6"]),
    "3dra144": ("head_3dra_aneurism/aneurism.vti", ["--root", "144,90,118", "--auto-terminals", "6"]),
    "3dra189": ("head_3dra_aneurism/aneurism.vti", ["--root", "189,133,97", "--auto-terminals", "6"]),
    "headcta5": ("head_cta_avm/AVM.nii.gz",
                 ["--root", "196,96,5", "--target", "82,253,110", "--target", "229,52,86", "--target", "60,101,16",
                  "--target", "239,261,59", "--target", "36,77,101"]),
}


def timed(binary, volume, args, report):
    """One trace: (wall seconds, CPU seconds of the child)."""
    t0 = time.monotonic()
    p = subprocess.Popen([binary, "-q", "trace", volume, *args, "--json", report],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.monotonic() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"trace_time_ab: {binary} {' '.join(args)} exited {os.waitstatus_to_exitcode(status)}")
    return wall, ru.ru_utime + ru.ru_stime


def without_seconds(path):
    with open(path) as f:
        r = json.load(f)
    r.pop("seconds", None)
    return r


def spread(xs):
    return f"{statistics.median(xs):.3f} ({min(xs):.3f} - {max(xs):.3f})"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--a", required=True, help="main's volscissors")
    ap.add_argument("--b", required=True, help="the change's volscissors")
    ap.add_argument("--data", default=os.environ.get("VS_DATA", os.path.join(os.path.dirname(__file__),
                                                                            "../../shared/data")))
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--traces", default="carotid,headcta,3dra144,3dra189")
    ap.add_argument("--check", action="store_true", help="A's and B's reports identical but for seconds")
    ap.add_argument("--out", default=None, help="folder for the reports (default: a temporary one)")
    a = ap.parse_args()
    out = a.out or tempfile.mkdtemp(prefix="trace_time_ab_")
    os.makedirs(out, exist_ok=True)
    names = a.traces.split(",")
    times = {(n, w): {"wall": [], "cpu": []} for n in names for w in "AB"}
    differ = 0
    for r in range(a.rounds):
        order = "AB" if r % 2 == 0 else "BA"
        for n in names:
            vol, args = TRACES[n]
            for w in order:
                report = os.path.join(out, f"{n}_{w}_{r}.json")
                wall, cpu = timed(a.a if w == "A" else a.b, os.path.join(a.data, vol), args, report)
                times[(n, w)]["wall"].append(wall)
                times[(n, w)]["cpu"].append(cpu)
                print(f"round {r + 1} {n} {w}: wall {wall:.3f} s, cpu {cpu:.3f} s", flush=True)
            if a.check and r == 0:
                same = without_seconds(os.path.join(out, f"{n}_A_0.json")) == without_seconds(
                    os.path.join(out, f"{n}_B_0.json"))
                differ += not same
                print(f"{n}: reports {'identical' if same else 'DIFFER'} but for seconds", flush=True)
            for w in "AB":
                if r > 0:
                    os.remove(os.path.join(out, f"{n}_{w}_{r}.json"))
    print("\ntrace     binary  wall s median (min - max)   cpu s median (min - max)")
    for n in names:
        for w in "AB":
            t = times[(n, w)]
            print(f"{n:9s} {w}       {spread(t['wall']):24s} {spread(t['cpu'])}")
        ratios = {k: [b / a_ for a_, b in zip(times[(n, 'A')][k], times[(n, 'B')][k])] for k in ("wall", "cpu")}
        print(f"{n:9s} B/A     wall {spread(ratios['wall'])}, cpu {spread(ratios['cpu'])} (per-round ratios)")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
