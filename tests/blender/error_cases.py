"""The add-on's refusals, in one Blender process (tests/blender/blender_capture.sh errors): each
case runs the headless command's argument handling (cli.run) and must raise the expected calf
error id, as a usage error (exit 2) or not (exit 1), with a one-line message, and write no
manifest. The last case disables the Cycles add-on. Exit status 0 when every case holds.

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
    ("no_cycles", "CALF-E014", False, ["--rig", "list:0,1,0"]),
]
failed = 0
for name, want, usage, args in CASES:
    out = os.path.join(work, name if name != "unwritable" else "afile/set")
    if name == "no_cycles":
        bpy.ops.preferences.addon_disable(module="cycles")
    try:
        cli.run(["--out", out] + args)
        got = None
    except capture.CaptureError as e:
        got = e
    ok = (got is not None and got.error_id == want and got.usage == usage and
          "\n" not in str(got) and not os.path.exists(os.path.join(out, "manifest.json")))
    failed += not ok
    print("error_cases: %s %s: %s" % ("ok" if ok else "FAIL", name,
                                      got if got is not None else "no error"))
sys.stdout.flush()
os._exit(1 if failed else 0)
