"""Builds an axis-aligned box room (seen from inside) with an axis-aligned block standing in it, in
the open Blender file, for the face-order, depth and coverage check of
tests/blender/blender_capture.sh: the room spans ROOM_MIN..ROOM_MAX and the block BLOCK_MIN..
BLOCK_MAX in calf's frame (calf (x, y, z) = Blender (x, z, -y)), both an emissive grey.

    blender -b --factory-startup -P tests/blender/box_room.py -P blender/calf_capture/cli.py -- ...
"""

import bpy

ROOM_MIN = (-1.5, -0.8, -1.3)
ROOM_MAX = (2.1, 1.7, 1.9)
BLOCK_MIN = (0.6, -0.5, 0.5)
BLOCK_MAX = (1.2, 0.2, 1.1)

for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj)
scene = bpy.context.scene
scene.frame_start = scene.frame_end = 1


def blender(p):
    return (p[0], -p[2], p[1])


def box_mesh(name, lo, hi):
    corners = [blender((hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1],
                        hi[2] if i & 4 else lo[2])) for i in range(8)]
    quads = [(0, 2, 6, 4), (1, 5, 7, 3), (0, 4, 5, 1), (2, 3, 7, 6), (0, 1, 3, 2), (4, 6, 7, 5)]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(corners, [], quads)
    mesh.materials.append(mat)
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)


mat = bpy.data.materials.new("grey")
mat.use_nodes = True
nodes = mat.node_tree.nodes
emission = nodes.new("ShaderNodeEmission")
emission.inputs["Color"].default_value = (0.5, 0.5, 0.5, 1)
mat.node_tree.links.new(emission.outputs["Emission"], nodes["Material Output"].inputs["Surface"])
box_mesh("room", ROOM_MIN, ROOM_MAX)
box_mesh("block", BLOCK_MIN, BLOCK_MAX)
