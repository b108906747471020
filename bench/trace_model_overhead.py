#!/usr/bin/env python3
"""What the lumen model (the default `--cost auto`) adds to a trace (issue 21, "Speed"), same run.

For each case the same `volscissors trace` runs with the default cost and with `--cost intensity`
given the window and polarity the auto cost estimated (what a user would type to get the root
window alone), alternating, --repeat times each (each process run alone, nothing else started by
this script meanwhile). Reported per case, median and spread (max/min) over the runs:
- wall and CPU (user+sys) of the whole process, and the ratio auto / intensity of the medians
  (the issue's reading: "adds <= 20 % to a trace's wall time");
- the report's `features` seconds (smoothing + cost) of each, and the model's own time as a share
  of the intensity trace: (features_auto - features_intensity) / total_intensity (the stricter
  reading: the same search with a plain cost; the searches differ, so this is the model alone).
Both runs' search results are compared: the number of paths and whether every target was reached.
Then the median CPU seconds of each phase of each (the report's seconds.phases: the cost's phases, search,
terminals, refine): where the difference goes.

  /usr/bin/python3 bench/trace_model_overhead.py [--cli build/volscissors] [--repeat 5] [--data ../shared/data]
  [--cases head_cta,carotid,aorta,airway] [--json out.json]

Exit 0 on a completed measurement; 1 when a run fails or a volume is missing (named).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# Cases: volume under the data folder, trace arguments (the notes' roots, docs/notes/tracking.md).
CASES = {
    "head_cta": ("head_cta_avm/AVM.nii.gz", ["--root", "196,96,5", "--auto-terminals", "6"]),
    "carotid": ("neck_mra_carotid_vtk/carotid.vtk", ["--root", "18,23,10", "--target", "72,11,28", "--target", "52,44,32",
                                                     "--target", "38,4,39", "--target", "72,39,3", "--target", "64,33,3"]),
    "aorta": ("abdomen_mra_aorta_vmtk/aorta.mha", ["--root", "75,172,14", "--auto-terminals", "6"]),
    "airway": ("chest_cta_totalseg/ct_cropped.nii.gz",
               ["--root", "46,59,150", "--auto-terminals", "6", "--min-length", "20"]),
}


def run(cli, volume, args, report, may_fail=False):
    t0 = time.monotonic()
    r0 = os.times()
    p = subprocess.run([cli, "-q", "trace", volume] + args + ["--json", report], capture_output=True, text=True)
    r1 = os.times()
    wall = time.monotonic() - t0
    if p.returncode != 0 and may_fail:
        return {"refused": p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "exit %d" % p.returncode}
    if p.returncode != 0:
        raise SystemExit("trace_model_overhead: %s %s failed (exit %d): %s" %
                         (volume, " ".join(args), p.returncode, p.stderr.strip()[-400:]))
    cpu = (r1.children_user - r0.children_user) + (r1.children_system - r0.children_system)
    rep = json.load(open(report))
    return {"wall": wall, "cpu": cpu, "features": rep["seconds"]["features"], "paths": len(rep["paths"]),
            "estimate": rep.get("cost_estimate"), "phases": rep["seconds"].get("phases", [])}


def phase_text(runs):
    """'smooth 0.41, connect 0.12, ...': the median CPU seconds of each phase over the runs."""
    names = [p[0] for p in runs[0]["phases"]]
    med = {n: statistics.median(p[2] for r in runs for p in r["phases"] if p[0] == n) for n in names}
    return ", ".join("%s %.3f" % (n, med[n]) for n in names), med


def spread(xs):
    return max(xs) / max(min(xs), 1e-12)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default=os.path.join(ROOT, "build", "volscissors"))
    ap.add_argument("--data", default=os.path.join(ROOT, "..", "shared", "data"))
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--json", help="write the rows here")
    a = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        rep = os.path.join(tmp, "r.json")
        for name in a.cases.split(","):
            rel, args = CASES[name]
            volume = os.path.join(a.data, rel)
            if not os.path.exists(volume):
                raise SystemExit("trace_model_overhead: %s is missing (the shared data set %s)" % (volume, rel))
            first = run(a.cli, volume, args, rep)  # warm the page cache; gives the window
            e = first["estimate"]
            plain = args + ["--cost", "intensity", "--polarity", e["polarity"], "--window",
                            "%.6g,%.6g" % tuple(e["window"]), "--smooth", "%g" % e["smooth_mm"]]
            auto, inten = [], []
            for _ in range(a.repeat):
                auto.append(run(a.cli, volume, args, rep))
                inten.append(run(a.cli, volume, plain, rep, may_fail=True))
                if "refused" in inten[-1]:
                    break
            if "refused" in inten[-1]:
                # No like-for-like run: the root window alone does not reach these targets.
                print("%-9s auto wall %.2f s cpu %.2f s features %.2f s; intensity with the same window REFUSED (%s)" %
                      (name, auto[0]["wall"], auto[0]["cpu"], auto[0]["features"], inten[-1]["refused"]), flush=True)
                rows.append({"case": name, "auto_wall": auto[0]["wall"], "intensity_refused": inten[-1]["refused"]})
                continue
            med = {k: (statistics.median(r[k] for r in auto), statistics.median(r[k] for r in inten))
                   for k in ("wall", "cpu", "features")}
            row = {"case": name, "auto_wall": med["wall"][0], "intensity_wall": med["wall"][1],
                   "wall_ratio": med["wall"][0] / med["wall"][1],
                   "wall_spread": [spread([r["wall"] for r in auto]), spread([r["wall"] for r in inten])],
                   "auto_cpu": med["cpu"][0], "intensity_cpu": med["cpu"][1], "cpu_ratio": med["cpu"][0] / med["cpu"][1],
                   "features": list(med["features"]),
                   "model_share": (med["features"][0] - med["features"][1]) / med["wall"][1],
                   "paths": [auto[0]["paths"], inten[0]["paths"]]}
            if auto[0]["phases"] and inten[0]["phases"]:
                (ta, ma), (ti, mi) = phase_text(auto), phase_text(inten)
                row["phases_cpu"] = [ma, mi]
            rows.append(row)
            print("%-9s wall auto %.2f s / intensity %.2f s = %.3f (spread %.2f, %.2f); cpu %.2f / %.2f = %.3f; "
                  "features %.2f / %.2f s: model alone %.1f %% of the intensity trace; paths %d / %d" %
                  (name, row["auto_wall"], row["intensity_wall"], row["wall_ratio"], *row["wall_spread"],
                   row["auto_cpu"], row["intensity_cpu"], row["cpu_ratio"], *row["features"],
                   100 * row["model_share"], *row["paths"]), flush=True)
            if "phases_cpu" in row:
                print("          CPU by phase, auto: %s\n          intensity: %s" % (ta, ti), flush=True)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
