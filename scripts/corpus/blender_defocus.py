# SPDX-License-Identifier: LGPL-2.1-or-later
# Blender's Defocus compositor node on one corpus scene folder: the anchor the presets are held
# against. Run inside Blender 3.4 (scripts/corpus/anchors.py runs it):
#   blender -b --factory-startup --python scripts/corpus/blender_defocus.py -- SCENE_DIR OUT.exr \
#       [BLUR_MAX_PX [NODE_BOKEH [NODE_ANGLE_DEG]]]     (the last two override the scene's aperture)
# Calibrated as ../shared/data/README.md measured on the bundled scene: Z buffer on, preview off,
# blur_max above the largest CoC radius, and node f-stop = N x (1000 / sensor width mm) x
# (1 - f / focus); the camera's own f-stop gives about 27x too much blur in 3.4. Angle 0 gives the
# hexagon orientation of Cycles' rotation 0.
# Apertures (scene.json lens.blades, bladeRotationDeg, apertureRatio): the node draws a disk or
# 3 to 8 blades; more blades get the one of its shapes nearest in area (Cycles' polygons and the
# node's are inscribed in the same circle): 9 to 11 its octagon, 12 and more its disk. On the
# 9-bladed truths of data/corpus-apertures/ the octagon measured 1.0 to 1.3 dB above the disk
# (the disk is 4 % too wide) on spheres-near-focus and overlapping-lights, the same on
# spheres-far-focus. The node's angle (0 to 90 degrees) turns its polygon clockwise from a
# corner straight up, and its gather shows that bokeh image point-reflected
# (BokehImageOperation, VariableSizeBokehBlurOperation); node_angle_deg() gives the orientation
# Cycles' lights behind the focus have (x right, y up: corners at rotation + 180/n + k 360/n
# degrees counter-clockwise), as bokeh_crops.py measured on scenes.py's aperture-probe for 5
# blades at 0 and 90 degrees, 7 at 0 and 15, and 8 at 0. The node draws that one shape at every
# depth, so for odd blade counts its bokeh in front of the focus point the other way than
# Cycles'. It has no aperture ratio: an anamorphic aperture gets the node's unsqueezed shape.
import json
import math
import os
import sys

import bpy

scene_dir, out_path = sys.argv[sys.argv.index("--") + 1:][:2]
meta = json.load(open(os.path.join(scene_dir, "scene.json")))
lens = meta["lens"]
argv = sys.argv[sys.argv.index("--") + 1:]
NODE_BOKEH = {0: "CIRCLE", 3: "TRIANGLE", 4: "SQUARE", 5: "PENTAGON", 6: "HEXAGON", 7: "HEPTAGON", 8: "OCTAGON"}
NODE_FLAPS = {v: k for k, v in NODE_BOKEH.items()}


def node_angle_deg(blades, rotation_deg):
    """The node's angle that draws Cycles' aperture of `blades` at `rotation_deg` as Cycles shows
    it behind the focus. The node's corner k is at (sin, cos)(a + k 360/n) in its bokeh image,
    y up, i.e. at 90 - a - k 360/n degrees counter-clockwise, and shows point-reflected: at
    270 - a - k 360/n. Cycles' corners are at rotation + 180/n + k 360/n, so
    a = 270 - 180/n - rotation, modulo the polygon's period 360/n."""
    period = 360.0 / blades
    angle = (270.0 - 180.0 / blades - rotation_deg) % period
    if angle > 90.0:  # only a triangle's period (120) exceeds the node's range
        sys.exit(f"blender_defocus.py: {blades} blades at {rotation_deg} deg needs angle {angle:.1f}, beyond the node's 90")
    return angle


def polygon_area(blades):
    """Area of a regular polygon inscribed in the unit circle, as a share of the circle's."""
    return 1.0 if blades == 0 else blades * math.sin(2.0 * math.pi / blades) / (2.0 * math.pi)


def nearest_node_bokeh(blades):
    if blades in NODE_BOKEH:
        return NODE_BOKEH[blades]
    return NODE_BOKEH[min(NODE_BOKEH, key=lambda k: abs(polygon_area(k) - polygon_area(blades)))]


blades = int(lens["blades"])
bokeh = argv[3] if len(argv) > 3 else nearest_node_bokeh(blades)
if bokeh not in NODE_FLAPS:
    sys.exit(f"blender_defocus.py: node bokeh {bokeh} is none of {sorted(NODE_FLAPS)}")
flaps = NODE_FLAPS[bokeh]
if len(argv) > 4:
    angle_deg = float(argv[4])
else:
    angle_deg = node_angle_deg(flaps, lens.get("bladeRotationDeg", 0.0)) if flaps else 0.0

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
defocus.bokeh = bokeh
defocus.angle = math.radians(angle_deg)
defocus.use_zbuffer = True
defocus.use_preview = False
defocus.use_gamma_correction = False
defocus.scene = scene
f_mm, focus_mm = lens["focalLengthMm"], lens["focusM"] * 1000.0
defocus.f_stop = lens["fNumber"] * (1000.0 / lens["sensorWidthMm"]) * (1.0 - f_mm / focus_mm)
# Largest CoC radius of the scene's depth range (1.2 x for margin), pixels.
near = float(argv[2]) if len(argv) > 2 else 64.0
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
print(f"blender_defocus.py: {bokeh} at angle {angle_deg:.2f} deg (scene: {blades} blades at "
      f"{lens.get('bladeRotationDeg', 0.0):g} deg, ratio {lens.get('apertureRatio', 1.0):g}), f-stop {defocus.f_stop:.2f}, "
      f"blur_max {defocus.blur_max:.0f} -> {out_path}")
