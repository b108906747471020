#!/usr/bin/python3
"""Cohort runner: a cohort of the shared volumes traced on one Dask worker, then on two.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_cohort.py [BUILD] [--copies N]

Each shared vessel / airway volume is one case (auto terminals from a root inside the
structure), repeated --copies times under different case names. Reports the wall time of
run_cohort (local cluster start included, and separately the time from the first submitted case)
for 1 and 2 workers, and the ratio (issue 17: two workers at most 0.6x one worker).
"""
import argparse
import csv
import os
import shutil
import statistics
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, "..", "shared", "data")
CASES = [  # path, root, parameters: airways (dark) or contrast vessels (bright)
    ("chest_cta_totalseg/ct_cropped.nii.gz", "46,59,150",
     {"cost": "intensity", "polarity": "dark", "window": "-1000,-950", "smooth_mm": "0"}),
    ("neck_mra_carotid_vtk/carotid.vtk", "52,24,3", {"cost": "intensity"}),
    ("abdomen_mra_aorta_vmtk/aorta.mha", "78,196,17", {"cost": "intensity"}),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("build", nargs="?", default=os.path.join(ROOT, "build"))
    ap.add_argument("--copies", type=int, default=2)
    a = ap.parse_args()
    sys.path.insert(0, os.path.join(a.build, "python"))
    from volscissors import batch

    tmp = tempfile.mkdtemp(prefix="vs_bench_cohort_")
    fields = ["case", "path", "root", "auto_terminals", "min_length_mm", "cost", "polarity", "window", "smooth_mm"]
    rows = []
    for k in range(a.copies):
        for path, root, params in CASES:
            full = os.path.join(DATA, path)
            if os.path.exists(full):
                name = os.path.basename(os.path.dirname(path))
                rows.append({"case": f"{name}-{k}", "path": os.path.abspath(full), "root": root,
                             "auto_terminals": "4", "min_length_mm": "10", **params})
    if not rows:
        sys.exit("no shared data found")
    cases = os.path.join(tmp, "cases.csv")
    with open(cases, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        w.writerows(rows)
    times = {}
    for workers in (1, 2):
        out = os.path.join(tmp, f"out{workers}")
        os.environ.pop("VS_THREADS", None)
        t = time.perf_counter()
        records = batch.run_cohort(cases, "trace", out, workers=workers, log=lambda *_: None)
        wall = time.perf_counter() - t
        ok = sum(r["status"] == "ok" for r in records)
        busy = statistics.fsum(r["seconds"]["total"] for r in records)
        times[workers] = wall
        print(f"{workers} worker(s): {len(records)} cases ({ok} ok) in {wall:.2f} s wall, "
              f"{busy:.2f} s of case time")
        for r in records:
            if r["status"] != "ok":
                print(f"   {r['case']}: {r['error']['type']}: {r['error']['message']}")
    print(f"two workers / one worker: {times[2] / times[1]:.3f} (target <= 0.6)")
    shutil.rmtree(tmp)


if __name__ == "__main__":
    main()
