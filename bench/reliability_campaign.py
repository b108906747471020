#!/usr/bin/python3
"""Bad-input campaign against the volscissors CLI (issue 11). Prints totals per class.

  bench/reliability_campaign.py [--cli build/volscissors] [--mutants 40] [--seed 1]

Everything is generated here, in a private temporary folder: valid seed files from the
project's own generator (`phantom`, `convert`), hand-made hostile files per format and
command, random header mutants of every format (through `info`), commands whose output is
one of their inputs, interrupted runs (SIGINT/SIGTERM at random moments), and a "full disk"
(RLIMIT_FSIZE with SIGXFSZ ignored, so write(2) fails with EFBIG like ENOSPC; a real small
tmpfs needs mount privileges, used when `mount -t tmpfs` works).

Classes counted (the README's contract: exit 2 usage, 1 data/IO, 130 cancelled, a message
naming the file, never a crash, a hang, a partial output or a leftover temporary):
  crash      killed by a signal, exit status outside {0,1,2,130}, "internal error", or a
             sanitizer report on stderr
  hang       still running after --timeout seconds (default 10) on a tiny input
  accepted   a corrupt input read with exit 0 (hand-made cases whose answer is known)
  exit       wrong exit status (1 expected for bad data, 2 for bad usage)
  message    the error message does not name the offending file
  destroyed  an input changed by a command (output == input)
  partial    an output file left after a failed or cancelled run
  leftover   a temporary (.name.tmp*, .vs_*) left in the output folder
Runs are bounded: about 300 short processes plus a few interrupted ones, a few minutes.
"""
import argparse
import hashlib
import os
import random
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib
from pathlib import Path

COUNTS = {k: 0 for k in ["crash", "hang", "accepted", "exit", "message", "destroyed", "partial", "leftover"]}
DETAILS = []
CASES = 0


def flag(kind, case, why):
    COUNTS[kind] += 1
    DETAILS.append(f"{kind:9s} {case}: {why}")


def run(cli, args, timeout, cwd, preexec=None):
    t0 = time.time()
    try:
        p = subprocess.run([cli] + args, cwd=cwd, capture_output=True, timeout=timeout, preexec_fn=preexec)
        return p.returncode, p.stderr.decode(errors="replace"), time.time() - t0
    except subprocess.TimeoutExpired:
        return None, "", time.time() - t0


def check(case, rc, err, expect_rc=None, names=None, allow_ok=False):
    """Classifies one finished run. expect_rc: 1 or 2 (None: any of 0/1/2)."""
    global CASES
    CASES += 1
    if rc is None:
        return flag("hang", case, "timeout")
    if rc < 0 or rc not in (0, 1, 2, 130) or "internal error" in err or "Sanitizer" in err or "runtime error:" in err:
        return flag("crash", case, f"rc={rc} {err.strip()[-200:]}")
    if expect_rc is None:
        return
    if rc == 0 and not allow_ok:
        return flag("accepted", case, "exit 0 on a corrupt input")
    if rc != 0 and rc != expect_rc:
        return flag("exit", case, f"rc={rc}, expected {expect_rc}: {err.strip()[-160:]}")
    if rc != 0 and names and not any(n in err for n in names):
        flag("message", case, f"message does not name {names[0]}: {err.strip()[-160:]}")


def leftovers(folder):
    return [p.name for p in Path(folder).iterdir() if p.name.startswith(".") and (".tmp" in p.name or p.name.startswith(".vs_"))]


