#!/usr/bin/python3
"""Readers, outputs and front ends under real-world and bad input (issue 22). Prints totals per class.

  bench/reader_campaign.py [--cli build/volscissors] [--python build/python] [--seed 22] [--random 40]

Generated here, in a private temporary folder (nothing from elsewhere is copied in):
- DICOM series written with pydicom at known geometry: the fixed fixtures of
  tests/io/dicom_fixtures.py plus --random series at random orientations, slice steps,
  gantry tilts and pixel spacings, read with `info --json` and compared with the geometry
  they were written with;
- every file of nibabel's and pydicom's test data read with `info --json`, compared with
  nibabel's / pydicom's reading (dims, spacing, origin, direction, value range), or refused
  with a message naming the file;
- NIfTI files written with nibabel with random sform/qform codes and matrices, units, scl_slope
  0/NaN/random, 2D images, float32 near-orthonormal sforms and negative pixdim;
- outputs that are a FIFO, a character device (when mknod is allowed), a symbolic link to
  /dev/full, to a regular file and a dangling one, for info, convert, render, phantom;
- Python: Volume(dtype=...) with values the type cannot hold, non-orthonormal directions,
  trace(auto_terminals=2**40), the cohort runner with ragged rows and colliding case names;
- phantom with absurd spacing; SIGTERM to long commands (the first signal must end the
  command within a second with exit 130, no output, no temporary).

Classes (besides those of bench/reliability_campaign.py, whose helpers are reused):
  wrong      data read with exit 0 that differs from the reference / the written geometry
  replaced   an output path that was not a regular file (device, FIFO, symlink) was replaced
  slow       the first SIGTERM did not end the command within 1.5 s (1 s plus start-up slack)
  traceback  a Python front end raised an unexpected exception type or printed a traceback
"""
import argparse
import glob
import json
import math
import os
import random
import signal
import stat
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests" / "io"))
import reliability_campaign as rc  # noqa: E402

for k in ["wrong", "replaced", "slow", "traceback"]:
    rc.COUNTS[k] = 0


def info_json(cli, path, d, timeout=30):
    out = d / "info.json"
    if out.exists():
        out.unlink()
    code, err, _ = rc.run(cli, ["info", str(path), "--json", str(out)], timeout, d)
    data = json.loads(out.read_text()) if code == 0 and out.exists() else None
    return code, err, data


def close(a, b, tol):
    return len(a) == len(b) and all(abs(float(x) - float(y)) <= tol * max(1.0, abs(float(y))) for x, y in zip(a, b))


def compare(case, data, dims, spacing, origin, direction, tol=1e-4):
    bad = []
    if list(data["dims"]) != list(dims):
        bad.append(f"dims {data['dims']} != {list(dims)}")
    if not close(data["spacing"], spacing, tol):
        bad.append(f"spacing {data['spacing']} != {list(spacing)}")
    if origin is not None and not close(data["origin"], origin, max(tol, 1e-3)):
        bad.append(f"origin {data['origin']} != {list(origin)}")
    if direction is not None and not close(data["direction"], direction, max(tol, 1e-3)):
        bad.append(f"direction {data['direction']} != {list(direction)}")
    if bad:
        rc.flag("wrong", case, "; ".join(bad))


