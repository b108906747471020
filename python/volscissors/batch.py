"""Cohort runner: one volscissors operation per case of a CSV, on Dask distributed.

    python3 -m volscissors.batch cases.csv --op trace --out DIR [--scheduler ADDRESS] [--workers N]

cases.csv has a header row. Column ``path`` (required) is the volume (relative paths are taken
from the CSV's folder); ``case`` names the case (default: the row number). The other columns are
the operation's parameters, empty cells taking the defaults:

  trace:     root ("x y z" or "x,y,z"), targets ("x,y,z;x,y,z;..."), auto_terminals, min_length_mm,
             cost, polarity, window ("lo,hi"), smooth_mm, power, snap_mm, refine (0/1), connectivity,
             prune, full (0/1), world (0/1) (the defaults of volscissors.trace, i.e. of the CLI)
  measure:   the trace columns, then Tree.measure: step_mm, rays, lumen (auto|bright|dark); the
             record adds the measure summary and each path's mean/min diameter
  livewire:  points ("u,v;u,v;..."), slice ("z=40"), closed (0/1), cost, smooth_mm, snap

Each case writes DIR/<case>.json (inputs with size and SHA-256, parameters, version, timings, peak
RSS of the worker process, outcome, error if any) and its output (trace, measure: DIR/<case>.swc; livewire:
DIR/<case>.contour.json); DIR/summary.csv has one row per case. A failing case (missing or corrupt
file, unreachable target, a crashed worker) is an error row and never stops the cohort. A rerun
skips the cases already finished with the same input file and parameters. Exit status: 0 when
every case succeeded, 1 when some failed, 2 for a bad command line or CSV.
A local cluster (--workers processes, one thread each) is started unless --scheduler gives the
address of a running Dask scheduler (e.g. tcp://head:8786), whose workers must import volscissors.
"""

import argparse
import csv
import hashlib
import json
import os
import platform
import resource
import sys
import tempfile
import time

OPS = {
    "trace": {
        "root": "triple", "targets": "triples", "auto_terminals": int, "min_length_mm": float,
        "cost": str, "polarity": str, "window": "pair", "smooth_mm": float, "power": float,
        "snap_mm": float, "refine": "bool", "connectivity": int, "prune": str, "full": "bool", "world": "bool",
    },
    # trace, then quantify the tree (Tree.measure): the trace columns plus the measure options
    "measure": {
        "root": "triple", "targets": "triples", "auto_terminals": int, "min_length_mm": float,
        "cost": str, "polarity": str, "window": "pair", "smooth_mm": float, "power": float,
        "snap_mm": float, "refine": "bool", "connectivity": int, "prune": str, "full": "bool", "world": "bool",
        "step_mm": float, "rays": int, "lumen": str,
    },
    "livewire": {
        "points": "pairs", "slice": str, "closed": "bool", "cost": str, "smooth_mm": float, "snap": float,
    },
}


class CaseError(ValueError):
    """A malformed CSV cell (reported as that case's error)."""


def _numbers(text, what):
    try:
        return [float(x) for x in text.replace(",", " ").split()]
    except ValueError:
        raise CaseError(f"{what}: '{text}' is not a list of numbers") from None


def _parse_cell(kind, text, what):
    if kind == "triple" or kind == "pair":
        n = 3 if kind == "triple" else 2
        v = _numbers(text, what)
        if len(v) != n:
            raise CaseError(f"{what}: expected {n} numbers, got '{text}'")
        return v
    if kind in ("triples", "pairs"):
        n = 3 if kind == "triples" else 2
        out = []
        for item in text.split(";"):
            if item.strip():
                out.append(_parse_cell("triple" if n == 3 else "pair", item, what))
        return out
    if kind == "bool":
        if text.strip().lower() not in ("0", "1", "true", "false", "yes", "no"):
            raise CaseError(f"{what}: expected 0/1, got '{text}'")
        return text.strip().lower() in ("1", "true", "yes")
    try:
        return kind(text.strip())
    except ValueError:
        raise CaseError(f"{what}: cannot read '{text}' as {kind.__name__}") from None


def case_files(case, op):
    """The files a case writes in the output folder (its record and its output)."""
    return [f"{case}.json", f"{case}.swc" if op == "trace" else f"{case}.contour.json"]


