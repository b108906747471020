#!/usr/bin/python3
"""Volume cutting (issue 14) side by side with VTK, in one run.

  /usr/bin/python3 bench/cut_vs_vtk.py [--build build] [--data ../shared/data] [--workdir /tmp/vs_cut_bench]
                                       [--phantom 256] [--repeat 3]

1. build/bench_cut speed on the head CT (head_ct_cranium_invesalius, iso -300 HU, the eight
   points around the nose of scripts/demo.d/50_cut.sh): our mesh extraction, the contour updates
   while the points are placed (the search restarts at each point, then follows the cursor
   vertex by vertex along the segment), the whole cut after the last point (cutting surface +
   split). It writes the skin mesh (PLY), the searches (seed, cursor vertex) and the volume.
   Then the viewer's cut preview (the core's CutContourSession): point k clicked, the cursor moved
   towards point k+1 along the surface, one preview (the closed loop the cut will use) per
   position, each checked against cutContour from scratch (mismatches must be 0).
2. VTK on the same files: vtkDijkstraGraphGeodesicPath on the same mesh for every one of the
   same (seed, cursor) pairs (one filter reused, as an application would; its first Update, which
   builds the adjacency, reported apart); vtkFlyingEdges3D alone on the same volume and iso-value
   (normals, gradients and scalars off), median of --repeat runs, against our extraction (the same
   filter plus the mapping to world mm and outward winding), median of --repeat runs.
   VTK's Dijkstra weighs edges by length only (no image term); ours is eq. 13.
3. build/bench_cut phantom N: the whole cut after the last point on a N^3 head phantom, and the
   preview per cursor move on it as in 1.
Prints one JSON line per step and a summary line. Times are CPU seconds of the process (ours:
CLOCK_PROCESS_CPUTIME_ID, VTK: time.process_time), since on the shared, overloaded machine wall
time mostly measures the other processes; the load average is printed before and after.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
NOSE_POINTS = "110,214,16;126,231,13;142,223,16;145,216,26;138,211,38;126,216,42;114,199,38;107,210,26"


def run_json(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def percentile(values, p):
    v = sorted(values)
    return v[min(len(v) - 1, int(p / 100.0 * (len(v) - 1) + 0.5))]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--data", default=os.path.join(ROOT, "..", "shared", "data"))
    ap.add_argument("--workdir", default="/tmp/vs_cut_bench")
    ap.add_argument("--phantom", type=int, default=256)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    import numpy as np
    import vtk
    from vtk.util import numpy_support as ns

    os.makedirs(a.workdir, exist_ok=True)
    bench = os.path.join(a.build, "bench_cut")
    ct = os.path.join(a.data, "head_ct_cranium_invesalius", "cranium.nhdr")
    if not os.path.exists(ct):
        sys.exit(f"{ct} missing (../shared/data)")
    print(json.dumps({"uptime": open("/proc/loadavg").read().split()[:3]}))

    ours_runs = [run_json([bench, "speed", ct, "-300", NOSE_POINTS, a.workdir]) for _ in range(a.repeat)]
    ours = ours_runs[0]
    ours["extract_cpu_seconds_median"] = statistics.median(r["extract_cpu_seconds"] for r in ours_runs)
    print(json.dumps({"ours": ours}))

    # VTK's Dijkstra on the same mesh and the same (seed, cursor) pairs.
    reader = vtk.vtkPLYReader()
    reader.SetFileName(os.path.join(a.workdir, "mesh.ply"))
    reader.Update()
    mesh = reader.GetOutput()
    assert mesh.GetNumberOfPoints() == ours["skin_vertices"], "the PLY's vertices are not ours"
    queries = [tuple(map(int, line.split())) for line in open(os.path.join(a.workdir, "queries.txt"))]
    dijkstra = vtk.vtkDijkstraGraphGeodesicPath()
    dijkstra.SetInputData(mesh)
    dijkstra.StopWhenEndReachedOn()
    times = []
    first = None
    for seed, cursor in queries:
        dijkstra.SetStartVertex(seed)
        dijkstra.SetEndVertex(cursor)
        t0 = time.process_time()
        dijkstra.Update()
        dt = time.process_time() - t0
        if first is None:
            first = dt
        else:
            times.append(dt)
    vtk_paths = {"queries": len(queries), "first_update_cpu_ms": 1e3 * first,
                 "update_cpu_ms_median": 1e3 * statistics.median(times),
                 "update_cpu_ms_p95": 1e3 * percentile(times, 95), "update_cpu_ms_max": 1e3 * max(times)}
    print(json.dumps({"vtkDijkstraGraphGeodesicPath": vtk_paths}))

    # vtkFlyingEdges3D alone on the same volume (index space; spacing does not change the work).
    nx, ny, nz = ours["dims"]
    values = np.fromfile(os.path.join(a.workdir, "volume.f32"), dtype=np.float32)
    image = vtk.vtkImageData()
    image.SetDimensions(nx, ny, nz)
    image.SetSpacing(*ours["spacing"])
    image.GetPointData().SetScalars(ns.numpy_to_vtk(values, deep=True))
    fe_times = []
    for _ in range(a.repeat):
        fe = vtk.vtkFlyingEdges3D()
        fe.SetInputData(image)
        fe.SetValue(0, ours["iso"])
        fe.ComputeNormalsOff()
        fe.ComputeGradientsOff()
        fe.ComputeScalarsOff()
        t0, w0 = time.process_time(), time.perf_counter()
        fe.Update()
        fe_times.append(time.process_time() - t0)
        fe_wall = time.perf_counter() - w0
        triangles = fe.GetOutput().GetNumberOfCells()
    flying = {"cpu_seconds_median": statistics.median(fe_times), "wall_seconds_last": fe_wall, "triangles": triangles}
    print(json.dumps({"vtkFlyingEdges3D": flying}))

    phantom = run_json([bench, "phantom", str(a.phantom)])
    print(json.dumps({"phantom": phantom}))
    print(json.dumps({
        "summary": True,
        "load": open("/proc/loadavg").read().split()[:3],
        "contour_update_cpu_ms": {"ours_median": ours["update_cpu_ms_median"], "ours_p95": ours["update_cpu_ms_p95"],
                                  "ours_max": ours["update_cpu_ms_max"], "vtk_median": vtk_paths["update_cpu_ms_median"],
                                  "vtk_p95": vtk_paths["update_cpu_ms_p95"], "vtk_max": vtk_paths["update_cpu_ms_max"]},
        "preview_per_hover_cpu_ms": {
            "head_ct": {k: ours["preview"][k] for k in ("closed_hovers", "cpu_ms_median", "cpu_ms_p95", "cpu_ms_max",
                                                        "from_scratch_cpu_ms_median", "mismatches")},
            f"phantom_{a.phantom}": {k: phantom["preview"][k] for k in ("closed_hovers", "cpu_ms_median", "cpu_ms_p95",
                                                                       "cpu_ms_max", "from_scratch_cpu_ms_median",
                                                                       "mismatches")}},
        "after_last_point_cpu_seconds": {"head_ct": ours["after_last_point_cpu_seconds"],
                                         f"phantom_{a.phantom}": phantom["after_last_point_cpu_seconds"]},
        "extraction_cpu_seconds": {"ours": ours["extract_cpu_seconds_median"],
                                   "vtkFlyingEdges3D": flying["cpu_seconds_median"],
                                   "ours_over_vtk": ours["extract_cpu_seconds_median"] / flying["cpu_seconds_median"],
                                   "triangles_ours": ours["all_triangles"], "triangles_vtk": flying["triangles"]},
    }))


if __name__ == "__main__":
    main()
