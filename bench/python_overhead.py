#!/usr/bin/python3
"""Binding overhead: the same trace / live-wire map from Python and from C++, alternated round by round.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py [BUILD] [--rounds N] [--calls K]

Needs `cmake --build build --target volscissors_python bench_python_overhead`.
trace: vs.trace(volume, root, targets) with every option at its default (the CLI's: auto cost,
snapping, refinement) on a float32 Volume already in memory, against bench_python_overhead's
BM_Trace, which runs the same core pipeline (tracking/trace_run.h) on the same float32 volume.
live-wire: LiveWire.set_seed + build_map against BM_LiveWireMap on the same 512x512 image.
Both sides are timed per call, in wall time and in CPU time of the process (CPU time is what the
other users of a shared machine disturb least); rounds alternate C++ and Python. Prints the
medians and the ratios Python / C++ (1.05 = 5 % overhead).
--callgrind: instead, instructions per call from valgrind's callgrind, which no load disturbs:
each side runs 1 + K calls and 1 call, and the difference / K is the per-call count (so process
start, imports, reading and the warm-up call cancel out).
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


def cpp_round(bench, name, calls, env):
    """Per-call (wall, cpu) seconds of one Google Benchmark run of `name` with `calls` iterations."""
    out = subprocess.run([bench, f"--benchmark_filter=^{name}/", "--benchmark_format=json"], check=True,
                         capture_output=True, text=True, env=dict(env, VS_BENCH_CALLS=str(calls))).stdout
    b = json.loads(out)["benchmarks"][0]
    scale = {"ms": 1e-3, "us": 1e-6, "ns": 1e-9, "s": 1.0}[b["time_unit"]]
    return b["real_time"] * scale, b["cpu_time"] * scale


def py_round(fn, calls):
    wall, cpu = [], []
    for _ in range(calls):
        w, c = time.perf_counter(), time.process_time()
        fn()
        cpu.append(time.process_time() - c)
        wall.append(time.perf_counter() - w)
    return statistics.fmean(wall), statistics.fmean(cpu)


def instructions(cmd, env):
    """Instructions (Ir) of a whole process under callgrind."""
    out = tempfile.mktemp(prefix="vs_cg_")
    subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", *cmd], check=True,
                   capture_output=True, env=env)
    for line in open(out):
        if line.startswith("summary:") or line.startswith("totals:"):
            n = int(line.split()[1])
    os.unlink(out)
    return n


PY_DRIVER = """
import sys, json, volscissors as vs
what, n = sys.argv[1], int(sys.argv[2])
if what == "trace":
    t = json.load(open(sys.argv[4]))
    v = vs.Volume(vs.read(sys.argv[3]).array, dtype="float32")
    for _ in range(n):
        vs.trace(v, root=t["root_voxel"], targets=[x["voxel"] for x in t["terminals"][:4]])
else:
    lw = vs.LiveWire(vs.read(sys.argv[3]))
    for i in range(n):
        lw.set_seed((100 + i % 2, 100))
        lw.build_map()
"""


def callgrind(label, bench, name, env, py_args, k):
    py_env = dict(env, PYTHONPATH=os.pathsep.join(sys.path))
    cpp = [instructions([bench, f"--benchmark_filter=^{name}/"], dict(env, VS_BENCH_CALLS=str(c))) for c in (k + 1, 1)]
    py = [instructions([sys.executable, "-c", PY_DRIVER, *py_args[:1], str(c), *py_args[1:]], py_env)
          for c in (k + 1, 1)]
    c, p = (cpp[0] - cpp[1]) / k, (py[0] - py[1]) / k
    print(f"{label} [instructions per call]: python {p / 1e6:.2f} M, C++ {c / 1e6:.2f} M, ratio {p / c:.4f}")


def compare(label, bench, name, env, fn, rounds, calls):
    cpp, py = [], []
    fn()  # warm-up (first-touch page faults, lazy imports)
    for _ in range(rounds):
        cpp.append(cpp_round(bench, name, calls, env))
        py.append(py_round(fn, calls))
    for i, kind in enumerate(("wall", "cpu")):
        c = statistics.median(x[i] for x in cpp)
        p = statistics.median(x[i] for x in py)
        print(f"{label} [{kind}]: python {p * 1000:.2f} ms, C++ {c * 1000:.2f} ms, ratio {p / c:.4f} "
              f"(rounds: {', '.join(f'{x[i] / y[i]:.3f}' for x, y in zip(py, cpp))})")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("build", nargs="?", default=os.path.join(ROOT, "build"))
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--calls", type=int, default=5, help="calls per round and side")
    ap.add_argument("--callgrind", action="store_true", help="count instructions instead of timing")
    a = ap.parse_args()
    sys.path.insert(0, os.path.join(a.build, "python"))
    import volscissors as vs

    cli = os.path.join(a.build, "volscissors")
    bench = os.path.join(a.build, "bench_python_overhead")
    if not os.path.exists(bench):
        sys.exit("build bench_python_overhead first (cmake --build build --target bench_python_overhead)")
    tmp = tempfile.mkdtemp(prefix="vs_bench_py_")
    print(f"load: {os.getloadavg()}")

    # trace: a vessel phantom, root and four terminals from its truth.
    vol_path, truth_path = os.path.join(tmp, "vessels.nii.gz"), os.path.join(tmp, "vessels.json")
    subprocess.run([cli, "-q", "phantom", "vessels", "--seed", "2", "--size", "96,96,96", "--out", vol_path,
                    "--truth", truth_path], check=True)
    truth = json.load(open(truth_path))
    root = truth["root_voxel"]
    targets = [t["voxel"] for t in truth["terminals"][:4]]
    volume = vs.Volume(vs.read(vol_path).array, dtype="float32")  # the C++ side traces float32 too
    env = dict(os.environ, VS_BENCH_VOLUME=vol_path, VS_BENCH_ROOT=",".join(map(str, root)),
               VS_BENCH_TARGETS=";".join(",".join(map(str, t)) for t in targets))
    label = "trace (vessel phantom 96^3, 4 targets, defaults)"
    if a.callgrind:
        callgrind(label, bench, "BM_Trace", env, ["trace", vol_path, truth_path], a.calls)
    else:
        compare(label, bench, "BM_Trace", env, lambda: vs.trace(volume, root=root, targets=targets), a.rounds,
                a.calls)

    # live-wire: the full map on a 512x512 image.
    img = os.path.join(tmp, "shapes.nii.gz")
    subprocess.run([cli, "-q", "phantom", "shapes2d", "--seed", "1", "--size", "512,512", "--out", img], check=True)
    image = vs.read(img)
    seed = (100, 100)
    lw = vs.LiveWire(image)
    state = [0]

    def live_map():
        lw.set_seed((seed[0] + state[0] % 2, seed[1]))  # a different seed: the search starts from scratch
        state[0] += 1
        lw.build_map()

    env = dict(os.environ, VS_BENCH_IMAGE=img, VS_BENCH_SEED=f"{seed[0]},{seed[1]}")
    if a.callgrind:
        callgrind("live-wire full map (512x512)", bench, "BM_LiveWireMap", env, ["livewire", img], a.calls * 4)
    else:
        compare("live-wire full map (512x512)", bench, "BM_LiveWireMap", env, live_map, a.rounds, a.calls * 4)
    print(f"load: {os.getloadavg()}")


if __name__ == "__main__":
    main()
