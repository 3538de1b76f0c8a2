"""Animates the Blender test scene (tests/blender/make_scene.py) over four frames for the
render-noise measurements of docs/ENCODER.md "Keyframes and render noise": the red cube keeps
moving, and the sun (with a soft 10-degree disc) turns a little each frame, so that shading and
shadows change on static geometry as in a day-light animation.
    blender -b --factory-startup -P tests/blender/make_scene.py -P tests/blender/noise_scene.py \
        [-- OUT.blend]
"""
import math
import sys

import bpy

scene = bpy.context.scene
scene.frame_start, scene.frame_end = 1, 4
cube = bpy.data.objects["Cube"]
cube.location.x = -0.3
cube.rotation_euler.z = 0.9
cube.keyframe_insert("location", frame=4)
cube.keyframe_insert("rotation_euler", frame=4)
sun = bpy.data.objects["Sun"]
sun.data.angle = math.radians(10)
for frame in range(1, 5):
    sun.rotation_euler = (0.6 + 0.04 * frame, 0.2, 0.8 + 0.06 * frame)
    sun.keyframe_insert("rotation_euler", frame=frame)
scene.frame_set(1)
argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if argv and argv[0].endswith(".blend"):
    bpy.ops.wm.save_as_mainfile(filepath=argv[0])