def read_cases(csv_path, op):
    """Rows of the CSV as (case, volume path, raw parameter dict); raises ValueError on a bad header."""
    base = os.path.dirname(os.path.abspath(csv_path))
    with open(csv_path, newline="") as f:
        reader = csv.DictReader(f)
        if not reader.fieldnames or "path" not in reader.fieldnames:
            raise ValueError(f"{csv_path}: the header must have a 'path' column")
        unknown = [c for c in reader.fieldnames if c not in ("case", "path") and c not in OPS[op]]
        if unknown:
            raise ValueError(f"{csv_path}: unknown column(s) for --op {op}: {', '.join(unknown)} "
                             f"(known: case, path, {', '.join(OPS[op])})")
        cases, seen, files = [], set(), {"summary.csv": "the cohort summary"}
        for i, row in enumerate(reader, start=1):
            if None in row or any(v is None for v in row.values()):
                cells = len(reader.fieldnames) + len(row.get(None) or []) - sum(v is None for v in row.values())
                raise ValueError(f"{csv_path} row {i}: {cells} cells, but the header has {len(reader.fieldnames)} "
                                 f"columns (a ragged row: a missing or extra comma?)")
            case = (row.get("case") or "").strip() or f"case{i:04d}"
            if not all(c.isalnum() or c in "-_." for c in case) or case.startswith("."):
                raise ValueError(f"{csv_path} row {i}: case name '{case}' must be letters, digits, '-', '_', '.'")
            if case in seen:
                raise ValueError(f"{csv_path} row {i}: case '{case}' appears twice")
            seen.add(case)
            # Each case's files must be its own: cases 'a' and 'a.contour' would both write
            # a.contour.json.
            for name in case_files(case, op):
                if name in files:
                    raise ValueError(f"{csv_path} row {i}: case '{case}' would write {name}, which belongs to "
                                     f"{files[name]}; rename one of them")
                files[name] = f"case '{case}'"
            path = (row.get("path") or "").strip()
            if not path:
                raise ValueError(f"{csv_path} row {i}: empty path")
            params = {k: v for k, v in row.items() if k not in ("case", "path") and v is not None and v.strip()}
            cases.append((case, path if os.path.isabs(path) else os.path.join(base, path), params))
    return cases


