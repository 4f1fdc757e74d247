# SPDX-License-Identifier: LGPL-2.1-or-later
# Builds and renders the accuracy corpus' Cycles scenes: for one scene, a pinhole render (the
# filter's input: colour and planar depth) or one thin-lens render (half of the truth), 640x480.
# Run inside Blender (Debian 12's blender 3.4), normally through scripts/corpus/render.sh:
#   blender -b --factory-startup --python scripts/corpus/scenes.py -- \
#       --scene portrait-50 --pass pinhole --samples 64 --out out/corpus_render/portrait-50
#   ... --pass truth --samples 256 --seed 1 --out ...     (writes truth_seed1.exr)
#   blender -b --python scripts/corpus/scenes.py -- --list      (scene names, one a line)
# A scene name BASE--APERTURE is the scene BASE (same geometry, same pinhole colour and depth)
# seen through another aperture, only its truth differs (data/corpus-apertures/): APERTURE is
# "circle" or "<n>blades" (3..16), then optionally "-rot<degrees>" (blade rotation) and
# "-ratio<r>" (anamorphic, Cycles' dof.aperture_ratio): spheres-far-focus--circle,
# spheres-far-focus--7blades-rot15, spheres-far-focus--circle-ratio2.
#   ... -- --list-variants   (the variants data/corpus-apertures/ holds, one a line)
# Every scene is built from code below (no .blend file), so anyone can rerun and change it.
import argparse
import json
import math
import os
import random
import re
import sys

import bpy

WIDTH, HEIGHT = 640, 480
SENSOR_WIDTH_MM = 36.0

# ---- scene building blocks ----------------------------------------------------------------------


