"""Headless entry of the calf capture add-on:

    blender -b scene.blend -P blender/calf_capture/cli.py -- --out DIR [options]

renders a calf capture set (or, with --ground-truth, ground truth along an eye path) of the scene
with Cycles. `-- --help` lists every option and its default. Errors are one line,
`calf-blender: CALF-Ennn ...`, with exit status 2 for a usage error and 1 otherwise.
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from calf_capture import capture  # noqa: E402

PROG = "calf-blender"


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise capture.CaptureError("CALF-E006", message, usage=True)


def _triple_pair(text):
    v = [float(t) for t in text.split(",")]
    if len(v) != 6:
        raise ValueError(text)
    return (tuple(v[:3]), tuple(v[3:]))


def _frames(text):
    first, dash, last = text.partition("-")
    return (int(first), int(last if dash else first))


def _size(text):
    w, x, h = text.lower().partition("x")
    return (int(w), int(h))


def parser():
    p = _Parser(
        prog="blender -b SCENE.blend -P blender/calf_capture/cli.py --",
        description="Render a calf capture set (format/CAPTURE.md) of the open Blender scene with "
        "Cycles: six 90-degree faces per viewpoint and frame, scene-linear colour, radial depth "
        "(sky +inf), manifest.json written last. With --ground-truth, render ground truth along "
        "an eye path for calf-play --compare instead. Positions are in calf's frame: calf "
        "(x, y, z) = Blender (x, z, -y), as Blender's glTF exporter writes (docs/BLENDER.md).")
    p.add_argument("--out", default="", metavar="DIR",
                   help="output folder (created): the capture set, or the ground truth; required "
                   "unless --write-eye-path")
    g = p.add_argument_group("viewpoints and view volume (capture set)")
    g.add_argument("--rig", default="", metavar="STRING",
                   help="a calf rig string in calf coordinates, as calf-capture --rig takes it: "
                   "box:CX,CY,CZ,HX,HY,HZ | ring:N,R,CX,CY,CZ | sphere:N,R,CX,CY,CZ | "
                   "grid:NX,NY,NZ,X0,Y0,Z0,X1,Y1,Z1 | list:X,Y,Z/X,Y,Z/... (no default; this or "
                   "--collection)")
    g.add_argument("--collection", default="", metavar="NAME",
                   help="the viewpoints are the empties of this collection (sorted by name, "
                   "each named after its empty), placed where they are at the first frame")
    g.add_argument("--volume-object", default="", metavar="NAME",
                   help="the view volume is this object's world bounding box (e.g. a box "
                   "object); default: the rig's own volume, or the viewpoints' bounding box")
    g.add_argument("--volume", type=_triple_pair, default=None, metavar="X0,Y0,Z0,X1,Y1,Z1",
                   help="the view volume in calf coordinates (default: as --volume-object says)")
    g = p.add_argument_group("rendering")
    g.add_argument("--frames", type=_frames, default=None, metavar="FIRST-LAST",
                   help="scene frames to render, inclusive (capture frame 0 is FIRST); default "
                   "the scene's frame range. Also where eye-path time 0 lies for --ground-truth")
    g.add_argument("--face-size", type=int, default=64, metavar="N",
                   help="texels per face side, 1..16384; default 64")
    g.add_argument("--samples", type=int, default=64, metavar="N",
                   help="Cycles samples per pixel of the colour renders; default 64")
    g.add_argument("--adaptive-threshold", type=float, default=None, metavar="T",
                   help="Cycles' adaptive sampling: a pixel stops sampling once its noise is "
                   "below T (0..1); 0 = off, every pixel gets --samples. Default 0 for the "
                   "capture set and the ground truth (with adaptive sampling on, the ground "
                   "truth's noise floor stops falling as --samples rises)")
    g.add_argument("--seed", type=int, default=0,
                   help="Cycles seed; default 0 (the noise floor of --ground-truth uses seed + 1)")
    g.add_argument("--clip-start", type=float, default=0.01, metavar="D",
                   help="near clip distance of the face cameras; default 0.01")
    g.add_argument("--clip-end", type=float, default=1e5, metavar="D",
                   help="far clip distance; anything beyond it is sky (+inf); default 100000")
    g.add_argument("--coverage", action="store_true",
                   help="also write coverage (format/CAPTURE.md \"Coverage\"; a version-2 set) "
                   "from a depth pass 4 times finer than the faces; default off")
    g.add_argument("--threads", type=int, default=0, metavar="N",
                   help="render threads; default 0 = Blender's choice (all cores)")
    g = p.add_argument_group("ground truth")
    g.add_argument("--ground-truth", action="store_true",
                   help="render ground truth along an eye path into --out (gt_NNNNN.exr, "
                   "eye_path.json last, noise-floor/ at seed + 1) instead of a capture set")
    g.add_argument("--eye-path", default="", metavar="FILE",
                   help="a calf eye-path JSON (format/CAPTURE.md) to render")
    g.add_argument("--camera", default="", metavar="NAME",
                   help="instead of --eye-path: this camera's animation over the frame range, one "
                   "pose per frame")
    g.add_argument("--gt-size", type=_size, default=None, metavar="WxH",
                   help="ground-truth image size; default the eye path's own size (with --camera: "
                   "128x128)")
    g.add_argument("--no-noise-floor", action="store_true",
                   help="skip the second render at seed + 1 (default: written to "
                   "DIR/noise-floor/)")
    g.add_argument("--write-eye-path", default="", metavar="FILE",
                   help="with --camera: write the camera's eye path to FILE and render nothing")
    return p


def run(argv):
    import bpy

    args = parser().parse_args(argv)
    if not args.out and not args.write_eye_path:
        raise capture.CaptureError("CALF-E006", "--out DIR is required", usage=True)
    scene = bpy.context.scene
    if args.ground_truth or args.write_eye_path:
        if bool(args.eye_path) == bool(args.camera):
            raise capture.CaptureError("CALF-E006", "give one of --eye-path FILE or --camera NAME",
                                       usage=True)
        first, last = capture.frame_range(scene, _options(args))
        if args.camera:
            w, h = args.gt_size or (128, 128)
            eye_path = capture.eye_path_from_camera(scene, args.camera, w, h, first, last)
        else:
            eye_path = capture.read_eye_path(args.eye_path)
            if args.gt_size:
                eye_path["width"], eye_path["height"] = args.gt_size
        if args.write_eye_path:
            capture.write_json_atomically(args.write_eye_path, eye_path)
            print("%s: wrote %d poses to %s" % (PROG, len(eye_path["poses"]), args.write_eye_path))
            return
        capture.ground_truth(scene, eye_path, args.out, args.samples, args.seed, first,
                             not args.no_noise_floor, args.clip_start, args.clip_end,
                             args.threads, adaptive_threshold=capture.GT_ADAPTIVE_THRESHOLD
                             if args.adaptive_threshold is None else args.adaptive_threshold)
        print("%s: wrote ground truth of %d poses (%dx%d) to %s" %
              (PROG, len(eye_path["poses"]), eye_path["width"], eye_path["height"], args.out))
        return
    m = capture.capture_set(scene, _options(args))
    print("%s: wrote %d viewpoint(s) x %d frame(s), face size %d to %s" %
          (PROG, len(m["viewpoints"]), m["frame_count"], m["face_size"], args.out))


def _options(args):
    o = capture.CaptureOptions()
    o.out = args.out
    o.rig, o.collection = args.rig, args.collection
    o.volume_object, o.volume = args.volume_object, args.volume
    o.frames = args.frames
    o.face_size, o.samples, o.seed = args.face_size, args.samples, args.seed
    o.clip_start, o.clip_end, o.threads = args.clip_start, args.clip_end, args.threads
    o.coverage = args.coverage
    if args.adaptive_threshold is not None:
        o.adaptive_threshold = args.adaptive_threshold
    return o


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    try:
        run(argv)
    except capture.CaptureError as e:
        sys.stdout.flush()
        print("%s: %s" % (PROG, e), file=sys.stderr)
        sys.stderr.flush()
        os._exit(2 if e.usage else 1)
    except KeyboardInterrupt:
        os._exit(130)
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)


if __name__ == "__main__":
    main()
