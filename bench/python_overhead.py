#!/usr/bin/python3
"""Binding overhead: the same trace / live-wire map from Python and from C++, alternated round by round.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py [BUILD] [--rounds N]

trace: `volscissors trace --json` reports the seconds of its core calls (features, graph, search);
the Python figure is the whole vs.trace() call on an already loaded volume (it also converts to
float and estimates radii per path voxel, which the CLI counts under load/output: a conservative
comparison). live-wire: bench_livewire's BM_FeaturesAndCosts and BM_FullMap (C++, Google
Benchmark) against LiveWire(...) and set_seed + build_map from Python on the same 2D image.
Prints per-round medians and the ratio Python / C++ (1.05 = 5 % overhead).
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


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("build", nargs="?", default=os.path.join(ROOT, "build"))
    ap.add_argument("--rounds", type=int, default=5)
    a = ap.parse_args()
    sys.path.insert(0, os.path.join(a.build, "python"))
    import volscissors as vs

    cli = os.path.join(a.build, "volscissors")
    tmp = tempfile.mkdtemp(prefix="vs_bench_py_")
    data = os.path.join(ROOT, "..", "shared", "data", "chest_cta_totalseg", "ct_cropped.nii.gz")
    if os.path.exists(data):
        ct, name = data, "chest_cta_totalseg 120x126x164, airways, 3 auto terminals"
        args = dict(root=(46, 59, 150), auto_terminals=3, min_length_mm=20, cost="intensity", polarity="dark",
                    window=(-1000, -950), smooth_mm=0)
        cli_args = ["--root", "46,59,150", "--auto-terminals", "3", "--min-length", "20", "--cost", "intensity",
                    "--polarity", "dark", "--window", "-1000,-950", "--smooth", "0"]
    else:
        ct, name = os.path.join(tmp, "vessels.nii.gz"), "vessel phantom 128^3, 3 auto terminals"
        subprocess.run([cli, "-q", "phantom", "vessels", "--seed", "1", "--out", ct], check=True)
        args = dict(root=(64, 64, 10), auto_terminals=3)
        cli_args = ["--root", "64,64,10", "--auto-terminals", "3"]
    volume = vs.read(ct)
    py_t, cpp_t = [], []
    for _ in range(a.rounds):
        rep = os.path.join(tmp, "trace.json")
        subprocess.run([cli, "-q", "trace", ct, *cli_args, "--json", rep], check=True, capture_output=True)
        s = json.load(open(rep))["seconds"]
        cpp_t.append(s["features"] + s["graph"] + s["search"])
        t = time.perf_counter()
        vs.trace(volume, **args)
        py_t.append(time.perf_counter() - t)
    py, cpp = statistics.median(py_t), statistics.median(cpp_t)
    print(f"trace ({name}): python {py:.3f} s, C++ {cpp:.3f} s, ratio {py / cpp:.3f}")

    bench = os.path.join(a.build, "bench_livewire")
    if not os.path.exists(bench):
        print("live-wire: bench_livewire not built (cmake --build build --target bench_livewire)")
        return
    img = os.path.join(tmp, "shapes.nii.gz")
    subprocess.run([cli, "-q", "phantom", "shapes2d", "--seed", "1", "--size", "512,512", "--out", img], check=True)
    seed = (100, 100)
    env = dict(os.environ, VS_BENCH_IMAGE=img, VS_BENCH_SEED=f"{seed[0]},{seed[1]}", VS_BENCH_TARGETS="300,300")
    image = vs.read(img)
    py_build, py_map, cpp_build, cpp_map = [], [], [], []
    for _ in range(a.rounds):
        out = subprocess.run([bench, "--benchmark_filter=BM_FeaturesAndCosts|BM_FullMap", "--benchmark_format=json",
                              "--benchmark_min_time=0.5"], check=True, capture_output=True, text=True, env=env).stdout
        res = {b["name"].split("/")[0]: b["real_time"] / 1000.0 for b in json.loads(out)["benchmarks"]}
        cpp_build.append(res["BM_FeaturesAndCosts"])
        cpp_map.append(res["BM_FullMap"])
        t = time.perf_counter()
        lw = vs.LiveWire(image)
        py_build.append(time.perf_counter() - t)
        maps = []
        for i in range(6):
            t = time.perf_counter()
            lw.set_seed((seed[0] + i % 2, seed[1]))  # a different seed: the search starts from scratch
            lw.build_map()
            maps.append(time.perf_counter() - t)
        py_map.append(statistics.median(maps))
    for label, p, c in (("live-wire features+costs", py_build, cpp_build), ("live-wire full map", py_map, cpp_map)):
        p, c = statistics.median(p), statistics.median(c)
        print(f"{label} (512x512): python {p * 1000:.1f} ms, C++ {c * 1000:.1f} ms, ratio {p / c:.3f}")


if __name__ == "__main__":
    main()