# ---------------------------------------------------------------- DICOM written at known geometry
def run_dicom(cli, d, n_random, rng):
    try:
        import numpy as np
        import dicom_fixtures as fx
    except ImportError as e:
        print(f"dicom: skipped ({e})")
        return
    out = d / "dicom"
    fx.main(str(out))
    cases = json.loads((out / "expected.json").read_text())["cases"]
    for i in range(n_random):
        ax = np.array([rng.gauss(0, 1) for _ in range(3)])
        ax /= np.linalg.norm(ax)
        ang = math.radians(rng.uniform(-170, 170))
        K = np.array([[0, -ax[2], ax[1]], [ax[2], 0, -ax[0]], [-ax[1], ax[0], 0]])
        R = np.eye(3) + math.sin(ang) * K + (1 - math.cos(ang)) * K @ K
        tilt = rng.uniform(-25, 25) if i % 4 == 3 else None
        step = round(rng.uniform(0.5, 5.0), 3)
        ps = (round(rng.uniform(0.3, 2.0), 4), round(rng.uniform(0.3, 2.0), 4))
        n = rng.randint(2, 7)
        r, c = (R @ [1, 0, 0], R @ [0, 1, 0]) if tilt is None else ((1, 0, 0), (0, 1, 0))
        p0 = tuple(rng.uniform(-200, 200) for _ in range(3))
        cases.append(fx.series_case(str(out), f"random{i:02d}", r, c, step, n, ps=ps, p0=p0, tilt=tilt,
                                    implicit=bool(i % 2)))
    for c in cases:
        case = "dicom/" + c["name"]
        code, err, data = info_json(cli, c["read"], d)
        if "error" in c:
            rc.check(case, code, err, expect_rc=1, names=[os.path.basename(c["read"])])
            continue
        rc.check(case, code, err)
        if code != 0:
            rc.flag("exit", case, f"rc={code} on a valid series: {err.strip()[-200:]}")
            continue
        compare(case, data, c["dims"], c["spacing"], c["origin"], c["direction"])


# ---------------------------------------------------------------- peer corpora through `info`
def run_corpora(cli, d):
    try:
        import numpy as np
        import nibabel as nib
        import pydicom
        from pydicom.pixel_data_handlers.util import apply_modality_lut
    except ImportError as e:
        print(f"corpora: skipped ({e})")
        return
    nib_data = Path(nib.__file__).parent / "tests" / "data"
    for f in sorted(list(nib_data.glob("*.nii")) + list(nib_data.glob("*.nii.gz")) + list(nib_data.glob("*.hdr"))):
        case = "nibabel/" + f.name
        code, err, data = info_json(cli, f, d)
        rc.check(case, code, err, names=[f.name] if code else None)
        try:
            img = nib.load(str(f))
            arr = np.asanyarray(img.dataobj)
        except Exception:  # noqa: BLE001
            img = None
        if code != 0:
            if f.name not in err:
                rc.flag("message", case, f"refusal does not name the file: {err.strip()[-160:]}")
            continue
        if img is None:
            rc.flag("accepted", case, "read with exit 0 although nibabel cannot read it")
            continue
        dims, sp, origin, direction = nifti_expected(img)
        compare(case, data, dims, sp, origin, direction)
        while arr.ndim > 3:
            arr = arr[..., 0]
        lo, hi = float(np.nanmin(arr)), float(np.nanmax(arr))
        if not close(data["range"], [lo, hi], 1e-4):
            rc.flag("wrong", case, f"range {data['range']} != nibabel {[lo, hi]}")
    dcm_data = Path(pydicom.__file__).parent / "data" / "test_files"
    for f in sorted(p for p in dcm_data.rglob("*") if p.is_file()):
        case = "pydicom/" + str(f.relative_to(dcm_data))
        code, err, data = info_json(cli, f, d)
        rc.check(case, code, err)
        if code != 0:
            if f.name not in err:
                rc.flag("message", case, f"refusal does not name the file: {err.strip()[-160:]}")
            continue
        try:
            ds = pydicom.dcmread(str(f), force=True)
            ps = [float(x) for x in ds.get("PixelSpacing", ds.get("ImagerPixelSpacing", [1, 1]))]
            iop = [float(x) for x in ds.get("ImageOrientationPatient", [1, 0, 0, 0, 1, 0])]
        except Exception as e:  # noqa: BLE001
            rc.flag("accepted", case, f"read with exit 0 although pydicom cannot read it ({e})")
            continue
        r, c = np.array(iop[:3]), np.array(iop[3:])
        direction = np.column_stack([r, c, np.cross(r, c)]).ravel()
        origin = [float(x) for x in ds.get("ImagePositionPatient", [0, 0, 0])]
        nz = data["dims"][2]
        if nz > 1:
            # A file of a series: the volume is its folder's series; the file must be one of its slices.
            o, dz, sz = np.array(data["origin"]), np.array(data["direction"]).reshape(3, 3)[:, 2], data["spacing"][2]
            k = round(float(np.dot(np.array(origin) - o, dz)) / sz)
            if not (0 <= k < nz and np.allclose(o + k * sz * dz, origin, atol=1e-3)):
                rc.flag("wrong", case, f"the file's position {origin} is not a slice of the {nz}-slice volume")
            compare(case, data, [int(ds.Columns), int(ds.Rows), nz], [ps[1], ps[0], sz], None, direction)
            continue  # the slice's values: tests/python/test_peer_corpus.py compares them
        compare(case, data, [int(ds.Columns), int(ds.Rows), 1], [ps[1], ps[0], data["spacing"][2]], origin, direction)
        try:
            px = apply_modality_lut(ds.pixel_array, ds)
        except Exception:  # noqa: BLE001 - no pydicom decoder here for this transfer syntax
            continue
        if not close(data["range"], [float(px.min()), float(px.max())], 1e-4):
            rc.flag("wrong", case, f"range {data['range']} != pydicom {[float(px.min()), float(px.max())]}")


