#!/usr/bin/env python3
"""The viewer in a user's hands, measured with real X input events (issue 27).

Starts a private Xvfb (Mesa's software OpenGL: no GPU), opens `volscissors view` on a volume
with VS_VIEWER_FRAME_LOG set (one line per drawn frame: when it was on the screen, its first
input event, what the 3D view did), drives it with xdotool and prints:
  idle CPU (share of one core over 10 s with nothing happening),
  rotate drag: interval between new 3D pictures while dragging, and the full-resolution picture
    after the release,
  wheel notch: from sending one notch to the frame showing the next slice,
  live-wire hover: from sending a mouse move to the frame showing the new live path.
Times are CLOCK_MONOTONIC in both processes; "from sending" includes starting xdotool (a few ms).

  With --cut instead (issue 26): the cut tool with three points placed around the head phantom's
  nose (the demo's points scaled to 256^3), then mouse moves over the face in the 3D view: from
  sending a move to the frame showing the previewed loop through the hovered point (the core's
  CutContourSession: the closed loop the cut would use).

Usage: bench/viewer_interaction.py BUILD_DIR [VOLUME] [--renderer auto|gpu|cpu] [--size WxH] [--cut]
(default VOLUME: the 256^3 head phantom written by `volscissors phantom`).
Goals (issue 27): idle <= 2 % of a core; drag frames <= 100 ms apart; full frame <= 1 s after
release; wheel notch <= 50 ms; live-wire hover <= 30 ms.
"""
import argparse
import os
import secrets
import shutil
import statistics
import subprocess
import sys
import tempfile
import time


