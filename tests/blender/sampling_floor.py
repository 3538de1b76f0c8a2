"""What Cycles' adaptive sampling does to the add-on's renders (docs/BLENDER.md, "Cost and
quality"): one pose of the test scene's camera (tests/blender/make_scene.py, frame 1) rendered by
the add-on's renderer at W x H with adaptive sampling off and at each threshold, at each sample
count, twice (seeds 0 and 1); prints per setting the seconds per render, the PSNR of the seed-0
render against a reference rendered with adaptive sampling off at REF samples (seed 100), and the
noise floor as calf-play --compare prints it (seed 0 against seed 1). PSNR as calf-play computes
it (player/src/image_compare.cc: sRGB-encoded, clamped to 0..1).

    blender -b --factory-startup -P tests/blender/make_scene.py -P tests/blender/sampling_floor.py \
        -- [--size 64x48] [--samples 16,64,256] [--thresholds 0,0.01] [--ref 4096] [--threads 2]
"""

import argparse
import math
import os
import sys
import time

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "blender"))
from calf_capture import capture  # noqa: E402

p = argparse.ArgumentParser(prog="sampling_floor.py")
p.add_argument("--size", default="64x48")
p.add_argument("--samples", default="16,64,256")
p.add_argument("--thresholds", default="0,0.01")
p.add_argument("--ref", type=int, default=4096)
p.add_argument("--threads", type=int, default=2)
a = p.parse_args(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
width, height = (int(v) for v in a.size.split("x"))
scene = bpy.context.scene
path = capture.eye_path_from_camera(scene, "Eye", width, height, 1, 1)
pose = path["poses"][0]
forward, up = capture._pose_frame(pose)
matrix = capture._matrix(pose["position"], forward, up)
fov_y = math.radians(path["fov_y_degrees"])
scene.frame_set(1)


def render(samples, threshold, seed):
    r = capture._Renderer(scene, samples, seed, 0.01, 1e5, a.threads, threshold)
    try:
        start = time.monotonic()
        rgb, _ = r.render(matrix, fov_y, width, height)
        return rgb, time.monotonic() - start
    finally:
        r.close()


def srgb(v):
    v = min(max(v, 0.0), 1.0)
    return 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055


def psnr(x, y):
    s = sum((srgb(u) - srgb(v)) ** 2 for u, v in zip(x, y))
    return math.inf if s == 0 else 10 * math.log10(len(x) / s)


ref, t = render(a.ref, 0.0, 100)
print("sampling_floor: %dx%d, reference %d samples adaptive off: %.1f s" %
      (width, height, a.ref, t))
for threshold in (float(v) for v in a.thresholds.split(",")):
    for samples in (int(v) for v in a.samples.split(",")):
        img0, t0 = render(samples, threshold, 0)
        img1, t1 = render(samples, threshold, 1)
        print("sampling_floor: adaptive %-8s samples %5d: %6.2f s per render, against the "
              "reference %.2f dB, noise floor %.2f dB" %
              ("off" if threshold == 0 else threshold, samples, (t0 + t1) / 2, psnr(img0, ref),
               psnr(img0, img1)))
        sys.stdout.flush()
sys.stdout.flush()
os._exit(0)
