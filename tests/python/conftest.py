"""Shared fixtures: the CLI binary (results to compare with), the shared data, small phantoms.

Run with PYTHONPATH=build/python /usr/bin/python3 -m pytest tests/python (make test does it).
"""
import contextlib
import json
import os
import struct
import subprocess
import threading
import time
import zlib

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CLI = os.environ.get("VS_CLI_PATH", os.path.join(ROOT, "build", "volscissors"))
DATA = os.environ.get("VS_SHARED_DATA_DIR", os.path.join(ROOT, "..", "shared", "data"))


def shared(relative):
    """Path of a shared data set, or a pytest skip naming what is missing."""
    path = os.path.join(DATA, relative)
    if not os.path.exists(path):
        pytest.skip(f"shared data {path} not found (set VS_SHARED_DATA_DIR)")
    return path


@contextlib.contextmanager
def ticking_thread():
    """Runs a Python thread that counts milliseconds while the body runs; yields a callable that
    returns how often it ticked so far. It advances only while the body releases the GIL."""
    ticks, running = [0], [True]

    def count():
        while running[0]:
            ticks[0] += 1
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    try:
        yield lambda: ticks[0]
    finally:
        running[0] = False
        t.join()


def cli(*args):
    """Runs the volscissors CLI; returns its stdout (fails the test with stderr on error)."""
    r = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 0, f"volscissors {' '.join(map(str, args))} failed ({r.returncode}): {r.stderr}"
    return r.stdout


def read_png(path):
    """Decodes an 8-bit RGBA or RGB non-interlaced PNG (what the CLI writes) to [rows, cols, C]."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, w = 8, b"", None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, color, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert depth == 8 and color in (2, 6) and interlace == 0
            channels = 4 if color == 6 else 3
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw = zlib.decompress(idat)
    stride = w * channels
    out = np.zeros((h, stride), np.uint8)
    prev = np.zeros(stride, np.int32)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = np.frombuffer(raw, np.uint8, stride, y * (stride + 1) + 1).astype(np.int32)
        cur = np.zeros(stride, np.int32)
        for x in range(stride):
            a = cur[x - channels] if x >= channels else 0
            b = prev[x]
            c = prev[x - channels] if x >= channels else 0
            if f == 0:
                p = 0
            elif f == 1:
                p = a
            elif f == 2:
                p = b
            elif f == 3:
                p = (a + b) // 2
            else:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            cur[x] = (line[x] + p) & 255
        out[y] = cur
        prev = cur
    return out.reshape(h, w, channels)


@pytest.fixture(scope="session")
def vessels(tmp_path_factory):
    """A 64^3 vessel-tree phantom (seed 3) and its ground truth (voxel indices x, y, z)."""
    d = tmp_path_factory.mktemp("phantom")
    path, truth = d / "vessels.nii.gz", d / "vessels.json"
    cli("phantom", "vessels", "--seed", 3, "--size", "64,64,64", "--spacing", "0.8,0.9,1.1", "--out", path,
        "--truth", truth)
    return str(path), json.load(open(truth))


@pytest.fixture(scope="session")
def big_vessels(tmp_path_factory):
    """A 160^3 vessel phantom: long enough for the threading, progress and Ctrl-C tests."""
    d = tmp_path_factory.mktemp("phantom_big")
    path = d / "vessels.nii.gz"
    cli("phantom", "vessels", "--seed", 5, "--size", "160,160,160", "--out", path)
    return str(path)