def _fingerprint(op, path, params):
    """Identifies a finished case: operation, parameters and the input file's size and mtime."""
    try:
        st = os.stat(path)
        stamp = [st.st_size, st.st_mtime_ns]
    except OSError:
        stamp = None
    text = json.dumps([op, os.path.abspath(path), stamp, params], sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _sha256(path):
    if os.path.isdir(path):
        return None
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _write_atomically(path, text):
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(path), prefix=".tmp-", suffix=os.path.basename(path))
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def run_case(op, case, path, params, out_dir, fingerprint):
    """Runs one case in a worker and writes its record; never raises (errors become the record)."""
    record = {
        "case": case, "op": op, "status": "error", "fingerprint": fingerprint,
        "input": {"path": path}, "params": params, "host": platform.node(), "pid": os.getpid(),
        "started": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "started_unix": time.time(),
        "seconds": {}, "outputs": [],
    }
    t0 = time.perf_counter()
    try:
        import volscissors as vs

        record["volscissors_version"] = vs.__version__
        kinds = OPS[op]
        args = {k: _parse_cell(kinds[k], v, k) for k, v in params.items()}
        record["input"]["bytes"] = os.path.getsize(path) if os.path.isfile(path) else None
        record["input"]["sha256"] = _sha256(path) if os.path.exists(path) else None
        t = time.perf_counter()
        volume = vs.read(path)
        record["seconds"]["read"] = time.perf_counter() - t
        record["input"]["dims"] = list(volume.dims)
        record["input"]["spacing"] = list(volume.spacing)
        t = time.perf_counter()
        if op in ("trace", "measure"):
            if "root" not in args:
                raise CaseError(f"{op} needs a 'root' column")
            measure_args = {k: args.pop(k) for k in ("step_mm", "rays") if k in args}
            if "lumen" in args:
                measure_args["polarity"] = args.pop("lumen")
            tree = vs.trace(volume, **args)
            summary = tree.measure(volume, **measure_args) if op == "measure" else None
            out = os.path.join(out_dir, case + ".swc")
            tree.save(out)
            record["outputs"].append(os.path.basename(out))
            record["result"] = {
                "root": list(tree.root), "requested_root": list(tree.requested_root), "cost": tree.cost,
                "cost_estimate": tree.cost_estimate, "notes": list(tree.notes),
                "branch_points": len(tree.branch_points),
                "paths": [{"target": list(p.target), "cost": p.cost, "length_mm": p.length_mm,
                           "voxels": len(p.voxels), "parent": p.parent} for p in tree.paths],
                "total_length_mm": sum(p.length_mm for p in tree.paths),
                "settled": tree.stats["settled"],
            }
            if summary is not None:
                record["result"]["measure"] = summary
                for p, rp in zip(tree.paths, record["result"]["paths"]):
                    d = p.profile["diameter_mm"]
                    ok = d[d == d]
                    rp["mean_diameter_mm"] = float(ok.mean()) if ok.size else None
                    rp["min_diameter_mm"] = float(ok.min()) if ok.size else None
        else:
            if "points" not in args:
                raise CaseError("livewire needs a 'points' column")
            c = vs.livewire(volume, **args)
            out = os.path.join(out_dir, case + ".contour.json")
            _write_atomically(out, json.dumps({
                "slice": c.slice, "closed": c.closed, "points": c.pixels.tolist(),
                "points_index": c.index.tolist(), "points_world": c.world.tolist(),
                "length_mm": c.length_mm, "cost": c.cost}) + "\n")
            record["outputs"].append(os.path.basename(out))
            record["result"] = {"slice": c.slice, "pixels": len(c), "length_mm": c.length_mm, "cost": c.cost,
                                "area_mm2": c.area_mm2}
        record["seconds"]["op"] = time.perf_counter() - t
        record["status"] = "ok"
    except BaseException as e:  # a case never stops the cohort (KeyboardInterrupt included)
        record["error"] = {"type": type(e).__name__, "message": str(e)}
    record["seconds"]["total"] = time.perf_counter() - t0
    record["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    _write_atomically(os.path.join(out_dir, case + ".json"), json.dumps(record, indent=1) + "\n")
    return record


def _summary_row(record):
    result = record.get("result") or {}
    error = record.get("error") or {}
    return {
        "case": record["case"], "status": record["status"], "skipped": record.get("skipped", False),
        "seconds": round(record.get("seconds", {}).get("total", 0.0), 3),
        "paths": len(result.get("paths", [])) if "paths" in result else "",
        "length_mm": round(result.get("total_length_mm", result.get("length_mm", 0.0)), 3) if result else "",
        "error": f"{error.get('type', '')}: {error.get('message', '')}" if error else "",
        "record": record["case"] + ".json",
    }


def _finished(out_dir, case, fingerprint):
    try:
        with open(os.path.join(out_dir, case + ".json")) as f:
            rec = json.load(f)
    except (OSError, ValueError):
        return None
    if rec.get("status") == "ok" and rec.get("fingerprint") == fingerprint and all(
            os.path.exists(os.path.join(out_dir, o)) for o in rec.get("outputs", [])):
        return rec
    return None


def run_cohort(csv_path, op, out_dir, scheduler=None, workers=2, log=print):
    """Runs every case; returns the list of records (in CSV order)."""
    from dask.distributed import Client, LocalCluster, as_completed

    cases = read_cases(csv_path, op)
    os.makedirs(out_dir, exist_ok=True)
    records, todo = {}, []
    for case, path, params in cases:
        fp = _fingerprint(op, path, params)
        done = _finished(out_dir, case, fp)
        if done:
            done["skipped"] = True
            records[case] = done
        else:
            todo.append((case, path, params, fp))
    log(f"batch: {len(cases)} cases, {len(cases) - len(todo)} already finished, {len(todo)} to run")
    if todo:
        cluster = None
        if scheduler:
            client = Client(scheduler)
        else:
            # Each worker process runs one case at a time; the core's threads share the cores.
            os.environ.setdefault("VS_THREADS", str(max(1, (os.cpu_count() or 1) // workers)))
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None, silence_logs=40)
            client = Client(cluster)
        try:
            futures = {client.submit(run_case, op, case, path, params, os.path.abspath(out_dir), fp,
                                     key=f"volscissors-{op}-{case}-{fp}", pure=False, retries=0): case
                       for case, path, params, fp in todo}
            for future in as_completed(futures):
                case = futures[future]
                try:
                    rec = future.result()
                except BaseException as e:  # the worker died (crash, memory): record it here
                    path = next(p for c, p, _, _ in todo if c == case)
                    rec = {"case": case, "op": op, "status": "error", "input": {"path": path},
                           "error": {"type": type(e).__name__, "message": str(e)}, "seconds": {}, "outputs": []}
                    _write_atomically(os.path.join(out_dir, case + ".json"), json.dumps(rec, indent=1) + "\n")
                records[case] = rec
                err = rec.get("error")
                log(f"  {case}: {rec['status']}" + (f" ({err['type']}: {err['message']})" if err else
                                                    f" in {rec['seconds'].get('total', 0):.2f} s"))
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    ordered = [records[case] for case, _, _ in cases]
    fields = ["case", "status", "skipped", "seconds", "paths", "length_mm", "error", "record"]
    with tempfile.NamedTemporaryFile("w", dir=out_dir, prefix=".tmp-", suffix=".csv", delete=False, newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        for rec in ordered:
            w.writerow(_summary_row(rec))
    os.replace(f.name, os.path.join(out_dir, "summary.csv"))
    return ordered


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python3 -m volscissors.batch", description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 2)[2])
    ap.add_argument("cases", help="CSV of cases (columns: case, path, then the operation's parameters)")
    ap.add_argument("--op", choices=sorted(OPS), default="trace", help="operation per case (default: trace)")
    ap.add_argument("--out", required=True, help="output folder: <case>.json records, outputs, summary.csv")
    ap.add_argument("--scheduler", help="address of a running Dask scheduler (default: a local cluster)")
    ap.add_argument("--workers", type=int, default=2, help="local cluster worker processes (default: 2)")
    a = ap.parse_args(argv)
    if a.workers < 1:
        ap.error("--workers must be >= 1")
    try:
        records = run_cohort(a.cases, a.op, a.out, a.scheduler, a.workers)
    except (OSError, ValueError) as e:
        print(f"batch: {e}", file=sys.stderr)
        return 2
    failed = [r["case"] for r in records if r["status"] != "ok"]
    print(f"batch: {len(records) - len(failed)} ok, {len(failed)} failed -> {os.path.join(a.out, 'summary.csv')}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