def nifti_expected(img):
    import numpy as np
    hdr = img.header
    shape = list(img.shape[:3]) + [1] * (3 - min(3, len(img.shape)))
    xyz = hdr.get_xyzt_units()[0] if hasattr(hdr, "get_xyzt_units") else "unknown"
    unit = {"meter": 1000.0, "micron": 0.001}.get(xyz, 1.0)
    codes = (int(hdr["sform_code"]), int(hdr["qform_code"])) if "sform_code" in hdr else (0, 0)
    if codes == (0, 0):
        z = np.abs(np.array(list(hdr.get_zooms()[:3]) + [1.0] * 3)[:3]) * unit
        z[z == 0] = 1
        return shape, list(z), None, None
    A = np.array(img.affine, float)
    A[:3] *= unit
    A[:2] *= -1
    sp = np.linalg.norm(A[:3, :3], axis=0)
    u, _, vt = np.linalg.svd(A[:3, :3] / sp)
    return shape, list(sp), list(A[:3, 3]), list((u @ vt).ravel())


# ---------------------------------------------------------------- NIfTI headers written by nibabel
def run_nifti(cli, d, n, rng):
    try:
        import numpy as np
        import nibabel as nib
    except ImportError as e:
        print(f"nifti: skipped ({e})")
        return
    out = d / "nifti"
    out.mkdir()
    for i in range(n):
        shape = (rng.randint(2, 6), rng.randint(2, 6)) if i % 7 == 6 else tuple(rng.randint(2, 6) for _ in range(3))
        data = (np.arange(int(np.prod(shape))).reshape(shape) % 97).astype(np.int16)
        ax = np.array([rng.gauss(0, 1) for _ in range(3)])
        ax /= np.linalg.norm(ax)
        ang = math.radians(rng.uniform(-180, 180))
        K = np.array([[0, -ax[2], ax[1]], [ax[2], 0, -ax[0]], [-ax[1], ax[0], 0]])
        R = np.eye(3) + math.sin(ang) * K + (1 - math.cos(ang)) * K @ K
        if rng.random() < 0.3:
            R[:, 2] *= -1  # left-handed
        A = np.eye(4)
        A[:3, :3] = R @ np.diag([rng.uniform(0.2, 3) for _ in range(3)])
        A[:3, 3] = [rng.uniform(-150, 150) for _ in range(3)]
        if i % 5 == 4:
            A[:3, :3] = A[:3, :3].astype(np.float32) + rng.uniform(-3e-4, 3e-4)
        img = nib.Nifti1Image(data, A)
        codes = rng.choice([(1, 1), (2, 1), (0, 1), (1, 0), (4, 2)])
        q = A.copy()
        q[:3, 3] += [rng.uniform(-40, 40) for _ in range(3)]
        img.set_qform(q, code=codes[1]) if codes[1] else img.set_qform(None, code=0)
        img.set_sform(A, code=codes[0]) if codes[0] else img.set_sform(None, code=0)
        img.header.set_xyzt_units(xyz=rng.choice(["mm", "meter", "micron", "unknown"]))
        path = out / f"n{i:03d}.nii"
        nib.save(img, str(path))
        raw = bytearray(path.read_bytes())
        if i % 6 == 1:
            raw[112:116] = np.float32(rng.choice([0.0, float("nan")])).tobytes()
            raw[116:120] = np.float32(rng.uniform(-100, 100)).tobytes()
        if i % 6 == 2:
            raw[80:84] = np.float32(-abs(np.frombuffer(bytes(raw[80:84]), np.float32)[0])).tobytes()
        path.write_bytes(bytes(raw))
        case = f"nifti/n{i:03d}"
        code, err, got = info_json(cli, path, d)
        try:
            ref = nib.load(str(path))
            arr = np.asanyarray(ref.dataobj)
        except Exception as e:  # noqa: BLE001
            if code == 0:
                rc.flag("accepted", case, f"exit 0 although nibabel refuses it ({e})")
            continue
        rc.check(case, code, err)
        if code != 0:
            rc.flag("exit", case, f"refused a file nibabel reads: {err.strip()[-200:]}")
            continue
        dims, sp, origin, direction = nifti_expected(ref)
        compare(case, got, dims, sp, origin, direction, tol=2e-4)
        if not close(got["range"], [float(arr.min()), float(arr.max())], 1e-4):
            rc.flag("wrong", case, f"range {got['range']} != nibabel {[float(arr.min()), float(arr.max())]}")