def start_xvfb(tmp, width, height):
    auth = os.path.join(tmp, "xauthority")
    cookie = secrets.token_bytes(16)

    def field(b):
        return len(b).to_bytes(2, "big") + b

    with open(auth, "wb") as f:  # FamilyWild, any display number (matches what -displayfd picks)
        f.write(b"\xff\xff" + field(b"") + field(b"") + field(b"MIT-MAGIC-COOKIE-1") + field(cookie))
    r, w = os.pipe()
    xvfb = subprocess.Popen(["Xvfb", "-displayfd", str(w), "-auth", auth, "-screen", "0",
                             f"{width}x{height}x24", "-nolisten", "tcp", "-noreset"],
                            pass_fds=(w,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(w)
    number = b""
    while not number.endswith(b"\n"):
        c = os.read(r, 1)
        if not c:
            raise SystemExit("Xvfb did not start")
        number += c
    os.close(r)
    env = dict(os.environ, DISPLAY=":" + number.decode().strip(), XAUTHORITY=auth)
    return xvfb, env


def cpu_seconds(pid):
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime + stime


def read_log(path):
    frames = []
    with open(path) as f:
        for line in f:
            p = line.split()
            if len(p) < 7:
                continue
            frames.append({"done": float(p[0]), "input": float(p[1]), "events": int(p[2]), "view3d": p[3],
                           "ms3d": float(p[4]), "cursor": tuple(int(v) for v in p[5].split(",")),
                           "azimuth": float(p[6])})
    return frames


def stats(values):
    if not values:
        return "n=0"
    v = sorted(values)
    p95 = v[min(len(v) - 1, int(round(0.95 * (len(v) - 1))))]
    return f"n={len(v)} median {statistics.median(v):.1f} p95 {p95:.1f} max {v[-1]:.1f}"


def frame_latency(frames, sent, inside):
    """From each sent event to the first frame after it that handled input (ms); `inside` gets the
    time from the window receiving the event to that frame."""
    out = []
    for i, t in enumerate(sent):
        nxt = sent[i + 1] if i + 1 < len(sent) else float("inf")
        for f in frames:
            if f["done"] < t:
                continue
            if f["done"] > nxt:
                break
            if f["events"] > 0:
                out.append(1000 * (f["done"] - t))
                inside.append(1000 * (f["done"] - f["input"]))
                break
    return out


def measure_cut(a, xdo, c3d, viewer, log, tmp, start_s):
    # Moves over the face (the 3D view's centre, left to right and back), 0.15 s apart.
    xdo("mousemove", "--window", "%1", str(c3d[0] - 60), str(c3d[1]))
    time.sleep(2)  # the first move: the component's features and graph
    sent = []
    for k in list(range(1, 41)) + list(range(39, 0, -1)):
        t = time.monotonic()
        xdo("mousemove", "--window", "%1", str(c3d[0] - 60 + 3 * k), str(c3d[1] + (k % 4)))
        sent.append(t)
        time.sleep(0.15)
    xdo("key", "F12")
    viewer.wait(timeout=120)
    frames = read_log(log)
    inside = []
    lat = frame_latency(frames, sent, inside)
    print(f"viewer cut tool, {a.size}, --renderer {a.renderer}, head phantom 256^3, 3 points placed")
    print(f"  start to first full frame: {start_s:.1f} s")
    print(f"  cut hover to the previewed loop on screen, ms: {stats(lat)} (of {len(sent)} moves); "
          f"from the window receiving it: {stats(inside)}")
    print(f"  load average at the end: {os.getloadavg()[0]:.1f} (2 cores)")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("build")
    ap.add_argument("volume", nargs="?")
    ap.add_argument("--renderer", default="auto")
    ap.add_argument("--size", default="1440x900")
    ap.add_argument("--cut", action="store_true", help="measure the cut tool's preview per mouse move only")
    ap.add_argument("--picture", help="--cut: write the last frame (the previewed loop) to this PNG")
    a = ap.parse_args()
    for tool in ("Xvfb", "xdotool"):
        if not shutil.which(tool):
            raise SystemExit(f"{tool} is not installed (scripts/install-deps.sh)")
    cli = os.path.join(a.build, "volscissors")
    W, H = (int(v) for v in a.size.split("x"))
    tmp = tempfile.mkdtemp(prefix="vs_viewer_bench_")
    xvfb = viewer = None
    try:
        volume = a.volume
        if not volume:
            volume = os.path.join(tmp, "head.nii.gz")
            subprocess.run([cli, "-q", "phantom", "head", "--size", "256,256,256", "--out", volume], check=True)
        xvfb, env = start_xvfb(tmp, W + 40, H + 40)
        script = os.path.join(tmp, "script.txt")
        ready = os.path.join(tmp, "ready.png")
        with open(script, "w") as f:
            if a.cut:  # the phantom's nose points of bench_cut phantom (128^3 demo points x 2), the first three
                pts = "".join(f"point {x * 2},{y * 2},{z * 2}\n" for x, y, z in ((72, 21, 58), (69, 20, 68), (64, 20, 73)))
                f.write(f"tf ct-skin\nview 0 10\nsnap 3\ntool cut\n{pts}wait\nscreenshot {ready}\ninteract F12\n"
                        + (f"screenshot {os.path.abspath(a.picture)}\n" if a.picture else "") + "quit\n")
            else:
                f.write(f"tool none\nscreenshot {ready}\ninteract F12\nquit\n")
        log = os.path.join(tmp, "frames.txt")
        env["VS_VIEWER_FRAME_LOG"] = log
        err = open(os.path.join(tmp, "err.txt"), "w")
        t_start = time.monotonic()
        viewer = subprocess.Popen([cli, "view", volume, "--size", a.size, "--renderer", a.renderer,
                                   "--script", script], env=env, stdout=subprocess.DEVNULL, stderr=err)
        while not os.path.exists(ready):
            if viewer.poll() is not None:
                raise SystemExit("the viewer ended: " + open(os.path.join(tmp, "err.txt")).read())
            time.sleep(0.05)
        t_ready = time.monotonic()

        def xdo(*args):
            subprocess.run(["xdotool", "search", "--sync", "--name", "volscissors view", *args], env=env,
                           check=True, stdout=subprocess.DEVNULL)

        # Layout: panel 340 px, then 2x2 views; 3D top left, axial top right.
        cw, ch = (W - 340) // 2, H // 2
        c3d = (340 + cw // 2, ch // 2 + 10)
        cax = (340 + cw + cw // 2, ch // 2 + 10)
        time.sleep(3)  # the renderer choice and the first full frame settle
        if a.cut:
            return measure_cut(a, xdo, c3d, viewer, log, tmp, t_ready - t_start)
        # Idle.
        c0, t0 = cpu_seconds(viewer.pid), time.monotonic()
        time.sleep(10)
        idle = (cpu_seconds(viewer.pid) - c0) / (time.monotonic() - t0)
        # Rotate drag: 100 moves of 4 px, 20 ms apart (2 s), then release.
        moves = []
        for k in range(1, 101):
            moves += ["mousemove", "--window", "%1", str(c3d[0] - 200 + 4 * k), str(c3d[1]), "sleep", "0.02"]
        t_drag = time.monotonic()
        xdo("mousemove", "--window", "%1", str(c3d[0] - 200), str(c3d[1]), "mousedown", "1", *moves, "mouseup", "1")
        t_release = time.monotonic()
        time.sleep(6)
        # Wheel notches over the axial view, one at a time.
        xdo("mousemove", "--window", "%1", str(cax[0]), str(cax[1]))
        time.sleep(1)
        notches = []
        for _ in range(20):
            t = time.monotonic()
            xdo("click", "4")
            notches.append(t)
            time.sleep(0.3)
        # Live-wire: tool 1, a seed click on the axial view, then moves along a line.
        xdo("key", "1")
        time.sleep(0.5)
        xdo("mousemove", "--window", "%1", str(cax[0] - 60), str(cax[1]), "click", "1")
        time.sleep(2)
        hovers = []
        for k in range(1, 31):
            t = time.monotonic()
            xdo("mousemove", "--window", "%1", str(cax[0] - 60 + 3 * k), str(cax[1] + (k % 5)))
            hovers.append(t)
            time.sleep(0.15)
        xdo("key", "F12")
        viewer.wait(timeout=120)
        frames = read_log(log)

        drag_frames = [f for f in frames if t_drag <= f["done"] <= t_release + 0.05 and f["view3d"] != "kept"]
        intervals = [1000 * (b["done"] - a["done"]) for a, b in zip(drag_frames, drag_frames[1:])]
        full_after = [f for f in frames if f["done"] > t_release and f["view3d"] in ("gpu-full", "cpu-full")]
        full_ms = 1000 * (full_after[0]["done"] - t_release) if full_after else float("nan")

        inside = []  # from the window receiving the event (GLFW callback) to the frame on the screen

        def latency(sent, changed):
            out = []
            for i, t in enumerate(sent):
                nxt = sent[i + 1] if i + 1 < len(sent) else float("inf")
                prev = None
                for f in frames:
                    if f["done"] < t:
                        prev = f
                        continue
                    if f["done"] > nxt:
                        break
                    if f["events"] > 0 and (prev is None or changed(prev, f)):
                        out.append(1000 * (f["done"] - t))
                        inside.append(1000 * (f["done"] - f["input"]))
                        break
                    prev = f
            return out

        wheel = latency(notches, lambda p, f: f["cursor"] != p["cursor"])
        wheel_inside = list(inside)
        inside.clear()
        hover = latency(hovers, lambda p, f: True)
        hover_inside = list(inside)
        frame_ms = [1000 * (b["done"] - a["done"]) for a, b in zip(frames, frames[1:]) if b["events"] > 0
                    and b["view3d"] == "kept" and b["done"] - a["done"] < 1]
        print(f"viewer interaction, {a.size}, --renderer {a.renderer}, volume {a.volume or 'head phantom 256^3'}")
        print(f"  start to first full frame (script screenshot): {t_ready - t_start:.1f} s")
        notes = [l.strip() for l in open(os.path.join(tmp, "err.txt")) if "note" in l]
        for n in notes:
            print("  " + n)
        print(f"  idle CPU: {100 * idle:.2f} % of a core (10 s)")
        print(f"  drag: {len(drag_frames)} new 3D pictures in {1000 * (t_release - t_drag):.0f} ms; "
              f"interval ms {stats(intervals)}; kinds {sorted(set(f['view3d'] for f in drag_frames))}")
        turned = frames[-1]["azimuth"] if frames else float("nan")
        print(f"  full-resolution frame after release: {full_ms:.0f} ms (azimuth now {turned:.1f})")
        print(f"  wheel notch to new slice on screen, ms: {stats(wheel)} (of {len(notches)} notches); "
              f"from the window receiving it: {stats(wheel_inside)}")
        print(f"  live-wire hover to new path on screen, ms: {stats(hover)} (of {len(hovers)} moves); "
              f"from the window receiving it: {stats(hover_inside)}")
        print(f"  UI frames without a new 3D picture (input present), interval ms: {stats(frame_ms)}")
        print(f"  load average at the end: {os.getloadavg()[0]:.1f} (2 cores)")
    finally:
        if viewer and viewer.poll() is None:
            viewer.kill()
        if xvfb:
            xvfb.terminate()
            xvfb.wait()
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
