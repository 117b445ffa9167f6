# Run by blender_test (tests/outputs/blender_test.cc):
#   blender --background --factory-startup --python blender_dump.py -- SCENE.glb FPS OUT.json F1,F2,...
# Imports the scene with Blender's own glTF importer and writes what the test checks: the
# armatures and their bones, the meshes, the animation's frame range, and each mesh's
# evaluated vertices at the given frames, back in glTF axes (metres, +y up).
import json
import sys

import bpy
import numpy

# Debian 12's Blender 3.4 glTF importer uses numpy.bool, which its numpy 1.24 removed
# (KhronosGroup/glTF-Blender-IO#1844, fixed in Blender 3.5): restore the alias.
if "bool" not in numpy.__dict__:
    numpy.bool = bool

glb, fps, out, frames = sys.argv[sys.argv.index("--") + 1:]
fps = float(fps)
frames = [int(f) for f in frames.split(",")]

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = max(1, round(fps))
scene.render.fps_base = scene.render.fps / fps
bpy.ops.import_scene.gltf(filepath=glb)

result = {"armatures": {}, "meshes": {}, "actions": {}, "frames": {}}
for ob in bpy.data.objects:
    if ob.type == "ARMATURE":
        result["armatures"][ob.name] = [b.name for b in ob.data.bones]
    elif ob.type == "MESH":
        result["meshes"][ob.name] = {"vertices": len(ob.data.vertices),
                                     "shape_keys": len(ob.data.shape_keys.key_blocks) if ob.data.shape_keys else 0}
for action in bpy.data.actions:
    result["actions"][action.name] = list(action.frame_range)

for f in frames:
    scene.frame_set(f)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    per_mesh = {}
    for ob in bpy.data.objects:
        if ob.type != "MESH":
            continue
        ev = ob.evaluated_get(depsgraph)
        mesh = ev.to_mesh()
        m = ev.matrix_world
        # Blender is +z up; its importer maps glTF (x, y, z) to (x, -z, y).
        per_mesh[ob.name] = [[w.x, w.z, -w.y] for w in (m @ v.co for v in mesh.vertices)]
        ev.to_mesh_clear()
    result["frames"][str(f)] = per_mesh

with open(out, "w") as fh:
    json.dump(result, fh)
print("blender_dump: wrote", out)
