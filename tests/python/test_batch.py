"""The cohort runner on a two-worker local Dask cluster: records, failure isolation, resume."""
import csv
import json
import os
import shutil
import subprocess
import sys

import pytest

import volscissors as vs
from conftest import DATA, cli


@pytest.fixture(scope="module")
def cohort(tmp_path_factory):
    """Three phantoms, the small shared volumes when present, a corrupt file and a missing one."""
    d = tmp_path_factory.mktemp("cohort")
    rows = []
    for seed in (1, 2, 3):
        path = d / f"phantom{seed}.nii.gz"
        truth = d / f"phantom{seed}.json"
        cli("phantom", "vessels", "--seed", seed, "--size", "48,48,48", "--out", path, "--truth", truth)
        t = json.load(open(truth))
        rows.append({"case": f"phantom{seed}", "path": path.name, "root": " ".join(map(str, t["root_voxel"])),
                     "targets": ";".join(",".join(map(str, x["voxel"])) for x in t["terminals"][:3]),
                     "auto_terminals": ""})
    carotid = os.path.join(DATA, "neck_mra_carotid_vtk", "carotid.vtk")
    if os.path.exists(carotid):  # real data: auto terminals from a root in the carotid
        rows.append({"case": "carotid", "path": os.path.abspath(carotid), "root": "52,24,3", "targets": "",
                     "auto_terminals": "2", "cost": "intensity"})
    good = d / "phantom1.nii.gz"
    data = good.read_bytes()
    (d / "corrupt.nii.gz").write_bytes(data[:len(data) // 3])  # truncated
    rows.append({"case": "corrupt", "path": "corrupt.nii.gz", "root": "1,1,1", "targets": "5,5,5",
                 "auto_terminals": ""})
    rows.append({"case": "missing", "path": "nowhere.nii.gz", "root": "1,1,1", "targets": "5,5,5",
                 "auto_terminals": ""})
    with open(d / "cases.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["case", "path", "root", "targets", "auto_terminals", "cost"], restval="")
        w.writeheader()
        w.writerows(rows)
    return d, rows


def _run(csv_path, out):
    env = dict(os.environ)
    return subprocess.run([sys.executable, "-m", "volscissors.batch", str(csv_path), "--op", "trace", "--out", str(out),
                           "--workers", "2"], capture_output=True, text=True, env=env, timeout=300)


def test_cohort_isolates_failures_and_resumes(cohort, tmp_path):
    d, rows = cohort
    out = tmp_path / "out"
    r = _run(d / "cases.csv", out)
    assert r.returncode == 1, r.stdout + r.stderr  # some cases failed, none crashed the run
    summary = {row["case"]: row for row in csv.DictReader(open(out / "summary.csv"))}
    assert list(summary) == [row["case"] for row in rows]
    assert summary["corrupt"]["status"] == "error" and "OSError" in summary["corrupt"]["error"]
    assert summary["missing"]["status"] == "error" and "FileNotFoundError" in summary["missing"]["error"]
    ok = [row for row in rows if row["case"] not in ("corrupt", "missing")]
    assert all(summary[row["case"]]["status"] == "ok" for row in ok)

    # Records: provenance and the same paths as a direct call.
    rec = json.load(open(out / "phantom2.json"))
    assert rec["status"] == "ok" and len(rec["input"]["sha256"]) == 64 and rec["volscissors_version"]
    assert rec["peak_rss_mb"] > 0 and rec["seconds"]["total"] > 0
    row = next(x for x in rows if x["case"] == "phantom2")
    direct = vs.trace(vs.read(str(d / row["path"])), root=[int(c) for c in row["root"].split()],
                      targets=[[int(c) for c in t.split(",")] for t in row["targets"].split(";")])
    assert [p["length_mm"] for p in rec["result"]["paths"]] == pytest.approx([p.length_mm for p in direct.paths])
    assert os.path.getsize(out / "phantom2.swc") > 0
    assert not (out / "corrupt.swc").exists()

    # A rerun skips the finished cases and retries the failed ones.
    (out / "phantom1.json").unlink()  # as if that case had been interrupted
    r2 = _run(d / "cases.csv", out)
    assert r2.returncode == 1
    again = {row["case"]: row for row in csv.DictReader(open(out / "summary.csv"))}
    assert again["phantom1"]["skipped"] == "False" and again["phantom1"]["status"] == "ok"
    assert all(again[x["case"]]["skipped"] == "True" for x in ok if x["case"] != "phantom1")
    assert again["corrupt"]["skipped"] == "False" and again["corrupt"]["status"] == "error"


def test_bad_csv_is_a_usage_error(tmp_path):
    bad = tmp_path / "cases.csv"
    bad.write_text("case,path,colour\na,x.nii.gz,red\n")
    r = _run(bad, tmp_path / "out")
    assert r.returncode == 2 and "unknown column" in r.stderr
    shutil.rmtree(tmp_path / "out", ignore_errors=True)


def test_ragged_rows_and_colliding_case_files_are_csv_errors(tmp_path):
    from volscissors.batch import read_cases

    vol = tmp_path / "v.nii"
    vol.write_bytes(b"")
    for text, match in [(f"case,path,auto_terminals\na,{vol},1,EXTRA\n", "ragged"),
                        ("case,path,auto_terminals\na\n", "ragged")]:
        f = tmp_path / "c.csv"
        f.write_text(text)
        with pytest.raises(ValueError, match=match):
            read_cases(str(f), "trace")
    f = tmp_path / "lw.csv"
    f.write_text(f"case,path,points,slice\na,{vol},1 1;5 5,z=3\na.contour,{vol},1 1;5 5,z=3\n")
    with pytest.raises(ValueError, match="a.contour.json"):
        read_cases(str(f), "livewire")
