# SPDX-License-Identifier: LGPL-2.1-or-later
# Blender's Defocus compositor node on one corpus scene folder: the anchor the presets are held
# against. Run inside Blender 3.4 (scripts/corpus/anchors.py runs it):
#   blender -b --factory-startup --python scripts/corpus/blender_defocus.py -- SCENE_DIR OUT.exr
# Calibrated as ../shared/data/README.md measured on the bundled scene: Z buffer on, preview off,
# blur_max above the largest CoC radius, and node f-stop = N x (1000 / sensor width mm) x
# (1 - f / focus); the camera's own f-stop gives about 27x too much blur in 3.4. Angle 0 gives the
# hexagon orientation of Cycles' rotation 0.
import json
import math
import os
import sys

import bpy

scene_dir, out_path = sys.argv[sys.argv.index("--") + 1:][:2]
meta = json.load(open(os.path.join(scene_dir, "scene.json")))
lens = meta["lens"]
if lens["blades"] != 6:
    sys.exit("blender_defocus.py: only 6 blades")

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
colour = bpy.data.images.load(os.path.abspath(os.path.join(scene_dir, meta["color"])))
depth = bpy.data.images.load(os.path.abspath(os.path.join(scene_dir, meta["depth"])))
depth.colorspace_settings.name = "Non-Color"
scene.render.resolution_x, scene.render.resolution_y = colour.size[0], colour.size[1]
scene.render.resolution_percentage = 100
scene.view_settings.view_transform = "Standard"

cam_data = bpy.data.cameras.new("camera")
cam_data.lens = lens["focalLengthMm"]
cam_data.sensor_fit = "HORIZONTAL"
cam_data.sensor_width = lens["sensorWidthMm"]
cam_data.dof.focus_distance = lens["focusM"]
cam = bpy.data.objects.new("camera", cam_data)
scene.collection.objects.link(cam)
scene.camera = cam

scene.use_nodes = True
tree = scene.node_tree
tree.nodes.clear()
image = tree.nodes.new("CompositorNodeImage")
image.image = colour
zimage = tree.nodes.new("CompositorNodeImage")
zimage.image = depth
z = zimage.outputs["Image"]
if meta["depth"].lower().endswith(".png"):
    # 16-bit PNG: the node gives value / 65535; metres = value / units per metre.
    scale = tree.nodes.new("CompositorNodeMath")
    scale.operation = "MULTIPLY"
    scale.inputs[1].default_value = 65535.0 / meta.get("depthUnitsPerMetre", 1000.0)
    tree.links.new(z, scale.inputs[0])
    z = scale.outputs[0]
defocus = tree.nodes.new("CompositorNodeDefocus")
defocus.bokeh = "HEXAGON"
defocus.angle = 0.0
defocus.use_zbuffer = True
defocus.use_preview = False
defocus.use_gamma_correction = False
defocus.scene = scene
f_mm, focus_mm = lens["focalLengthMm"], lens["focusM"] * 1000.0
defocus.f_stop = lens["fNumber"] * (1000.0 / lens["sensorWidthMm"]) * (1.0 - f_mm / focus_mm)
# Largest CoC radius of the scene's depth range (1.2 x for margin), pixels.
near = float(sys.argv[sys.argv.index("--") + 3]) if len(sys.argv) > sys.argv.index("--") + 3 else 64.0
defocus.blur_max = max(8.0, near)
tree.links.new(image.outputs["Image"], defocus.inputs["Image"])
tree.links.new(z, defocus.inputs["Z"])
composite = tree.nodes.new("CompositorNodeComposite")
tree.links.new(defocus.outputs["Image"], composite.inputs["Image"])

scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.render.image_settings.color_mode = "RGB"
scene.render.filepath = os.path.abspath(out_path)
bpy.ops.render.render(write_still=True)
print(f"blender_defocus.py: f-stop {defocus.f_stop:.2f}, blur_max {defocus.blur_max:.0f} -> {out_path}")