def sha(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest() if Path(path).is_file() else None


# ---------------------------------------------------------------- hand-made bad inputs
def vti_blocks(nblocks, block, last, csizes, payload, offset="0", extent="0 3 0 3 0 3"):
    x = (b'<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64" '
         b'compressor="vtkZLibDataCompressor">\n<ImageData WholeExtent="' + extent.encode() + b'" Spacing="1 1 1">\n'
         b'<Piece Extent="' + extent.encode() + b'"><PointData Scalars="s">\n<DataArray type="UInt8" Name="s" '
         b'format="appended" offset="' + offset.encode() + b'"/>\n</PointData></Piece></ImageData>\n'
         b'<AppendedData encoding="raw">\n_')
    x += struct.pack("<3Q", nblocks, block, last) + b"".join(struct.pack("<Q", c) for c in csizes) + payload
    return x + b"\n</AppendedData>\n</VTKFile>\n"


def nifti(dim0=3, dims=(4, 4, 4), srow0=1.0, sform=1, datatype=2, bitpix=8, data=None, vox=352.0):
    h = bytearray(352)
    struct.pack_into("<i", h, 0, 348)
    struct.pack_into("<8h", h, 40, dim0, *dims, 1, 1, 1, 1)
    struct.pack_into("<hh", h, 70, datatype, bitpix)
    struct.pack_into("<8f", h, 76, 1, 1, 1, 1, 0, 0, 0, 0)
    struct.pack_into("<f", h, 108, vox)
    struct.pack_into("<h", h, 254, sform)
    struct.pack_into("<4f", h, 280, srow0, 0, 0, 0)
    struct.pack_into("<4f", h, 296, 0, 1, 0, 0)
    struct.pack_into("<4f", h, 312, 0, 0, 1, 0)
    h[344:348] = b"n+1\0"
    n = 1
    for d in dims:
        n *= max(d, 1)
    return bytes(h) + (data if data is not None else bytes(range(256)) * (n // 256) + bytes(n % 256))


def png_chunk(kind, body):
    return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)


def png(w, h, rows=None, corrupt=False, truncate=False):
    raw = rows if rows is not None else b"".join(b"\0" + bytes((x * 7 + y) & 255 for x in range(w)) for y in range(h))
    idat = zlib.compress(raw)
    if corrupt:
        idat = idat[:4] + bytes(b ^ 0x5A for b in idat[4:20]) + idat[20:]
    data = b"\x89PNG\r\n\x1a\n" + png_chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0))
    data += png_chunk(b"IDAT", idat) + png_chunk(b"IEND", b"")
    return data[: len(data) // 2] if truncate else data


def hand_made_cases(d):
    """(name, file name, bytes or None, extra files) -> every case must be refused with exit 1."""
    legacy = b"# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\n"
    z = zlib.compress(bytes(64))
    nhdr = "NRRD0004\ndimension: 3\nsizes: 2 2 2\ntype: uchar\nencoding: raw\ndata file: "
    meta = "ObjectType = Image\nNDims = {}\nDimSize = 2 2 2\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n"
    cases = [
        ("vti-wrapping-blocks", "a.vti", vti_blocks(3, 1 << 63, 64, [len(z)] * 3, z * 3)),
        ("vti-huge-block", "a.vti", vti_blocks(1, 1 << 40, 0, [len(z)], z)),
        ("vti-csize-wrap", "a.vti", vti_blocks(1, 64, 0, [(1 << 64) - 5], z)),
        ("vti-2^32-blocks", "a.vti", vti_blocks(1 << 32, 1, 0, [], z)),
        ("vti-negative-offset", "a.vti", vti_blocks(1, 64, 0, [len(z)], z, offset="-7")),
        ("vti-nan-extent", "a.vti", vti_blocks(1, 64, 0, [len(z)], z, extent="0 nan 0 3 0 3")),
        ("vti-huge-extent", "a.vti", vti_blocks(1, 64, 0, [len(z)], z, extent="0 60000 0 60000 0 60000")),
        ("vtk-negative-cell-data", "a.vtk", legacy + b"DIMENSIONS 2 2 2\nCELL_DATA -1\nSCALARS c float 1\nLOOKUP_TABLE default\nabcd\n"),
        ("vtk-dims-overflow", "a.vtk", legacy + b"DIMENSIONS 4294967296 4294967296 4294967296\nPOINT_DATA 1\nSCALARS s float\n"),
        ("vtk-gigabytes-from-bytes", "a.vtk", legacy + b"DIMENSIONS 1500 1500 1000\nPOINT_DATA 2250000000\nSCALARS s unsigned_char 1\nLOOKUP_TABLE default\nab"),
        ("vtk-field-negative", "a.vtk", legacy + b"DIMENSIONS 2 2 2\nPOINT_DATA 8\nFIELD f 1\na -3 8 float\n"),
        ("nrrd-pattern-%n", "a.nhdr", (nhdr + "s%n%n%n%n.raw 1 4 1\n").encode()),
        ("nrrd-pattern-%s", "a.nhdr", (nhdr + "s%s%s%s.raw 1 4 1\n").encode()),
        ("nrrd-pattern-width", "a.nhdr", (nhdr + "s%2147483647d.raw 1 2 1\n").encode()),
        ("nrrd-4d-raw", "a.nrrd", b"NRRD0004\ndimension: 4\nsizes: 2 2 2 3\ntype: uchar\nencoding: raw\n\n" + bytes(20)),
        ("nrrd-5d-raw", "a.nrrd", b"NRRD0004\ndimension: 5\nsizes: 2 2 2 3 2\ntype: uchar\nencoding: raw\n\n" + bytes(40)),
        ("nrrd-huge-from-bytes", "a.nrrd", b"NRRD0004\ndimension: 3\nsizes: 2000 2000 1000\ntype: uchar\nencoding: gzip\n\n" + z),
        ("meta-ndims-negative", "a.mha", (meta.format(-1)).encode() + bytes(8)),
        ("meta-ndims-huge", "a.mha", (meta.format(2000000000)).encode() + bytes(8)),
        ("meta-pattern-%n", "a.mhd", b"ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nElementDataFile = s%n.raw 1 2 1\n"),
        ("meta-missing-slices", "a.mhd", b"ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nElementDataFile = s%03d.raw 1 2 1\n"),
        ("meta-undecodable", "a.mha", b"ObjectType = Image\nNDims = 3\nDimSize = 4 4 4\nElementType = MET_UCHAR\nCompressedData = True\n"
                                      b"CompressedDataSize = 30\nElementDataFile = LOCAL\n" + b"q" * 30),
        ("meta-short-raw", "a.mha", (meta.format(3)).encode() + bytes(3)),
        ("nifti-nan-sform", "a.nii", nifti(srow0=float("nan"))),
        ("nifti-huge-sform", "a.nii", nifti(srow0=3e38)),
        ("nifti-dim0-zero", "a.nii", nifti(dim0=0)),
        ("nifti-negative-dim", "a.nii", nifti(dims=(4, -4, 4), data=bytes(64))),
        ("nifti-truncated", "a.nii", nifti()[:360]),
        ("png-corrupt-idat", "a.png", png(40, 30, corrupt=True)),
        ("png-truncated", "a.png", png(40, 30, truncate=True)),
        ("png-100000^2-tiny", "a.png", png(100000, 100000, rows=b"\0" * 10)),
        ("png-short-rows", "a.png", png(40, 30, rows=b"\0" * 50)),
        ("empty-nii", "a.nii", b""),
        ("wrong-magic-nrrd", "a.nrrd", b"NOTNRRD\n"),
        ("ply-2^64-elements", "a.ply", b"ply\nformat binary_little_endian 1.0\nelement junk 18446744073709551615\nend_header\n"),
    ]
    return cases


def run_hand_made(cli, d, timeout):
    for name, fname, data in hand_made_cases(d):
        case_dir = d / ("hand_" + name)
        case_dir.mkdir()
        path = case_dir / fname
        path.write_bytes(data)
        if name == "meta-missing-slices":
            (case_dir / "s001.raw").write_bytes(bytes(4))
        cmd = ["info", str(path)]
        if fname.endswith(".ply"):  # meshes are read by render --overlay
            vol = d / "seed" / "v.nii"
            cmd = ["render", str(vol), "--overlay", str(path), "--size", "32x32", "--out", str(case_dir / "o.png")]
        rc, err, _ = run(cli, cmd, timeout, case_dir)
        check("hand/" + name, rc, err, expect_rc=1, names=[fname])
    # DICOM: a series with one truncated file (pixel data cut) must not be read as zeros.
    src = Path(__file__).resolve().parent.parent.parent / "shared" / "data" / "abdomen_ct_dicom_j2k_totalseg" / "example_ct_dicom"
    if src.is_dir():
        dcm = d / "dicom_trunc"
        shutil.copytree(src, dcm)
        files = sorted(p for p in dcm.iterdir() if p.is_file())
        victim = files[len(files) // 2]
        victim.write_bytes(victim.read_bytes()[: victim.stat().st_size * 2 // 3])
        rc, err, _ = run(cli, ["info", str(dcm)], timeout, d)
        check("hand/dicom-truncated-slice", rc, err, expect_rc=1, names=[victim.name, str(dcm)])


# ---------------------------------------------------------------- usage errors per command
def run_usage(cli, d, timeout):
    v = str(d / "seed" / "v.nii")
    cases = [
        ("render-plane-negative", ["render", v, "--mode", "slice", "--plane", "z=-1", "--out", str(d / "u.png")]),
        ("render-plane-beyond", ["render", v, "--mode", "slice", "--plane", "z=100000", "--out", str(d / "u.png")]),
        ("livewire-weights-text", ["livewire", v, "--points", "1,1;5,5", "--weights", "a", "b", "c", "--out", str(d / "u.json")]),
        ("livewire-smooth-1e300", ["livewire", v, "--points", "1,1;5,5", "--smooth", "1e300", "--out", str(d / "u.json")]),
        ("livewire-smooth-1e6", ["livewire", v, "--points", "1,1;5,5", "--smooth", "1e6", "--out", str(d / "u.json")]),
        ("trace-scales-1e300", ["trace", v, "--root", "1,1,1", "--target", "5,5,5", "--cost", "vesselness", "--scales", "1e300",
                                "--out", str(d / "u.swc")]),
        ("trace-smooth-1e6", ["trace", v, "--root", "1,1,1", "--target", "5,5,5", "--cost", "intensity", "--smooth", "1e6",
                              "--out", str(d / "u.swc")]),
        ("phantom-size-negative", ["phantom", "vessels", "--size", "-5,4,4", "--out", str(d / "u.nii")]),
        ("convert-unknown-ext", ["convert", v, str(d / "u.xyz")]),
    ]
    for name, args in cases:
        rc, err, _ = run(cli, args, timeout, d)
        check("usage/" + name, rc, err, expect_rc=2)
    # JSON inputs with a string where a number is expected: a data error naming the file.
    tf = d / "tf_bad.json"
    tf.write_text('{"points": [{"value": "zero", "opacity": 0}, {"value": 1, "opacity": 1}]}')
    rc, err, _ = run(cli, ["render", v, "--tf", str(tf), "--size", "32x32", "--out", str(d / "u.png")], timeout, d)
    check("json/tf-string-value", rc, err, expect_rc=1, names=["tf_bad.json"])
    tg = d / "targets_bad.json"
    tg.write_text('{"root": ["a", 1, 2], "terminals": [[1, 2, 3]]}')
    rc, err, _ = run(cli, ["trace", v, "--targets-file", str(tg), "--out", str(d / "u.swc")], timeout, d)
    check("json/targets-string", rc, err, expect_rc=1, names=["targets_bad.json"])
    ov = d / "overlay_bad.json"
    ov.write_text('{"points_index": [["x", 1, 2], [3, 4, 5]]}')
    rc, err, _ = run(cli, ["render", v, "--overlay", str(ov), "--size", "32x32", "--out", str(d / "u.png")], timeout, d)
    check("json/overlay-string", rc, err, expect_rc=1, names=["overlay_bad.json"])


# ---------------------------------------------------------------- outputs
def run_outputs(cli, d, timeout):
    seed = d / "seed"
    o = d / "outputs"
    o.mkdir()
    v = o / "v.nii"
    shutil.copy(seed / "v.nii", v)
    alias = o / "alias.nii"
    os.symlink(v, alias)
    hv = sha(v)
    cases = [
        ("info-json-is-input", ["info", str(v), "--json", str(v)]),
        ("convert-onto-itself", ["convert", str(v), str(v)]),
        ("convert-onto-symlink", ["convert", str(v), str(alias)]),
        ("convert-dotdot-spelling", ["convert", str(v), str(o / ".." / "outputs" / "v.nii")]),
        ("render-out-is-input", ["render", str(v), "--size", "32x32", "--out", str(v)]),
        ("trace-out-equals-json", ["trace", str(v), "--root", "2,2,2", "--target", "8,8,8", "--out", str(o / "t.json"),
                                   "--json", str(o / "t.json")]),
        ("trace-labels-is-input", ["trace", str(v), "--root", "2,2,2", "--target", "8,8,8", "--out", str(o / "t.swc"),
                                   "--labels", str(alias)]),
    ]
    for name, args in cases:
        rc, err, _ = run(cli, args, timeout, o)
        check("output/" + name, rc, err, expect_rc=2)
        if sha(v) != hv:
            flag("destroyed", "output/" + name, "input changed")
            shutil.copy(seed / "v.nii", v)
            hv = sha(v)
        if name.startswith("trace") and rc != 0 and (o / "t.swc").exists():
            flag("partial", "output/" + name, "t.swc left after a failed run")
            (o / "t.swc").unlink()
        for f in leftovers(o):
            flag("leftover", "output/" + name, f)
    # An output folder that does not exist: refused before computing, nothing written.
    rc, err, t = run(cli, ["trace", str(v), "--root", "2,2,2", "--target", "8,8,8", "--out", str(o / "t.swc"), "--labels",
                           str(o / "missing" / "l.nii.gz")], timeout, o)
    check("output/trace-missing-folder", rc, err, expect_rc=1, names=["missing"])
    if (o / "t.swc").exists():
        flag("partial", "output/trace-missing-folder", "t.swc written although --labels could not be")
    # Full disk: writes fail with EFBIG past 64 KiB (RLIMIT_FSIZE, SIGXFSZ ignored).
    def small_disk():
        import resource
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (65536, 65536))
    big = seed / "big.nii"
    for ext in ["nii", "nii.gz", "mha", "nrrd", "mhd", "nhdr"]:
        out = o / f"full.{ext}"
        rc, err, _ = run(cli, ["convert", str(big), str(out)], timeout, o, preexec=small_disk)
        check("fulldisk/" + ext, rc, err, expect_rc=1, names=[out.name])
        if out.exists():
            flag("partial", "fulldisk/" + ext, f"{out.name} exists after a failed write (rc={rc})")
            out.unlink()
        for f in leftovers(o):
            flag("leftover", "fulldisk/" + ext, f)
            p = o / f
            shutil.rmtree(p) if p.is_dir() else p.unlink()


# ---------------------------------------------------------------- mutants
NASTY = [b"-1", b"0", b"2147483648", b"18446744073709551615", b"-9223372036854775808", b"nan", b"inf", b"1e308", b"%n%s",
         b"999999999", b"3.5", b"-0"]


def mutate(data, rng, header_len):
    b = bytearray(data)
    for _ in range(rng.randint(1, 4)):
        r = rng.random()
        hl = max(1, min(header_len, len(b)))
        if r < 0.4:  # flip bytes in the header
            i = rng.randrange(hl)
            b[i] = rng.randrange(256)
        elif r < 0.8:  # replace a number in the text header by a nasty one
            text_positions = [i for i in range(hl) if chr(b[i]).isdigit()]
            if text_positions:
                i = rng.choice(text_positions)
                j = i
                while j < hl and (chr(b[j]).isdigit() or b[j] in b".-e"):
                    j += 1
                b[i:j] = rng.choice(NASTY)
            else:
                i = rng.randrange(max(1, hl - 8))
                b[i:i + 8] = struct.pack("<q", rng.choice([-1, 1 << 62, 1 << 31, -(1 << 31), 0]))
        elif r < 0.9:  # truncate
            del b[rng.randrange(1, len(b)):]
        else:  # overwrite a binary word anywhere in the first 600 bytes
            i = rng.randrange(max(1, min(600, len(b)) - 8))
            b[i:i + 8] = struct.pack("<d", rng.choice([float("nan"), 1e300, -1e300, 0.0]))
    return bytes(b)


def run_mutants(cli, d, n, timeout, rng):
    seed = d / "seed"
    header_len = {"v.nii": 352, "v.nii.gz": 400, "v.nrrd": 300, "v.mha": 400, "a.vtk": 260, "a.vti": 500, "a.png": 60, "v.nhdr": 300}
    for name, hl in header_len.items():
        data = (seed / name).read_bytes()
        if name == "v.nii.gz":  # mutate the decompressed header, then compress again
            import gzip
            inner = gzip.decompress(data)
        for k in range(n):
            mdir = d / f"mut_{name}_{k}"
            mdir.mkdir()
            if name == "v.nii.gz":
                blob = gzip.compress(mutate(inner, rng, hl))
            else:
                blob = mutate(data, rng, hl)
            path = mdir / name
            path.write_bytes(blob)
            if name == "v.nhdr":
                shutil.copy(seed / "v.raw.gz", mdir / "v.raw.gz")
            rc, err, _ = run(cli, ["info", str(path)], timeout, mdir)
            check(f"mutant/{name}#{k}", rc, err)
            shutil.rmtree(mdir, ignore_errors=True)


# ---------------------------------------------------------------- interrupted runs
def run_interrupts(cli, d, count, rng):
    seed = d / "seed"
    outdir = d / "interrupt"
    outdir.mkdir()
    big = str(seed / "big.nii")
    # The trace's root lies in the background on purpose (a long full map to interrupt): the
    # gradient cost, since the default auto cost rightly refuses a root with no lumen around it.
    commands = [
        ("convert-nhdr", lambda o: ["convert", big, str(o / "c.nhdr")], ["c.nhdr", "c.raw.gz"]),
        ("convert-niigz", lambda o: ["convert", big, str(o / "c.nii.gz")], ["c.nii.gz"]),
        ("trace", lambda o: ["trace", big, "--root", "3,3,3", "--target", "150,150,120", "--full", "--cost", "gradient",
                             "--out", str(o / "t.swc"),
                             "--json", str(o / "t.json"), "--labels", str(o / "t.nii.gz")], ["t.swc", "t.json", "t.nii.gz"]),
        ("render-turntable", lambda o: ["render", big, "--turntable", "12", "--size", "256x256", "--out", str(o / "r.png")],
         ["r.png"] + [f"r_{i:03d}.png" for i in range(12)]),
    ]
    for i in range(count):
        name, make, outs = commands[i % len(commands)]
        o = outdir / f"{name}_{i}"
        o.mkdir()
        sig = signal.SIGINT if i % 2 == 0 else signal.SIGTERM
        # After start-up (dynamic loading takes up to a second on a loaded machine; a signal
        # before main() installs its handler kills the process before it has written anything).
        delay = rng.uniform(1.5, 4.0)
        # A background shell starts children with SIGINT ignored: restore the default first.
        p = subprocess.Popen([cli, "-q"] + make(o), cwd=o, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                             preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
        time.sleep(delay)
        p.send_signal(sig)
        try:
            _, err = p.communicate(timeout=20)
            rc = p.returncode
        except subprocess.TimeoutExpired:
            p.kill()
            p.communicate()
            rc = None
            err = b""
        case = f"signal/{name}/{signal.Signals(sig).name}@{delay:.2f}s"
        if rc == -sig:  # killed by the signal itself: no handler, nothing cleaned up
            flag("exit", case, f"killed by {signal.Signals(sig).name} (no handler), expected exit 130")
        else:
            check(case, rc, err.decode(errors="replace"))
        if rc is not None and rc != 0:
            if rc != 130 and rc != -sig:
                flag("exit", case, f"rc={rc}, expected 130")
            left = [f for f in outs if (o / f).exists()]
            if left:
                flag("partial", case, f"outputs after an interrupted run: {left}")
        elif rc == 0:  # finished before the signal: every output must be there
            missing = [f for f in outs if not (o / f).exists() and not f.startswith("r_")]
            if missing and name != "render-turntable":
                flag("partial", case, f"exit 0 but missing {missing}")
        for f in leftovers(o):
            flag("leftover", case, f)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default="build/volscissors")
    ap.add_argument("--mutants", type=int, default=30, help="mutants per format (default 30)")
    ap.add_argument("--interrupts", type=int, default=16, help="interrupted runs (default 16)")
    ap.add_argument("--timeout", type=float, default=10.0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--verbose", action="store_true")
    a = ap.parse_args()
    cli = str(Path(a.cli).resolve())
    rng = random.Random(a.seed)
    t0 = time.time()
    with tempfile.TemporaryDirectory(prefix="vs_campaign_") as tmp:
        d = Path(tmp)
        seed = d / "seed"
        seed.mkdir()
        subprocess.run([cli, "-q", "phantom", "vessels", "--size", "32,28,24", "--seed", "2", "--out", str(seed / "v.nii")], check=True)
        subprocess.run([cli, "-q", "phantom", "vessels", "--size", "160,160,128", "--seed", "2", "--out", str(seed / "big.nii")], check=True)
        for ext in ["nii.gz", "nrrd", "mha", "nhdr"]:
            subprocess.run([cli, "-q", "convert", str(seed / "v.nii"), str(seed / f"v.{ext}")], check=True)
        (seed / "a.vtk").write_bytes(b"# vtk DataFile Version 3.0\ns\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 3 2 2\n"
                                     b"SPACING 1 1 2\nORIGIN 0 0 0\nPOINT_DATA 12\nSCALARS s short 1\nLOOKUP_TABLE default\n"
                                     b"0 1 2 3 4 5 6 7 8 9 10 11\n")
        (seed / "a.vti").write_bytes(vti_blocks(1, 64, 0, [len(zlib.compress(bytes(range(64))))], zlib.compress(bytes(range(64)))))
        (seed / "a.png").write_bytes(png(40, 30))
        run_hand_made(cli, d, a.timeout)
        run_usage(cli, d, a.timeout)
        run_outputs(cli, d, a.timeout)
        run_mutants(cli, d, a.mutants, a.timeout, rng)
        run_interrupts(cli, d, a.interrupts, rng)
    print(f"campaign: {CASES} cases in {time.time() - t0:.0f} s with {a.cli}")
    for k, v in COUNTS.items():
        print(f"  {k:10s} {v}")
    print(f"  total      {sum(COUNTS.values())}")
    if a.verbose or sum(COUNTS.values()):
        for line in DETAILS:
            print("   ", line)
    return 1 if sum(COUNTS.values()) else 0


if __name__ == "__main__":
    sys.exit(main())
