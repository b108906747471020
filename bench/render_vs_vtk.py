#!/usr/bin/python3
"""volscissors render vs VTK's CPU ray caster (vtkFixedPointVolumeRayCastMapper), same run.

  /usr/bin/python3 bench/render_vs_vtk.py [--build build] [--size 256] [--frames 10] [--blend composite|mip]
                                          [--rounds 3] [--unshaded] [--lighting KA,KD,KS,POWER]
                                          [--workdir /tmp/vs_render_bench] [--images DIR]

Input: the peers' deterministic vessel phantom (make_volumes.py, seed 1234), uint8 N^3,
written here as NRRD (.nhdr + raw, x = numpy's last axis, as VTK sees it). Same transfer
function (our "vessels" preset = raycast_vtk.py's ramps), same 512x512 image, same
sample distance (0.5 voxel), same camera: VTK's final view (ResetCamera, Elevation 20, Zoom 1.5
-> 20 deg vertical field of view, net Azimuth 7 deg), given to us as --camera ... --perspective
--fov 20.

Shading: raycast_vtk.py sets ambient 0.3, diffuse 0.8 (specular 0.2, power 10 by default), but
VTK's CPU ray caster builds its shading tables (vtkEncodedGradientShader) with the ambient
coefficient times the *light's* ambient colour, and the headlight the renderer creates has
ambient colour black: the ambient term is 0. Our renderer reads "ambient" as standard Blinn-Phong
(white ambient light), so to render the same lighting we are given VTK's effective constants,
--lighting 0,0.8,0.2,10 (override with --lighting; docs/notes/render.md has the derivation).
--unshaded turns shading off in both (VTK through a subclass of vtkVolumeProperty whose ShadeOn
does nothing, so raycast_vtk.py runs unchanged otherwise).

Timing: VTK's frame median (camera rotating, includes a small GL blit; first frame with
gradient tables reported apart) vs our frame median (--repeat N of the same view after a
warm-up; prepare with gradients reported apart). With --rounds R (default 3) the two tools run
alternately R times (VTK, ours, VTK, ours, ...); each round gives a ratio VTK frame median /
our frame median from runs seconds apart, and the reported ratio is the median of the rounds'
ratios (fps: medians over the rounds), so load from other processes on this shared machine
hits both alike; each round's ratio is reported too. Quality: mean absolute difference
(RGB, 0..255) and SSIM (luminance, Gaussian window sigma 1.5) between the two pictures, plus
the same numbers between VTK and a black image for scale. Prints one JSON line with "ratio".
Requires (Debian): python3-vtk9 python3-numpy python3-scipy xvfb xauth.
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
PEERS = os.path.abspath(os.path.join(ROOT, "..", "shared", "peers"))


def read_png(path):
    import vtk
    from vtk.util import numpy_support as ns
    r = vtk.vtkPNGReader()
    r.SetFileName(path)
    r.Update()
    img = r.GetOutput()
    w, h, _ = img.GetDimensions()
    a = ns.vtk_to_numpy(img.GetPointData().GetScalars()).reshape(h, w, -1)[::-1]  # VTK rows are bottom-up
    return a[:, :, :3].astype(np.float64)


def ssim(a, b):
    from scipy.ndimage import gaussian_filter
    la = a @ [0.299, 0.587, 0.114]
    lb = b @ [0.299, 0.587, 0.114]
    s = 1.5
    mu_a, mu_b = gaussian_filter(la, s), gaussian_filter(lb, s)
    saa = gaussian_filter(la * la, s) - mu_a ** 2
    sbb = gaussian_filter(lb * lb, s) - mu_b ** 2
    sab = gaussian_filter(la * lb, s) - mu_a * mu_b
    c1, c2 = (0.01 * 255) ** 2, (0.03 * 255) ** 2
    m = ((2 * mu_a * mu_b + c1) * (2 * sab + c2)) / ((mu_a ** 2 + mu_b ** 2 + c1) * (saa + sbb + c2))
    return float(m.mean())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--frames", type=int, default=10)
    ap.add_argument("--blend", choices=["composite", "mip"], default="composite")
    ap.add_argument("--workdir", default="/tmp/vs_render_bench")
    ap.add_argument("--images", default=None, help="also write vtk.png, ours.png and a side-by-side here")
    ap.add_argument("--rounds", type=int, default=3, help="alternate VTK and ours this many times")
    ap.add_argument("--unshaded", action="store_true", help="composite without shading in both tools")
    ap.add_argument("--lighting", default="0,0.8,0.2,10",
                    help="our --lighting KA,KD,KS,POWER (default: VTK's effective constants, see above; "
                         "'default' passes none)")
    a = ap.parse_args()
    os.makedirs(a.workdir, exist_ok=True)
    vs = os.path.join(a.build, "volscissors")
    if not os.path.exists(vs):
        sys.exit(f"missing {vs}: build first (cmake --build {a.build} --target volscissors)")

    n = a.size
    npy = os.path.join(a.workdir, f"vessels_{n}.npy")
    if not os.path.exists(npy):
        subprocess.run(["/usr/bin/python3", os.path.join(PEERS, "make_volumes.py"), "--sizes", str(n),
                        "--outdir", a.workdir], check=True, cwd=PEERS, stdout=subprocess.DEVNULL)
    v = np.ascontiguousarray(np.load(npy))
    raw = os.path.join(a.workdir, f"vessels_{n}.raw")
    nhdr = os.path.join(a.workdir, f"vessels_{n}.nhdr")
    v.tofile(raw)
    with open(nhdr, "w") as f:
        f.write("NRRD0004\ntype: uint8\ndimension: 3\n"
                f"sizes: {v.shape[2]} {v.shape[1]} {v.shape[0]}\nspacings: 1 1 1\nencoding: raw\n"
                f"data file: {os.path.basename(raw)}\n")

    # VTK's final camera (see the docstring).
    c = (np.array(v.shape[::-1], float) - 1) / 2
    radius = np.linalg.norm(np.array(v.shape[::-1], float) - 1) / 2
    dist = radius / np.sin(np.radians(15))
    el, az = np.radians(20), np.radians(7)
    eye = c + dist * np.array([np.cos(el) * np.sin(az), np.sin(el), np.cos(el) * np.cos(az)])
    cam = ",".join(f"{x:.6f}" for x in [*eye, *c, 0, 1, 0])

    tag = a.blend + ("_unshaded" if a.unshaded else "")
    vtk_png = os.path.join(a.workdir, f"vtk_{tag}.png")
    our_png = os.path.join(a.workdir, f"ours_{tag}.png")
    our_json = os.path.join(a.workdir, f"ours_{tag}.json")
    env = dict(os.environ)
    vtk_args = [npy, "--blend", a.blend, "--frames", str(a.frames), "--png", vtk_png]
    if a.unshaded:
        # raycast_vtk.py unchanged, but its vtkVolumeProperty ignores ShadeOn().
        vtk_cmd = ["/usr/bin/python3", "-c",
                   "import runpy, sys, vtk\n"
                   "class Unshaded(vtk.vtkVolumeProperty):\n"
                   "    def ShadeOn(self):\n"
                   "        self.ShadeOff()\n"
                   "vtk.vtkVolumeProperty = Unshaded\n"
                   "sys.argv = sys.argv[1:]\n"
                   "runpy.run_path(sys.argv[0], run_name='__main__')\n",
                   os.path.join(PEERS, "raycast_vtk.py"), *vtk_args]
    else:
        vtk_cmd = ["/usr/bin/python3", os.path.join(PEERS, "raycast_vtk.py"), *vtk_args]
    mode = "full" if a.blend == "composite" else "mip"
    cmd = [vs, "render", nhdr, "--mode", mode, "--tf", "vessels", "--camera", cam, "--perspective", "--fov", "20",
           "--size", "512x512", "--repeat", str(a.frames), "--json", our_json, "--out", our_png]
    if a.blend == "mip":
        cmd.append("--mip-tf")  # VTK's MIP shows colour x opacity of the maximum through the same TF
    elif a.unshaded:
        cmd.append("--no-shading")
    elif a.lighting != "default":  # "default": our defaults (0.3,0.8,0.2,10), e.g. for an older build
        cmd += ["--lighting", a.lighting]
    rounds = []
    for _ in range(max(1, a.rounds)):
        p = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1024x768x24", *vtk_cmd], check=True, cwd=PEERS,
                           capture_output=True, text=True, env=env)
        vtk_res = json.loads(p.stdout.strip().splitlines()[-1])
        subprocess.run(cmd, check=True, stderr=subprocess.DEVNULL)
        ours = json.load(open(our_json))
        rounds.append((vtk_res["timings"]["frame"]["median_s"], ours["seconds"]["frame_median"]))

    A, B = read_png(vtk_png), read_png(our_png)
    mad = float(np.abs(A - B).mean())
    # Most of the picture is black background: also compare on the foreground (pixels where
    # either picture is brighter than 8/255) and SSIM on the foreground's bounding box.
    fg = np.maximum(A.max(axis=2), B.max(axis=2)) > 8
    ys, xs = np.nonzero(fg)
    y0, y1, x0, x1 = max(ys.min() - 8, 0), ys.max() + 9, max(xs.min() - 8, 0), xs.max() + 9
    mad_fg = float(np.abs(A - B)[fg].mean())
    mad_fg_black = float(A[fg].mean())
    ssim_box = ssim(A[y0:y1, x0:x1], B[y0:y1, x0:x1])
    ssim_box_black = ssim(A[y0:y1, x0:x1], np.zeros_like(A[y0:y1, x0:x1]))
    black = np.zeros_like(A)
    vtk_frame = float(np.median([r[0] for r in rounds]))
    our_frame = float(np.median([r[1] for r in rounds]))
    out = {
        "task": f"raycast_{tag}", "input": npy, "shape": list(v.shape), "image": [512, 512],
        "rounds": [{"vtk_frame_s": r[0], "our_frame_s": r[1], "ratio": round(r[0] / r[1], 3)} for r in rounds],
        "vtk": {"version": vtk_res.get("version"), "frame_s": vtk_frame, "fps": round(1 / vtk_frame, 3),
                "first_frame_s": vtk_res["timings"]["first_frame"]["median_s"],
                "threads": vtk_res.get("mapper_threads")},
        "ours": {"frame_s": our_frame, "fps": round(1 / our_frame, 3), "prepare_s": ours["seconds"]["prepare"],
                 "threads": ours["threads"], "samples": ours["samples"]},
        "ratio": round(float(np.median([r[0] / r[1] for r in rounds])), 3),
        "quality": {"mad_rgb": round(mad, 3), "ssim": round(ssim(A, B), 4),
                    "foreground_pixels": int(fg.sum()), "mad_rgb_foreground": round(mad_fg, 3),
                    "mad_vtk_vs_black_foreground": round(mad_fg_black, 3), "ssim_foreground_box": round(ssim_box, 4),
                    "ssim_vtk_vs_black_foreground_box": round(ssim_box_black, 4),
                    "mad_vtk_vs_black": round(float(np.abs(A - black).mean()), 3),
                    "ssim_vtk_vs_black": round(ssim(A, black), 4)},
        "our_command": " ".join(cmd),
    }
    if a.images:
        os.makedirs(a.images, exist_ok=True)
        import vtk
        from vtk.util import numpy_support as ns
        side = np.concatenate([A, np.full((A.shape[0], 8, 3), 255.0), B], axis=1).astype(np.uint8)
        img = vtk.vtkImageData()
        img.SetDimensions(side.shape[1], side.shape[0], 1)
        img.GetPointData().SetScalars(ns.numpy_to_vtk(side[::-1].reshape(-1, 3).copy(), deep=True))
        w = vtk.vtkPNGWriter()
        w.SetFileName(os.path.join(a.images, f"render_vs_vtk_{tag}.png"))
        w.SetInputData(img)
        w.Write()
    print(json.dumps(out))
    per = ", ".join(f"{r['ratio']:.2f}" for r in out["rounds"])
    print(f"RATIO {tag} (VTK frame / ours, median over {len(rounds)} alternating rounds): {out['ratio']:.2f}x   "
          f"VTK {out['vtk']['fps']} fps, ours {out['ours']['fps']} fps (rounds: {per}); foreground MAD {mad_fg:.2f}/255 (VTK vs black {mad_fg_black:.2f}), "
          f"SSIM on the foreground box {ssim_box:.3f} (VTK vs black {ssim_box_black:.3f})", file=sys.stderr)


if __name__ == "__main__":
    main()