# ---------------------------------------------------------------- outputs that are not regular files
def run_special_outputs(cli, d):
    o = d / "special"
    o.mkdir()
    v = d / "seed" / "v.nii"
    regular = o / "target.json"
    regular.write_text("old\n")
    targets = {}
    fifo = o / "fifo"
    os.mkfifo(fifo)
    targets["fifo"] = fifo
    try:
        os.mknod(o / "null", stat.S_IFCHR | 0o666, os.makedev(1, 3))
        targets["chardev"] = o / "null"
    except OSError:
        pass
    full = o / "to_full"
    os.symlink("/dev/full", full)
    targets["link-to-dev-full"] = full
    for name, path in targets.items():
        before = os.lstat(path)
        for cmd, args in [("info", ["info", str(v), "--json", str(path)]),
                          ("convert", ["convert", str(v), str(path)]),
                          ("render", ["render", str(v), "--size", "32x32", "--out", str(path)]),
                          ("phantom", ["phantom", "vessels", "--size", "24,24,24", "--out", str(path)])]:
            case = f"special/{cmd}->{name}"
            code, err, _ = rc.run(cli, args, 20, o)
            rc.check(case, code, err, expect_rc=2, names=[path.name])
            after = os.lstat(path)
            if stat.S_IFMT(after.st_mode) != stat.S_IFMT(before.st_mode) or after.st_ino != before.st_ino:
                rc.flag("replaced", case, f"{path.name} was replaced by a {stat.filemode(after.st_mode)}")
            for f in rc.leftovers(o):
                rc.flag("leftover", case, f)
    # A symbolic link to a regular file is written through: the link stays, the target changes.
    link = o / "link.json"
    os.symlink(regular.name, link)
    code, err, _ = rc.run(cli, ["info", str(v), "--json", str(link)], 20, o)
    rc.check("special/info->link-to-regular", code, err)
    if not link.is_symlink():
        rc.flag("replaced", "special/info->link-to-regular", "the link was replaced by a file")
    elif "dims" not in regular.read_text():
        rc.flag("wrong", "special/info->link-to-regular", "the link's target was not written")
    dangling = o / "dangling.json"
    os.symlink("made_by_info.json", dangling)
    code, err, _ = rc.run(cli, ["info", str(v), "--json", str(dangling)], 20, o)
    rc.check("special/info->dangling-link", code, err)
    if not dangling.is_symlink() or not (o / "made_by_info.json").exists():
        rc.flag("replaced", "special/info->dangling-link", "the link was replaced or its target not created")
    for f in rc.leftovers(o):
        rc.flag("leftover", "special/links", f)


