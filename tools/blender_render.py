# Renders one frame of a bimart .glb with Blender (Cycles on the CPU, headless):
#   blender --background --factory-startup --python tools/blender_render.py -- \
#       SCENE.glb FRAME OUT.png [FPS] [SIZE]
# Imports the scene with Blender's glTF importer, adds a camera that frames the hands and the
# object from the person's side and above, a sun and a soft world light, and renders.
import math
import sys

import bpy
import numpy

# Debian 12's Blender 3.4 glTF importer uses numpy.bool, which its numpy 1.24 removed
# (KhronosGroup/glTF-Blender-IO#1844, fixed in Blender 3.5): restore the alias.
if "bool" not in numpy.__dict__:
    numpy.bool = bool
from mathutils import Vector

args = sys.argv[sys.argv.index("--") + 1:]
glb, frame, out = args[0], int(args[1]), args[2]
fps = float(args[3]) if len(args) > 3 else 30.0
size = int(args[4]) if len(args) > 4 else 640

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = max(1, round(fps))
scene.render.fps_base = scene.render.fps / fps
bpy.ops.import_scene.gltf(filepath=glb)
scene.frame_set(frame)

# Bounds of the evaluated meshes at this frame.
depsgraph = bpy.context.evaluated_depsgraph_get()
lo, hi = Vector((1e9, 1e9, 1e9)), Vector((-1e9, -1e9, -1e9))
for ob in scene.objects:
    if ob.type != "MESH":
        continue
    ev = ob.evaluated_get(depsgraph)
    mesh = ev.to_mesh()
    for v in mesh.vertices:
        w = ev.matrix_world @ v.co
        lo = Vector(map(min, lo, w))
        hi = Vector(map(max, hi, w))
    ev.to_mesh_clear()
centre, radius = (lo + hi) / 2, max((hi - lo).length / 2, 0.05)

# The person's side is glTF +z, Blender -y; look from there and above.
direction = Vector((0.35, -1.0, 0.6)).normalized()
cam_data = bpy.data.cameras.new("camera")
cam_data.lens = 50
cam = bpy.data.objects.new("camera", cam_data)
scene.collection.objects.link(cam)
fov = 2 * math.atan(cam_data.sensor_width / (2 * cam_data.lens))
cam.location = centre + direction * (radius / math.sin(fov / 2))
cam.rotation_euler = (centre - cam.location).to_track_quat("-Z", "Y").to_euler()
scene.camera = cam

sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
sun.data.energy = 3.0
sun.rotation_euler = (math.radians(40), math.radians(15), math.radians(30))
scene.collection.objects.link(sun)
world = bpy.data.worlds.new("world")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs[0].default_value = (0.9, 0.9, 0.92, 1)
world.node_tree.nodes["Background"].inputs[1].default_value = 0.5
scene.world = world

scene.view_settings.view_transform = "Standard"
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 48
scene.cycles.use_denoising = False  # Debian builds Cycles without OpenImageDenoise
scene.render.resolution_x = scene.render.resolution_y = size
scene.render.filepath = out
bpy.ops.render.render(write_still=True)
print("blender_render: wrote", out)
