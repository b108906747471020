"""Tree.measure: the CLI's quantification (volscissors measure) on a traced tree, profiles as NumPy arrays."""
import json

import numpy as np
import pytest

import volscissors as vs
from conftest import cli


def test_profiles_and_summary_match_the_cli(vessels, tmp_path):
    path, truth = vessels
    root = truth["root_voxel"]
    targets = [t["voxel"] for t in truth["terminals"][:3]]
    volume = vs.read(path)
    tree = vs.trace(volume, root, targets)
    assert all(p.profile is None for p in tree.paths)
    summary = tree.measure(volume)
    assert summary["polarity"] == "bright"
    assert summary["sections"]["measured"] > 0
    for p in tree.paths:
        prof = p.profile
        n = len(prof["arc_mm"])
        assert n > 0
        assert prof["centre_mm"].shape == (n, 3)
        assert np.all(np.diff(prof["arc_mm"]) > 0)
        measured = prof["flags"] == 0
        assert measured.any()
        assert np.all(np.isfinite(prof["diameter_mm"][measured]))
        assert np.all(np.isnan(prof["diameter_mm"][~measured]))
        assert np.all(prof["min_diameter_mm"][measured] <= prof["max_diameter_mm"][measured] + 1e-9)
    # The same numbers as `volscissors measure` on the saved tree.
    swc = tmp_path / "t.swc"
    tree.save(str(swc))
    out = tmp_path / "m.json"
    cli("-q", "measure", swc, path, "--json", out)
    rep = json.load(open(out))["measure"]
    assert rep["sections"] == summary["sections"]
    assert len(rep["paths"]) == len(summary["paths"])
    for a, b in zip(rep["paths"], summary["paths"]):
        assert a["length_mm"] == pytest.approx(b["length_mm"], rel=1e-6)


def test_bad_polarity_is_a_value_error(vessels):
    path, truth = vessels
    volume = vs.read(path)
    tree = vs.trace(volume, truth["root_voxel"], [truth["terminals"][0]["voxel"]])
    with pytest.raises(ValueError):
        tree.measure(volume, polarity="purple")


def test_cohort_runner_op_measure(vessels, tmp_path):
    from volscissors.batch import run_case
    path, truth = vessels
    params = {"root": " ".join(map(str, truth["root_voxel"])),
              "targets": ";".join(",".join(map(str, t["voxel"])) for t in truth["terminals"][:2]), "step_mm": "1"}
    rec = run_case("measure", "c1", path, params, str(tmp_path), "fp")
    assert rec["status"] == "ok", rec.get("error")
    assert rec["result"]["measure"]["step_mm"] == 1.0
    assert all(p["mean_diameter_mm"] > 0 for p in rec["result"]["paths"])
    assert (tmp_path / "c1.swc").exists() and (tmp_path / "c1.json").exists()