# ---------------------------------------------------------------- Python front ends
PY_CASES = [
    ("dtype-int16-overflow", "vs.Volume(np.full((2,2,2), 70000, np.int32), dtype='int16')", "ValueError"),
    ("dtype-uint8-nan", "vs.Volume(np.full((2,2,2), np.nan, np.float32), dtype='uint8')", "ValueError"),
    ("dtype-uint8-negative", "vs.Volume(np.full((2,2,2), -5, np.int16), dtype='uint8')", "ValueError"),
    ("dtype-float32-overflow", "vs.Volume(np.full((2,2,2), 1e300), dtype='float32')", "ValueError"),
    ("direction-scaled", "vs.Volume(np.zeros((2,2,2), np.uint8), direction=np.diag([2.0,1,1]))", "ValueError"),
    ("direction-sheared", "vs.Volume(np.zeros((2,2,2), np.uint8), direction=[[1,0.3,0],[0,1,0],[0,0,1]])",
     "ValueError"),
    ("auto-terminals-2**40", "vs.trace(vs.Volume(np.zeros((8,8,8), np.float32)), root=(1,1,1), auto_terminals=2**40)",
     "ValueError"),
    ("auto-terminals-negative", "vs.trace(vs.Volume(np.zeros((8,8,8), np.float32)), root=(1,1,1), auto_terminals=-1)",
     "ValueError"),
]


def run_python(pydir, d):
    if not pydir or not Path(pydir).is_dir():
        print("python: skipped (no --python build folder)")
        return
    env = dict(os.environ, PYTHONPATH=str(pydir))
    for name, expr, want in PY_CASES:
        code = ("import numpy as np, volscissors as vs\ntry:\n    " + expr +
                "\n    print('NO-ERROR')\nexcept Exception as e:\n    print(type(e).__name__, e)\n")
        p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=60)
        rc.CASES += 1
        case = "python/" + name
        if p.returncode != 0 or "Traceback" in p.stderr:
            rc.flag("crash", case, p.stderr.strip()[-200:])
        elif p.stdout.startswith("NO-ERROR"):
            rc.flag("accepted", case, "accepted without error")
        elif not p.stdout.startswith(want):
            rc.flag("traceback", case, f"raised {p.stdout.strip()[:160]}, expected {want}")
    b = d / "batch"
    b.mkdir()
    vol = d / "seed" / "v.nii"
    csvs = {
        "ragged-extra": f"case,path,auto_terminals\na,{vol},1,EXTRA\n",
        "ragged-short": f"case,path,auto_terminals\na\n",
        "name-collision": f"case,path,points,slice\na,{vol},1 1;5 5,z=3\na.contour,{vol},1 1;5 5,z=3\n",
    }
    for name, text in csvs.items():
        f = b / f"{name}.csv"
        f.write_text(text)
        op = "livewire" if name == "name-collision" else "trace"
        p = subprocess.run([sys.executable, "-m", "volscissors.batch", str(f), "--op", op, "--out", str(b / name),
                            "--workers", "1"], capture_output=True, text=True, env=env, timeout=120)
        rc.CASES += 1
        case = "batch/" + name
        if "Traceback" in p.stderr:
            rc.flag("traceback", case, p.stderr.strip()[-200:])
        elif p.returncode != 2:
            rc.flag("exit", case, f"rc={p.returncode}, expected 2: {p.stderr.strip()[-160:]}")


