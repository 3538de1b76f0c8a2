"""Builds an axis-aligned box room (seen from inside) in the open Blender file, for the face-order
and depth check of tests/blender/blender_capture.sh: the room spans ROOM_MIN..ROOM_MAX in calf's
frame (calf (x, y, z) = Blender (x, z, -y)), an emissive grey, and nothing else.

    blender -b --factory-startup -P tests/blender/box_room.py -P blender/calf_capture/cli.py -- ...
"""

import bpy

ROOM_MIN = (-1.5, -0.8, -1.3)
ROOM_MAX = (2.1, 1.7, 1.9)

for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj)
scene = bpy.context.scene
scene.frame_start = scene.frame_end = 1


def blender(p):
    return (p[0], -p[2], p[1])


corners = [blender((ROOM_MAX[0] if i & 1 else ROOM_MIN[0], ROOM_MAX[1] if i & 2 else ROOM_MIN[1],
                    ROOM_MAX[2] if i & 4 else ROOM_MIN[2])) for i in range(8)]
quads = [(0, 2, 6, 4), (1, 5, 7, 3), (0, 4, 5, 1), (2, 3, 7, 6), (0, 1, 3, 2), (4, 6, 7, 5)]
mesh = bpy.data.meshes.new("room")
mesh.from_pydata(corners, [], quads)
mat = bpy.data.materials.new("room")
mat.use_nodes = True
nodes = mat.node_tree.nodes
emission = nodes.new("ShaderNodeEmission")
emission.inputs["Color"].default_value = (0.5, 0.5, 0.5, 1)
mat.node_tree.links.new(emission.outputs["Emission"], nodes["Material Output"].inputs["Surface"])
mesh.materials.append(mat)
room = bpy.data.objects.new("room", mesh)
scene.collection.objects.link(room)
