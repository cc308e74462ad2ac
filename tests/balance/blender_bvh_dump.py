"""Import a BVH file with Blender's own importer (io_anim_bvh) and write every
bone's head, in the file's axes and units, at every frame, as JSON.

Run: blender -b --factory-startup --python-exit-code 1 --python blender_bvh_dump.py -- IN.bvh OUT.json
"""
import builtins
import json
import sys

import bpy
from io_anim_bvh import import_bvh

# Debian's Blender 3.4 runs on Python 3.11, which dropped open()'s 'U' mode;
# the importer still asks for it. Only the mode is mended, not the reader.
import_bvh.open = lambda path, mode="r", *a, **k: builtins.open(path, mode.replace("U", ""), *a, **k)

source, target = sys.argv[sys.argv.index("--") + 1 :][:2]
# axis_up Y, axis_forward -Z (the importer's defaults): a file's (x, y, z)
# becomes Blender's (x, -z, y); written back below.
result = bpy.ops.import_anim.bvh(filepath=source, rotate_mode="NATIVE", axis_forward="-Z", axis_up="Y",
                                 global_scale=1.0, frame_start=1, update_scene_fps=False,
                                 update_scene_duration=True)
if result != {"FINISHED"}:
    sys.exit(f"import failed: {result}")
armature = bpy.context.object
scene = bpy.context.scene
first, last = (int(round(f)) for f in armature.animation_data.action.frame_range)
bones = {b.name: [] for b in armature.pose.bones}
for frame in range(first, last + 1):
    scene.frame_set(frame)
    for b in armature.pose.bones:
        x, y, z = armature.matrix_world @ b.head
        bones[b.name].extend((x, z, -y))
with open(target, "w") as out:
    json.dump({"blender": bpy.app.version_string, "frames": last - first + 1, "bones": bones}, out)
