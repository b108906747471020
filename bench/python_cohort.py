#!/usr/bin/python3
"""Cohort runner: a cohort of the shared volumes traced on one Dask worker, then on two, alternately.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_cohort.py [BUILD] [--copies N] [--repeats R]
                                                                   [--threads runner|1]

Each shared vessel / airway volume is one case (vs.trace with the CLI's defaults and automatic
terminals from a root inside the structure), repeated --copies times under different names.
For 1 and 2 workers, alternately --repeats times, it reports the wall time of run_cohort (local
cluster start included), the span from the first case's start to the last case's end (cluster
start excluded), and the summed case time. --threads runner keeps the runner's default (each
worker's core threads = cores / workers, so one worker already runs the two-thread search on both
cores); --threads 1 gives every case one thread, so the workers alone decide the parallelism.
Target (issue 17): two workers at most 0.6x the time of one.

The machine's own ceiling is measured in the same run, alternated with the rounds: a pure-Python
CPU loop (no memory traffic, no I/O) run twice in one process against once in each of two
processes at the same time. On a machine with two free cores that ratio is 0.5; a smaller share of
a physical core per vCPU (shared hosts, SMT siblings) or other load raises it, and no cohort runner
can do better than it.
"""
import argparse
import csv
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, "..", "shared", "data")
CASES = [  # path, root inside the structure (the auto cost finds polarity and window there)
    ("chest_cta_totalseg/ct_cropped.nii.gz", "46,59,150"),  # airways (dark)
    ("neck_mra_carotid_vtk/carotid.vtk", "52,24,3"),  # carotid (bright)
    ("abdomen_mra_aorta_vmtk/aorta.mha", "78,196,17"),  # aorta (bright)
]


SPIN = "s = 0\nfor i in range(12_000_000): s += i\n"


def spin_seconds(processes, units):
    """Wall seconds for `processes` processes at once, each running the CPU loop `units` times."""
    code = SPIN * units
    t = time.perf_counter()
    procs = [subprocess.Popen([sys.executable, "-c", code]) for _ in range(processes)]
    for p in procs:
        p.wait()
    return time.perf_counter() - t


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("build", nargs="?", default=os.path.join(ROOT, "build"))
    ap.add_argument("--copies", type=int, default=10)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--threads", choices=("runner", "1"), default="runner")
    a = ap.parse_args()
    sys.path.insert(0, os.path.join(a.build, "python"))
    from volscissors import batch

    tmp = tempfile.mkdtemp(prefix="vs_bench_cohort_")
    rows = []
    for k in range(a.copies):
        for path, root in CASES:
            full = os.path.join(DATA, path)
            if os.path.exists(full):
                name = os.path.basename(os.path.dirname(path))
                rows.append({"case": f"{name}-{k}", "path": os.path.abspath(full), "root": root,
                             "auto_terminals": "4"})
    if not rows:
        sys.exit("no shared data found")
    cases = os.path.join(tmp, "cases.csv")
    with open(cases, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["case", "path", "root", "auto_terminals"])
        w.writeheader()
        w.writerows(rows)
    print(f"{len(rows)} cases, threads per case: {a.threads}, load {os.getloadavg()}")
    results = {1: [], 2: []}
    ceilings = []
    for rep in range(a.repeats):
        serial, parallel = spin_seconds(1, 2), spin_seconds(2, 1)
        ceilings.append(parallel / serial)
        print(f"  machine ceiling: the same CPU loop twice in one process {serial:.2f} s, once in each of two "
              f"processes at once {parallel:.2f} s: {parallel / serial:.3f}, load {os.getloadavg()[0]:.1f}")
        for workers in (1, 2):
            out = os.path.join(tmp, f"out{workers}-{rep}")
            if a.threads == "1":
                os.environ["VS_THREADS"] = "1"
            else:
                os.environ.pop("VS_THREADS", None)
            t = time.perf_counter()
            records = batch.run_cohort(cases, "trace", out, workers=workers, log=lambda *_: None)
            wall = time.perf_counter() - t
            ok = sum(r["status"] == "ok" for r in records)
            busy = statistics.fsum(r["seconds"]["total"] for r in records)
            span = (max(r["started_unix"] + r["seconds"]["total"] for r in records) -
                    min(r["started_unix"] for r in records))
            results[workers].append((wall, span, busy))
            print(f"  {workers} worker(s): {ok}/{len(records)} ok, wall {wall:.2f} s, cases span {span:.2f} s, "
                  f"summed case time {busy:.2f} s, load {os.getloadavg()[0]:.1f}")
            for r in records:
                if r["status"] != "ok":
                    print(f"     {r['case']}: {r['error']['type']}: {r['error']['message']}")
    w1, w2 = (statistics.median(x[0] for x in results[k]) for k in (1, 2))
    s1, s2 = (statistics.median(x[1] for x in results[k]) for k in (1, 2))
    print(f"two workers / one worker: wall {w2 / w1:.3f}, cases span {s2 / s1:.3f} (target <= 0.6); "
          f"the machine's ceiling for two processes in the same run: {statistics.median(ceilings):.3f}")
    shutil.rmtree(tmp)


if __name__ == "__main__":
    main()
