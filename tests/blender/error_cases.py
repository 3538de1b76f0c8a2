"""The add-on's refusals, in one Blender process (tests/blender/blender_capture.sh errors): each
case runs the headless command's argument handling (cli.run) and must raise the expected calf
error id, as a usage error (exit 2) or not (exit 1), with a one-line message, and write no
manifest. The last case disables the Cycles add-on. Before them, the Cycles settings that the
add-on's first colour render of a capture set and of ground truth runs with (samples, adaptive
sampling, its threshold, the time limit) for the default and a given --adaptive-threshold, and that the scene's own
settings are back afterwards (the render itself is stubbed out). Exit status 0 when every case
holds.

    blender -b --factory-startup -P tests/blender/error_cases.py -- WORK_DIR
"""

import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "blender"))
from calf_capture import capture, cli  # noqa: E402

work = sys.argv[sys.argv.index("--") + 1]
open(os.path.join(work, "afile"), "w").close()
CASES = [  # name, error id, usage?, arguments
    ("empty_range", "CALF-E006", True, ["--rig", "list:0,1,0", "--frames", "5-3"]),
    ("face_size_0", "CALF-E006", True, ["--rig", "list:0,1,0", "--face-size", "0"]),
    ("face_size_big", "CALF-E006", True, ["--rig", "list:0,1,0", "--face-size", "16385"]),
    ("unwritable", "CALF-E004", False, ["--rig", "list:0,1,0"]),
    ("bad_rig", "CALF-E006", True, ["--rig", "ring:0,1,0,0,0"]),
    ("no_viewpoints", "CALF-E006", True, []),
    ("no_collection", "CALF-E006", True, ["--collection", "nothing"]),
    ("gt_no_path", "CALF-E006", True, ["--ground-truth"]),
    ("gt_no_camera", "CALF-E006", True, ["--ground-truth", "--camera", "nothing"]),
    ("unknown_option", "CALF-E006", True, ["--rig", "list:0,1,0", "--colour", "red"]),
    ("adaptive_negative", "CALF-E006", True, ["--rig", "list:0,1,0", "--adaptive-threshold",
                                              "-0.01"]),
    ("adaptive_above_1", "CALF-E006", True, ["--ground-truth", "--eye-path", "EYE",
                                             "--adaptive-threshold", "1.5"]),
    ("no_cycles", "CALF-E014", False, ["--rig", "list:0,1,0"]),
]
eye = os.path.join(work, "eye.json")
with open(eye, "w") as f:
    f.write('{"format": "calf-eye-path", "version": 1, "width": 4, "height": 3, '
            '"fov_y_degrees": 60, "poses": [{"time": 0, "position": [0, 1, 0], '
            '"forward": [0, 0, -1]}]}')
failed = 0


class _Rendered(Exception):
    pass


def _spy(renderer, width, height, samples, filter_width, seed):
    c = renderer.scene.cycles
    raise _Rendered((samples, c.use_adaptive_sampling, round(c.adaptive_threshold, 6),
                     c.time_limit))


scene = bpy.context.scene
real_render_once = capture._Renderer._render_once
capture._Renderer._render_once = _spy
SETTINGS = [  # name, arguments, (samples, adaptive sampling, threshold, time limit) of the first
    # render
    ("cycles_capture_default", ["--rig", "list:0,1,0", "--face-size", "2"], (8, False, 0.02, 0)),
    ("cycles_capture_adaptive", ["--rig", "list:0,1,0", "--face-size", "2",
                                 "--adaptive-threshold", "0.05"], (8, True, 0.05, 0)),
    ("cycles_gt_default", ["--ground-truth", "--eye-path", eye], (8, False, 0.02, 0)),
    ("cycles_gt_adaptive", ["--ground-truth", "--eye-path", eye, "--adaptive-threshold",
                            "0.004"], (8, True, 0.004, 0)),
]
for name, args, want in SETTINGS:
    # The scene's own settings differ from everything the add-on sets, and must come back.
    scene.cycles.use_adaptive_sampling, scene.cycles.adaptive_threshold = True, 0.02
    scene.cycles.samples = 3
    scene.cycles.time_limit = 0.5  # a user's render time limit, which would cut samples short
    try:
        cli.run(["--out", os.path.join(work, name), "--samples", "8"] + args)
        got = "no render"
    except _Rendered as e:
        got = e.args[0]
    except capture.CaptureError as e:
        got = str(e)
    back = (scene.cycles.samples, scene.cycles.use_adaptive_sampling,
            round(scene.cycles.adaptive_threshold, 6), scene.cycles.time_limit)
    ok = got == want and back == (3, True, 0.02, 0.5)
    failed += not ok
    print("error_cases: %s %s: first render (samples, adaptive, threshold, time limit) %s, want "
          "%s; scene "
          "after %s" % ("ok" if ok else "FAIL", name, got, want, back))
capture._Renderer._render_once = real_render_once

for name, want, usage, args in CASES:
    args = [eye if a == "EYE" else a for a in args]
    out = os.path.join(work, name if name != "unwritable" else "afile/set")
    if name == "no_cycles":
        bpy.ops.preferences.addon_disable(module="cycles")
    try:
        cli.run(["--out", out] + args)
        got = None
    except capture.CaptureError as e:
        got = e
    ok = (got is not None and got.error_id == want and got.usage == usage and
          "\n" not in str(got) and not os.path.exists(os.path.join(out, "manifest.json")) and
          (not name.startswith("adaptive_") or "is outside 0..1" in str(got)))
    failed += not ok
    print("error_cases: %s %s: %s" % ("ok" if ok else "FAIL", name,
                                      got if got is not None else "no error"))
sys.stdout.flush()
os._exit(1 if failed else 0)