# ---------------------------------------------------------------- phantom spacing, SIGTERM timing
def run_phantom_and_signals(cli, d, rng, count):
    for sp in ["1e-300", "1e-30", "0", "-1", "nan", "1e300"]:
        code, err, t = rc.run(cli, ["phantom", "vessels", "--size", "32,32,32", "--spacing", f"{sp},1,1", "--out",
                                    str(d / "p.nii")], 20, d)
        rc.check(f"phantom/spacing={sp}", code, err, expect_rc=2)
    big = str(d / "seed" / "big.nii")
    s = d / "sig"
    s.mkdir()
    commands = [
        ("phantom", lambda o: ["phantom", "vessels", "--size", "320,320,256", "--out", str(o / "p.nii.gz")], ["p.nii.gz"]),
        ("surface", lambda o: ["surface", big, "--out", str(o / "s.ply")], ["s.ply"]),
        ("convert", lambda o: ["convert", big, str(o / "c.nhdr")], ["c.nhdr"]),
        ("render", lambda o: ["render", big, "--turntable", "24", "--size", "384x384", "--out", str(o / "r.png"),
                              "--json", str(o / "r.json")], ["r.json", "r_000.png"]),
        ("trace", lambda o: ["trace", big, "--root", "3,3,3", "--full", "--cost", "gradient", "--out",
                             str(o / "t.swc")], ["t.swc"]),
    ]
    for i in range(count):
        name, make, outs = commands[i % len(commands)]
        o = s / f"{name}_{i}"
        o.mkdir()
        delay = rng.uniform(1.5, 3.5)
        p = subprocess.Popen([cli, "-q"] + make(o), cwd=o, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        time.sleep(delay)
        finished = p.poll() is not None
        t0 = time.time()
        p.send_signal(signal.SIGTERM)
        try:
            _, err = p.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            p.kill()
            p.communicate()
            err = b""
        took = time.time() - t0
        case = f"sigterm/{name}@{delay:.1f}s"
        rc.check(case, p.returncode, err.decode(errors="replace"))
        if finished:
            continue
        if took > 1.5:
            rc.flag("slow", case, f"{took:.2f} s after the first SIGTERM")
        if p.returncode not in (0, 130):
            rc.flag("exit", case, f"rc={p.returncode}, expected 130")
        if p.returncode != 0:
            left = [f for f in outs if (o / f).exists()]
            if left:
                rc.flag("partial", case, f"outputs after a cancelled run: {left}")
        for f in rc.leftovers(o):
            rc.flag("leftover", case, f)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default="build/volscissors")
    ap.add_argument("--python", default="build/python", help="folder with the volscissors Python module")
    ap.add_argument("--random", type=int, default=40, help="random DICOM series and NIfTI files (default 40)")
    ap.add_argument("--signals", type=int, default=10)
    ap.add_argument("--seed", type=int, default=22)
    ap.add_argument("--verbose", action="store_true")
    a = ap.parse_args()
    cli = str(Path(a.cli).resolve())
    rng = random.Random(a.seed)
    t0 = time.time()
    with tempfile.TemporaryDirectory(prefix="vs_readers_") as tmp:
        d = Path(tmp)
        (d / "seed").mkdir()
        subprocess.run([cli, "-q", "phantom", "vessels", "--size", "32,28,24", "--seed", "2", "--out",
                        str(d / "seed" / "v.nii")], check=True)
        subprocess.run([cli, "-q", "phantom", "vessels", "--size", "192,192,160", "--seed", "2", "--out",
                        str(d / "seed" / "big.nii")], check=True)
        run_dicom(cli, d, a.random, rng)
        run_corpora(cli, d)
        run_nifti(cli, d, a.random, rng)
        run_special_outputs(cli, d)
        run_python(str(Path(a.python).resolve()) if a.python else None, d)
        run_phantom_and_signals(cli, d, rng, a.signals)
    print(f"reader campaign: {rc.CASES} cases in {time.time() - t0:.0f} s with {a.cli}")
    for k, v in rc.COUNTS.items():
        print(f"  {k:10s} {v}")
    print(f"  total      {sum(rc.COUNTS.values())}")
    if a.verbose or sum(rc.COUNTS.values()):
        for line in rc.DETAILS:
            print("   ", line)
    return 1 if sum(rc.COUNTS.values()) else 0


if __name__ == "__main__":
    sys.exit(main())