def material(name, colour, texture=None, scale=8.0, emission=0.0, colour2=None):
    """Diffuse material (fast to sample), optionally textured by a procedural checker, brick or
    noise; emission > 0 makes an emitter of that strength instead (a light brighter than white)."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    if emission > 0.0:
        shader = nodes.new("ShaderNodeEmission")
        shader.inputs["Color"].default_value = (*colour, 1.0)
        shader.inputs["Strength"].default_value = emission
        links.new(shader.outputs[0], out.inputs["Surface"])
        return mat
    shader = nodes.new("ShaderNodeBsdfDiffuse")
    links.new(shader.outputs[0], out.inputs["Surface"])
    c2 = colour2 or tuple(0.35 * c for c in colour)
    if texture == "checker":
        tex = nodes.new("ShaderNodeTexChecker")
        tex.inputs["Color1"].default_value = (*colour, 1.0)
        tex.inputs["Color2"].default_value = (*c2, 1.0)
        tex.inputs["Scale"].default_value = scale
        links.new(tex.outputs["Color"], shader.inputs["Color"])
    elif texture == "brick":
        tex = nodes.new("ShaderNodeTexBrick")
        tex.inputs["Color1"].default_value = (*colour, 1.0)
        tex.inputs["Color2"].default_value = (*c2, 1.0)
        tex.inputs["Mortar"].default_value = (0.8, 0.8, 0.78, 1.0)
        tex.inputs["Scale"].default_value = scale
        links.new(tex.outputs["Color"], shader.inputs["Color"])
    elif texture == "noise":
        tex = nodes.new("ShaderNodeTexNoise")
        tex.inputs["Scale"].default_value = scale
        tex.inputs["Detail"].default_value = 6.0
        ramp = nodes.new("ShaderNodeValToRGB")
        ramp.color_ramp.elements[0].color = (*c2, 1.0)
        ramp.color_ramp.elements[1].color = (*colour, 1.0)
        links.new(tex.outputs["Fac"], ramp.inputs["Fac"])
        links.new(ramp.outputs["Color"], shader.inputs["Color"])
    else:
        shader.inputs["Color"].default_value = (*colour, 1.0)
    return mat


def assign(obj, mat):
    obj.data.materials.append(mat)
    return obj


def sphere(loc, radius, mat, segments=48):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=segments, ring_count=segments // 2, radius=radius, location=loc)
    obj = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    return assign(obj, mat)


def box(loc, size, mat, rotation=(0.0, 0.0, 0.0)):
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=loc, rotation=rotation)
    obj = bpy.context.active_object
    obj.scale = size
    return assign(obj, mat)


def cylinder(loc, radius, depth, mat, rotation=(0.0, 0.0, 0.0)):
    bpy.ops.mesh.primitive_cylinder_add(vertices=24, radius=radius, depth=depth, location=loc, rotation=rotation)
    obj = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    return assign(obj, mat)


def plane(loc, size, mat, rotation=(0.0, 0.0, 0.0)):
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=loc, rotation=rotation)
    obj = bpy.context.active_object
    obj.scale = (size[0], size[1], 1.0)
    return assign(obj, mat)


def wall(distance, mat, width=80.0, height=40.0):
    """A wall facing the camera at `distance` metres (planar depth), centred on the view axis."""
    return plane((0.0, distance, height / 2 - 2.0), (width, height), mat, rotation=(math.pi / 2, 0.0, 0.0))


def floor(mat, z=0.0, size=120.0):
    return plane((0.0, size / 2 - 1.0, z), (size, size), mat)


def light(loc, radius=0.025, strength=60.0, colour=(1.0, 0.85, 0.6)):
    """A small emissive sphere: a highlight far brighter than white that turns into bokeh. Seen by
    the camera only, so that it lights nothing (which would add noise and no test)."""
    obj = sphere(loc, radius, material("light", colour, emission=strength), segments=16)
    obj.visible_diffuse = obj.visible_glossy = obj.visible_transmission = False
    obj.visible_volume_scatter = obj.visible_shadow = False
    return obj


def at_depth(depth, x_px, y_px, lens, camera_z):
    """World position at planar depth `depth` (metres) that the pinhole projects to pixel
    (x_px, y_px) (0,0 = top left), with the field of view of the focal length (Cycles')."""
    scale = SENSOR_WIDTH_MM / lens["focal_mm"] * depth / WIDTH  # metres per pixel at that depth
    return ((x_px - WIDTH / 2) * scale, depth, camera_z + (HEIGHT / 2 - y_px) * scale)


def leaves(rng, count, depth_range, x_range_px, y_range_px, lens, camera_z, size=(0.05, 0.09)):
    """Thin foreground occluders: small green leaves scattered in front of the focus."""
    greens = [(0.08, 0.25, 0.05), (0.12, 0.32, 0.06), (0.05, 0.18, 0.04)]
    mats = [material(f"leaf{i}", g, texture="noise", scale=30.0) for i, g in enumerate(greens)]
    for _ in range(count):
        d = rng.uniform(*depth_range)
        loc = at_depth(d, rng.uniform(*x_range_px), rng.uniform(*y_range_px), lens, camera_z)
        rot = (math.pi / 2 + rng.uniform(-0.6, 0.6), rng.uniform(-0.6, 0.6), rng.uniform(0, math.pi))
        bpy.ops.mesh.primitive_plane_add(size=1.0, location=loc, rotation=rot)
        obj = bpy.context.active_object
        obj.scale = (size[0] * rng.uniform(0.7, 1.3), size[1] * rng.uniform(0.7, 1.3), 1.0)
        assign(obj, rng.choice(mats))


# ---- the scenes -----------------------------------------------------------------------------------
# Each returns its lens: focal length mm, f-number, focus distance m (planar), camera height m.
# Lights sit in front of, at and behind the focus; the comments give the thin-lens CoC at 640 px.


def scene_spheres_near_focus(rng):
    """Spheres and boxes on a checker floor, brick wall at 30 m, 85 mm f/2 focused at 2.2 m:
    everything from 1.4 m (17 px) to the wall (28 px) blurs; lights at 1.6, 2.2, 6 and 25 m."""
    lens = dict(focal_mm=85.0, f_number=2.0, focus_m=2.2, camera_z=1.0)
    floor(material("floor", (0.5, 0.5, 0.48), "checker", 60.0))
    wall(30.0, material("wall", (0.55, 0.25, 0.15), "brick", 3.0))
    z = lens["camera_z"]
    for d, x, y, r, col in [(1.4, 90, 330, 0.08, (0.8, 0.2, 0.2)), (2.2, 330, 260, 0.1, (0.2, 0.5, 0.8)),
                            (3.5, 470, 250, 0.25, (0.85, 0.75, 0.2)), (8.0, 200, 230, 0.6, (0.3, 0.7, 0.3)),
                            (15.0, 560, 235, 1.0, (0.6, 0.3, 0.7))]:
        sphere(at_depth(d, x, y, lens, z), r, material("s", col, "noise", 12.0))
    box(at_depth(2.2, 230, 300, lens, z), (0.15, 0.15, 0.15), material("b", (0.9, 0.9, 0.85), "checker", 4.0),
        rotation=(0.0, 0.0, 0.5))
    for d, x, y, s in [(1.6, 520, 120, 40), (2.2, 400, 180, 60), (6.0, 130, 120, 80), (25.0, 300, 90, 120),
                       (25.0, 330, 100, 120), (25.0, 600, 60, 120)]:
        light(at_depth(d, x, y, lens, z), radius=0.012 * d / 2.0 + 0.01, strength=s)
    return lens


def scene_spheres_far_focus(rng):
    """Same kind of scene focused far (85 mm f/1.4 at 12 m): lights in front of the focus
    (1.8 m: 43 px, 3 m: 23 px) turn into large hexagons over a sharp background."""
    lens = dict(focal_mm=85.0, f_number=1.4, focus_m=12.0, camera_z=1.2)
    floor(material("floor", (0.45, 0.45, 0.42), "checker", 80.0))
    wall(40.0, material("wall", (0.5, 0.5, 0.55), "brick", 2.0))
    z = lens["camera_z"]
    for d, x, y, r, col in [(12.0, 320, 260, 0.8, (0.8, 0.5, 0.2)), (12.0, 120, 280, 0.5, (0.3, 0.3, 0.8)),
                            (20.0, 520, 250, 1.2, (0.3, 0.6, 0.4)), (2.5, 560, 380, 0.12, (0.7, 0.1, 0.1))]:
        sphere(at_depth(d, x, y, lens, z), r, material("s", col, "noise", 6.0))
    for d, x, y, s in [(1.8, 150, 140, 30), (3.0, 420, 110, 40), (3.0, 470, 140, 40), (12.0, 250, 200, 80),
                       (30.0, 80, 60, 150), (30.0, 600, 420, 150)]:
        light(at_depth(d, x, y, lens, z), radius=0.004 * d + 0.01, strength=s)
    return lens


def scene_portrait(rng):
    """A face-like subject at portrait distance (50 mm f/1.8, 1.2 m), foliage at 0.6-0.8 m
    (up to 21 px) over the frame's edges, a wall at 5 m (16 px) with a string of lights."""
    lens = dict(focal_mm=50.0, f_number=1.8, focus_m=1.2, camera_z=1.5)
    z = lens["camera_z"]
    floor(material("floor", (0.35, 0.3, 0.25), "checker", 90.0))
    wall(5.0, material("wall", (0.6, 0.55, 0.5), "brick", 6.0))
    skin = material("skin", (0.8, 0.55, 0.42), "noise", 40.0, colour2=(0.7, 0.45, 0.35))
    head = at_depth(1.2, 320, 200, lens, z)
    sphere(head, 0.1, skin).scale = (0.85, 0.95, 1.15)
    dark = material("eye", (0.05, 0.04, 0.04))
    for dx in (-0.035, 0.035):
        sphere((head[0] + dx, head[1] - 0.08, head[2] + 0.025), 0.012, dark)
    sphere((head[0], head[1] - 0.095, head[2] - 0.015), 0.016, skin)
    box((head[0], head[1] - 0.07, head[2] - 0.06), (0.05, 0.01, 0.012), material("lips", (0.6, 0.2, 0.2)))
    sphere((head[0], head[1] + 0.02, head[2] + 0.07), 0.095, material("hair", (0.12, 0.07, 0.04), "noise", 60.0))
    cylinder((head[0], head[1], head[2] - 0.17), 0.045, 0.12, skin)
    body = material("shirt", (0.15, 0.25, 0.5), "checker", 30.0)
    sphere((head[0], head[1] + 0.03, head[2] - 0.42), 0.3, body).scale = (1.0, 0.45, 0.75)
    leaves(rng, 140, (0.6, 0.8), (-40, 160), (-40, 520), lens, z)
    leaves(rng, 90, (0.6, 0.8), (500, 680), (-40, 300), lens, z)
    for i in range(14):  # a string of lights on the wall, and two lamps in the room
        light(at_depth(4.9, 40 + i * 45, 70 + 25 * math.sin(i * 0.8), lens, z), radius=0.02, strength=50)
    light(at_depth(3.0, 560, 300, lens, z), radius=0.03, strength=40)
    light(at_depth(2.0, 120, 150, lens, z), radius=0.02, strength=40)
    return lens


def scene_wide_table(rng):
    """Wide angle, close focus: 24 mm f/1.2 focused at 0.5 m on objects on a table (0.3 m: 12
    px), a room behind to 8 m (17 px) with lamps at 2-7 m."""
    lens = dict(focal_mm=24.0, f_number=1.2, focus_m=0.5, camera_z=0.9)
    z = lens["camera_z"]
    plane((0.0, 0.6, 0.75), (1.6, 1.0), material("table", (0.5, 0.35, 0.2), "noise", 8.0))
    floor(material("floor", (0.4, 0.4, 0.4), "checker", 60.0))
    wall(8.0, material("wall", (0.7, 0.7, 0.65), "brick", 8.0))
    box((2.5, 4.0, 1.0), (0.8, 0.8, 2.0), material("shelf", (0.3, 0.2, 0.15), "checker", 10.0))
    sphere((0.03, 0.5, 0.8), 0.05, material("cup", (0.8, 0.8, 0.75), "checker", 20.0))
    sphere((-0.12, 0.35, 0.79), 0.04, material("fruit", (0.8, 0.3, 0.05), "noise", 30.0))
    box((0.12, 0.6, 0.8), (0.06, 0.06, 0.1), material("box", (0.2, 0.4, 0.7), "checker", 12.0))
    for d, x, y, s in [(2.0, 80, 150, 40), (3.5, 470, 120, 50), (5.0, 330, 170, 60), (7.0, 600, 90, 80),
                       (7.0, 200, 80, 80), (0.45, 420, 330, 20)]:
        light(at_depth(d, x, y, lens, z), radius=0.01 + 0.01 * d, strength=s)
    return lens


def scene_tele_f8(rng):
    """Long lens stopped down: 135 mm f/8 focused at 3 m on a sphere; a post at 1.8 m (9 px),
    buildings to 30 m (13 px) with window lights; small blurs everywhere."""
    lens = dict(focal_mm=135.0, f_number=8.0, focus_m=3.0, camera_z=1.6)
    z = lens["camera_z"]
    floor(material("street", (0.3, 0.3, 0.3), "noise", 3.0))
    wall(30.0, material("facade", (0.55, 0.5, 0.45), "brick", 4.0))
    sphere(at_depth(3.0, 320, 250, lens, z), 0.12, material("ball", (0.85, 0.6, 0.1), "checker", 10.0))
    cylinder(at_depth(1.8, 130, 240, lens, z), 0.02, 3.0, material("post", (0.2, 0.2, 0.22), "noise", 40.0))
    box(at_depth(12.0, 480, 260, lens, z), (0.8, 0.6, 2.0), material("kiosk", (0.2, 0.5, 0.3), "checker", 6.0))
    for i in range(5):
        for j in range(3):
            light(at_depth(29.5, 60 + i * 120, 60 + j * 70, lens, z), radius=0.05, strength=60)
    light(at_depth(3.0, 420, 180, lens, z), radius=0.01, strength=40)
    light(at_depth(2.0, 230, 120, lens, z), radius=0.01, strength=40)
    return lens


def scene_overlapping_lights(rng):
    """Lights at different depths overlapping in the image: 85 mm f/1.2 focused at 3 m; pairs of
    lights at 2.8 m (near the focus, 2 px) in front of lights at 20 m (31 px), lights at 1.5 m
    (37 px) over the far ones, on a dark street scene."""
    lens = dict(focal_mm=85.0, f_number=1.2, focus_m=3.0, camera_z=1.4)
    z = lens["camera_z"]
    floor(material("street", (0.12, 0.12, 0.13), "noise", 4.0))
    wall(40.0, material("far", (0.08, 0.08, 0.1), "brick", 3.0))
    sphere(at_depth(3.0, 320, 330, lens, z), 0.08, material("ball", (0.7, 0.2, 0.1), "checker", 12.0))
    for x, y in [(120, 140), (300, 110), (470, 160), (560, 300), (200, 330)]:
        light(at_depth(20.0, x, y, lens, z), radius=0.08, strength=80)
        light(at_depth(2.8, x + 12, y + 8, lens, z), radius=0.012, strength=60, colour=(0.6, 0.8, 1.0))
    for x, y in [(420, 90), (80, 260)]:
        light(at_depth(1.5, x, y, lens, z), radius=0.008, strength=40, colour=(1.0, 0.5, 0.4))
        light(at_depth(20.0, x + 20, y - 10, lens, z), radius=0.08, strength=80)
    return lens


def scene_railing(rng):
    """Thin occluders over lights: a railing of 1 cm bars at 0.9 m (28 px) in front of lights at
    the focus (4 m) and far behind it (15 m: 6 px); 50 mm f/1.4."""
    lens = dict(focal_mm=50.0, f_number=1.4, focus_m=4.0, camera_z=1.2)
    z = lens["camera_z"]
    floor(material("deck", (0.35, 0.3, 0.25), "checker", 70.0))
    wall(15.5, material("wall", (0.3, 0.32, 0.35), "brick", 5.0))
    bar = material("bar", (0.25, 0.25, 0.27), "noise", 50.0)
    for i in range(12):
        x = -0.45 + i * 0.08
        cylinder((x, 0.9, 0.7), 0.005, 1.4, bar)
    cylinder((0.0, 0.9, 1.05), 0.012, 2.0, bar, rotation=(0.0, math.pi / 2, 0.0))
    sphere(at_depth(4.0, 330, 280, lens, z), 0.2, material("ball", (0.2, 0.6, 0.8), "checker", 14.0))
    box(at_depth(4.0, 150, 300, lens, z), (0.3, 0.3, 0.6), material("crate", (0.6, 0.45, 0.2), "noise", 20.0))
    for i in range(8):
        light(at_depth(4.0, 60 + i * 75, 150 + 20 * (i % 2), lens, z), radius=0.015, strength=50)
    for i in range(6):
        light(at_depth(15.0, 90 + i * 95, 90, lens, z), radius=0.05, strength=70)
    return lens


def scene_near_object(rng):
    """A frame-filling near object: a textured box at 0.35 m (30 px) covering the left half of
    the frame, 50 mm f/4 focused at 5 m on a garden scene with lights."""
    lens = dict(focal_mm=50.0, f_number=4.0, focus_m=5.0, camera_z=1.3)
    z = lens["camera_z"]
    floor(material("grass", (0.15, 0.35, 0.1), "noise", 20.0))
    wall(12.0, material("hedge", (0.1, 0.28, 0.08), "noise", 5.0))
    near = at_depth(0.35, 120, 240, lens, z)
    box((near[0], near[1] + 0.05, near[2]), (0.25, 0.1, 0.5), material("vase", (0.75, 0.7, 0.6), "checker", 16.0))
    sphere(at_depth(5.0, 420, 260, lens, z), 0.35, material("statue", (0.7, 0.7, 0.7), "noise", 8.0))
    leaves(rng, 40, (4.6, 5.4), (300, 640), (250, 480), lens, z, size=(0.15, 0.3))
    for d, x, y in [(5.0, 560, 150), (8.0, 330, 100), (11.5, 450, 80), (11.5, 600, 60), (0.35, 200, 120)]:  # the last: a light on the near object
        light(at_depth(d, x, y, lens, z), radius=0.003 + 0.006 * d, strength=60)
    return lens


def scene_aperture_probe(rng):
    """Not a corpus scene (not listed): point-like lights on black, to see an aperture's shape and
    which way it points. 85 mm f/1.4 focused at 3 m; lights at 1.5 m (in front of the focus: 31
    px) on the left, at the focus in the middle, at 20 m (behind it: 26 px) on the right."""
    lens = dict(focal_mm=85.0, f_number=1.4, focus_m=3.0, camera_z=1.0)
    z = lens["camera_z"]
    plane((0.0, 60.0, z), (200.0, 200.0), material("black", (0.0, 0.0, 0.0)), rotation=(math.pi / 2, 0.0, 0.0))
    for d, x, y in [(1.5, 160, 160), (1.5, 160, 320), (3.0, 320, 240), (20.0, 480, 160), (20.0, 480, 320)]:
        light(at_depth(d, x, y, lens, z), radius=0.0012 * d, strength=1000)
    return lens


SCENES = {
    "spheres-near-focus": scene_spheres_near_focus,
    "spheres-far-focus": scene_spheres_far_focus,
    "portrait-50": scene_portrait,
    "wide-table-24": scene_wide_table,
    "tele-135-f8": scene_tele_f8,
    "overlapping-lights": scene_overlapping_lights,
    "railing-lights": scene_railing,
    "near-object": scene_near_object,
}

# Scenes that scenes.py renders by name but does not --list: no part of the corpus.
PROBES = {"aperture-probe": scene_aperture_probe}

# The apertures data/corpus-apertures/ holds, each on the bases listed: spheres-far-focus has
# lights in front of the focus over a sharp background (depth edges), spheres-near-focus lights
# both in front of the focus and behind it (the two orientations of an odd blade count),
# overlapping-lights bokeh over bokeh at other depths, railing-lights thin bars over lights.
VARIANT_BASES = ["spheres-far-focus", "spheres-near-focus", "overlapping-lights", "railing-lights"]
VARIANT_APERTURES = ["circle", "5blades", "8blades", "9blades", "7blades-rot15", "circle-ratio2"]
VARIANTS = [f"{base}--{aperture}" for base in VARIANT_BASES for aperture in VARIANT_APERTURES]

APERTURE_NAME = re.compile(r"^(circle|([0-9]+)blades)(-rot(-?[0-9]+(?:\.[0-9]+)?))?(-ratio([0-9]+(?:\.[0-9]+)?))?$")


def parse_scene_name(name):
    """(base scene, aperture) of a scene name BASE or BASE--APERTURE; the aperture is a dict of
    blades (0 = a disk), rotation in degrees and ratio (Cycles' aperture_ratio)."""
    base, sep, spec = name.partition("--")
    aperture = dict(blades=6, rotation_deg=0.0, ratio=1.0)  # the corpus' own (data/corpus/)
    if sep:
        m = APERTURE_NAME.match(spec)
        if not m:
            raise ValueError(f"{name}: aperture '{spec}' is not circle or <n>blades, [-rot<deg>], [-ratio<r>]")
        aperture["blades"] = 0 if m.group(1) == "circle" else int(m.group(2))
        if aperture["blades"] != 0 and not 3 <= aperture["blades"] <= 16:
            raise ValueError(f"{name}: Cycles draws 3 to 16 blades (or circle), not {aperture['blades']}")
        aperture["rotation_deg"] = float(m.group(4) or 0.0)
        aperture["ratio"] = float(m.group(6) or 1.0)
        if aperture["ratio"] <= 0.0:
            raise ValueError(f"{name}: the aperture ratio must be positive")
    if base not in SCENES and base not in PROBES:
        raise ValueError(f"{name}: no scene '{base}' (--list)")
    return base, aperture


def describe_aperture(aperture):
    shape = "a disk" if aperture["blades"] == 0 else f"{aperture['blades']} blades"
    if aperture["blades"] != 0:
        shape += f" at rotation {aperture['rotation_deg']:g} deg"
    if aperture["ratio"] != 1.0:
        shape += f", anamorphic: aperture ratio {aperture['ratio']:g} (Cycles scales the lens' x by 1/{aperture['ratio']:g})"
    return shape


def lens_meta(lens, aperture):
    meta = {
        "focalLengthMm": lens["focal_mm"],
        "sensorWidthMm": SENSOR_WIDTH_MM,
        "fNumber": lens["f_number"],
        "focusM": lens["focus_m"],
        "blades": aperture["blades"],
        "bladeRotationDeg": aperture["rotation_deg"],
    }
    if aperture["ratio"] != 1.0:
        meta["apertureRatio"] = aperture["ratio"]
    meta["fieldOfView"] = "focal-length"
    return meta


# ---- render -------------------------------------------------------------------------------------


def setup(name, render_pass, samples, seed, adaptive=None):
    base, aperture = parse_scene_name(name)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    lens = {**SCENES, **PROBES}[base](random.Random(base))  # a variant is its base's geometry, random parts too

    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.35, 0.4, 0.5, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.6
    scene.world = world
    sun_data = bpy.data.lights.new("sun", "SUN")
    sun_data.energy = 2.5
    sun_data.angle = math.radians(2.0)
    sun = bpy.data.objects.new("sun", sun_data)
    sun.rotation_euler = (math.radians(50), math.radians(10), math.radians(30))
    scene.collection.objects.link(sun)

    cam_data = bpy.data.cameras.new("camera")
    cam_data.lens = lens["focal_mm"]
    cam_data.sensor_fit = "HORIZONTAL"
    cam_data.sensor_width = SENSOR_WIDTH_MM
    cam_data.clip_end = 500.0
    cam_data.dof.use_dof = render_pass == "truth"
    cam_data.dof.focus_distance = lens["focus_m"]
    cam_data.dof.aperture_fstop = lens["f_number"]
    cam_data.dof.aperture_blades = aperture["blades"]
    cam_data.dof.aperture_rotation = math.radians(aperture["rotation_deg"])
    cam_data.dof.aperture_ratio = aperture["ratio"]
    cam = bpy.data.objects.new("camera", cam_data)
    cam.location = (0.0, 0.0, lens["camera_z"])
    cam.rotation_euler = (math.pi / 2, 0.0, 0.0)  # looks along +y: planar depth = y
    scene.collection.objects.link(cam)
    scene.camera = cam

    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    # The truth's noise sits at the edges of the lights' bokeh (a few samples of 50-150 among
    # many of nothing); adaptive sampling spends the samples there. Seeds stay independent.
    scene.cycles.use_adaptive_sampling = adaptive is not None
    if adaptive is not None:
        scene.cycles.adaptive_threshold, scene.cycles.adaptive_min_samples = adaptive
    scene.cycles.use_denoising = False
    scene.cycles.seed = seed
    scene.cycles.max_bounces = 2
    scene.cycles.diffuse_bounces = 1
    scene.cycles.glossy_bounces = 0
    scene.cycles.transmission_bounces = 0
    scene.cycles.transparent_max_bounces = 0
    scene.cycles.caustics_reflective = False
    scene.cycles.caustics_refractive = False
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.render.use_compositing = True
    scene.view_layers[0].use_pass_z = True

    # Compositor: the combined pass to a half-float EXR (scene-linear, HDR kept), and for the
    # pinhole the depth pass to a float32 EXR.
    scene.use_nodes = True
    tree = scene.node_tree
    tree.nodes.clear()
    layers = tree.nodes.new("CompositorNodeRLayers")
    composite = tree.nodes.new("CompositorNodeComposite")
    tree.links.new(layers.outputs["Image"], composite.inputs["Image"])
    files = tree.nodes.new("CompositorNodeOutputFile")
    files.format.file_format = "OPEN_EXR"
    files.format.color_depth = "16"
    files.format.exr_codec = "ZIP"
    files.format.color_mode = "RGB"
    files.file_slots.clear()
    stem = "color_linear" if render_pass == "pinhole" else f"truth_seed{seed}"
    files.file_slots.new(stem)
    tree.links.new(layers.outputs["Image"], files.inputs[stem])
    if render_pass == "pinhole":
        files.file_slots.new("depth")
        slot = files.file_slots["depth"]
        slot.use_node_format = False
        slot.format.file_format = "OPEN_EXR"
        slot.format.color_depth = "32"
        slot.format.exr_codec = "ZIP"
        slot.format.color_mode = "RGB"  # one channel is kept when the scene folder is assembled
        tree.links.new(layers.outputs["Depth"], files.inputs["depth"])
    return lens, aperture, files, stem


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="scenes.py")
    parser.add_argument("--list", action="store_true", help="print the scene names and exit")
    parser.add_argument("--list-variants", action="store_true", help="print the aperture variants' names and exit")
    parser.add_argument("--scene", help="a scene (--list) or BASE--APERTURE")
    parser.add_argument("--pass", dest="render_pass", choices=["pinhole", "truth"], default="pinhole")
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--adaptive", type=float, nargs=2, metavar=("THRESHOLD", "MIN_SAMPLES"),
                        help="adaptive sampling: noise threshold and minimum samples (--samples is the maximum)")
    parser.add_argument("--threads", type=int, default=0, help="render threads, 0 = all cores")
    parser.add_argument("--out", help="output folder")
    args = parser.parse_args(argv)
    if args.list:
        print("\n".join(SCENES))
        return
    if args.list_variants:
        print("\n".join(VARIANTS))
        return
    if not args.scene or not args.out:
        parser.error("--scene and --out are required")
    try:
        base, aperture = parse_scene_name(args.scene)
    except ValueError as error:
        parser.error(str(error))
    if base != args.scene and args.render_pass == "pinhole":
        parser.error(f"{args.scene}: a variant's pinhole is its base's ({base}); render that")
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    adaptive = (args.adaptive[0], int(args.adaptive[1])) if args.adaptive else None
    lens, aperture, files, stem = setup(args.scene, args.render_pass, args.samples, args.seed, adaptive)
    scene = bpy.context.scene
    if args.threads > 0:
        scene.render.threads_mode = "FIXED"
        scene.render.threads = args.threads
    files.base_path = out
    scene.frame_set(1)
    scene.render.filepath = os.path.join(out, "_composite")
    bpy.ops.render.render(write_still=False)
    # The file output node appends the frame number; drop it.
    for s in [stem] + (["depth"] if args.render_pass == "pinhole" else []):
        os.replace(os.path.join(out, f"{s}0001.exr"), os.path.join(out, f"{s}.exr"))
    # The lens, for the scene folder (assemble.py): the pinhole's folder and every truth's.
    description = " ".join({**SCENES, **PROBES}[base].__doc__.split())
    if base != args.scene:
        description += f" The same scene through another aperture than data/corpus' 6 blades: {describe_aperture(aperture)}."
    with open(os.path.join(out, "lens.json"), "w") as f:
        json.dump({"lens": lens_meta(lens, aperture), "description": description}, f, indent=2)
    print(f"scenes.py: wrote {args.render_pass} of {args.scene} ({args.samples} samples, seed {args.seed}) to {out}")


main()
