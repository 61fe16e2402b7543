# Photoreal re-render of a generated sequence with Blender's Cycles path tracer (run by
# scripts/benchmark.py's photo section; needs Debian's `blender`):
#
#   blender -b --factory-startup -noaudio -P scripts/photoreal_render.py -- \
#       --source DIR --model OBJ --background IMAGE --output DIR [--samples N] [--seed N]
#       [--clutter N] [--clutter-texture IMAGE] [--moving-light] [--frames N] [--threads N]
#
# --source is a sequence folder written by generate_sequence (K.txt, pose.txt, visible.txt):
# its trajectory and ground truth are kept, its frames are not used. The object (the OBJ in
# metres, with its MTL colour or texture) flies along that trajectory in front of a diffusely lit
# photograph standing behind it, with `--clutter` boxes, cylinders and spheres between them, some
# wearing the object's own texture or colour. What the CPU rasterizer of generate_sequence does
# not have: path-traced soft shadows cast on the clutter and the background, inter-reflections,
# glossy highlights that move with the object, true motion blur over half the frame interval
# (shutter centred on the frame time, as generate_sequence), depth of field, the sampling noise of
# a short render and the filmic tone curve of a camera, written as JPEG (quality 90).
#
# Coordinates: the world frame is the OpenCV camera frame of the sequence (x right, y down,
# z forward, metres), so pose.txt's object_to_camera is the object's world matrix as it stands;
# the Blender camera sits at the origin turned 180 deg about x (it looks down its own -z) with the
# intrinsics of K.txt (focal length and principal point through sensor width and lens shift).
# Clutter never stands in front of the object (it is placed behind the trajectory's farthest
# point), so the source's visible.txt stays the ground truth of visibility.
import argparse
import math
import os
import random
import shutil
import sys

import bpy
from mathutils import Matrix, Quaternion


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="photoreal_render.py")
    p.add_argument("--source", required=True)
    p.add_argument("--model", required=True)
    p.add_argument("--background", required=True)
    p.add_argument("--output", required=True)
    p.add_argument("--samples", type=int, default=24)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--clutter", type=int, default=0)
    p.add_argument("--clutter-texture", default="")
    p.add_argument("--moving-light", action="store_true")
    p.add_argument("--frames", type=int, default=0, help="0 = all of the source's frames")
    p.add_argument("--threads", type=int, default=0, help="0 = all cores")
    return p.parse_args(argv)


def read_matrix_rows(path):
    rows = []
    for line in open(path):
        line = line.strip()
        if line and not line.startswith("#"):
            rows.append([float(x) for x in line.split()])
    return rows


def obj_vertices(path):
    out = []
    for line in open(path):
        if line.startswith("v "):
            out.append(tuple(float(x) for x in line.split()[1:4]))
    return out


def principled(name, color=(0.8, 0.8, 0.8, 1.0), image=None, roughness=0.5, specular=0.5):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = color
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Specular"].default_value = specular
    if image is not None:
        tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
        tex.image = image
        mat.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    return mat


def main():
    a = parse_args()
    rng = random.Random(a.seed)
    K = read_matrix_rows(os.path.join(a.source, "K.txt"))
    poses = read_matrix_rows(os.path.join(a.source, "pose.txt"))
    if a.frames > 0:
        poses = poses[:a.frames]
    first = bpy.data.images.load(os.path.join(a.source, "000000.jpg"))
    width, height = first.size
    fx, fy, cx, cy = K[0][0], K[1][1], K[0][2], K[1][2]

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = a.samples
    scene.cycles.use_adaptive_sampling = True
    scene.cycles.seed = a.seed
    scene.cycles.use_animated_seed = True  # new sampling noise every frame, as a sensor
    scene.cycles.max_bounces = 4
    scene.cycles.use_denoising = False  # the sampling noise stays: a camera is not noise-free
    if a.threads > 0:
        scene.render.threads_mode = "FIXED"
        scene.render.threads = a.threads
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = 1.0
    scene.render.pixel_aspect_y = fy / fx
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 0.5
    scene.cycles.motion_blur_position = "CENTER"
    scene.render.image_settings.file_format = "JPEG"
    scene.render.image_settings.quality = 90
    scene.view_settings.view_transform = "Filmic"
    scene.view_settings.look = "Medium High Contrast"
    scene.frame_start, scene.frame_end = 0, len(poses) - 1
    scene.render.fps = 30

    # Camera: OpenCV frame = world frame.
    cam_data = bpy.data.cameras.new("camera")
    cam_data.sensor_fit = "HORIZONTAL"
    cam_data.sensor_width = 36.0
    cam_data.lens = fx * cam_data.sensor_width / width
    # OpenCV pixel centres are integers; Blender's principal point is the continuous image centre.
    cam_data.shift_x = (width / 2.0 - (cx + 0.5)) / max(width, height)
    cam_data.shift_y = ((cy + 0.5) - height / 2.0) / max(width, height)
    cam_data.clip_start, cam_data.clip_end = 0.01, 50.0
    camera = bpy.data.objects.new("camera", cam_data)
    camera.rotation_euler = (math.pi, 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera

    # Object: the OBJ as it stands (metres, object frame), no axis conversion.
    bpy.ops.wm.obj_import(filepath=a.model, forward_axis="Y", up_axis="Z")
    obj = [o for o in bpy.context.selected_objects if o.type == "MESH"][0]
    obj.matrix_world = Matrix.Identity(4)
    file_vertices = obj_vertices(a.model)
    got = [tuple(v.co) for v in obj.data.vertices]
    span = max(max(abs(c) for c in v) for v in file_vertices)
    if len(got) != len(file_vertices) or max(
            max(abs(p - q) for p, q in zip(u, v)) for u, v in zip(sorted(got), sorted(file_vertices))) > 1e-5 * max(span, 1e-3):
        raise SystemExit("photoreal_render: the imported mesh differs from the OBJ's vertices")
    radius = max(math.sqrt(sum(c * c for c in v)) for v in file_vertices)
    smooth = os.path.basename(a.model).split(".")[0] in ("can", "toy")
    for poly in obj.data.polygons:
        poly.use_smooth = smooth
    if smooth:
        obj.data.use_auto_smooth = True
        obj.data.auto_smooth_angle = math.radians(40.0)
    object_image = None
    for slot in obj.material_slots:
        mat = slot.material
        if mat and mat.use_nodes:
            bsdf = mat.node_tree.nodes.get("Principled BSDF")
            if bsdf:
                bsdf.inputs["Roughness"].default_value = 0.35
                bsdf.inputs["Specular"].default_value = 0.5
            for node in mat.node_tree.nodes:
                if node.type == "TEX_IMAGE" and node.image is not None:
                    object_image = node.image
    object_color = (0.8, 0.8, 0.8, 1.0)
    if obj.material_slots and obj.material_slots[0].material:
        bsdf = obj.material_slots[0].material.node_tree.nodes.get("Principled BSDF")
        if bsdf:
            object_color = tuple(bsdf.inputs["Base Color"].default_value)

    obj.rotation_mode = "QUATERNION"
    previous = None
    depths = []
    for f, row in enumerate(poses):
        R = Matrix(((row[0], row[1], row[2]), (row[3], row[4], row[5]), (row[6], row[7], row[8])))
        q = R.to_quaternion()
        if previous is not None and previous.dot(q) < 0.0:
            q = Quaternion((-q.w, -q.x, -q.y, -q.z))  # shortest path between keys
        previous = q
        obj.rotation_quaternion = q
        obj.location = (row[9], row[10], row[11])
        depths.append(row[11])
        obj.keyframe_insert("rotation_quaternion", frame=f)
        obj.keyframe_insert("location", frame=f)
    for fc in obj.animation_data.action.fcurves:
        for key in fc.keyframe_points:
            key.interpolation = "LINEAR"

    # Background photograph on a plane behind the trajectory, filling the view with margin.
    far = max(depths) + radius
    plane_z = far + 0.25 + 2.0 * radius
    half_w = 0.55 * plane_z * width / fx
    half_h = 0.55 * plane_z * height / fy
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    plane = bpy.context.active_object
    plane.scale = (half_w, half_h, 1.0)
    plane.location = (0.0, 0.0, plane_z)
    plane.rotation_euler = (math.pi, 0.0, 0.0)  # normal towards the camera, image upright
    photo = bpy.data.images.load(a.background)
    plane.data.materials.append(principled("background", image=photo, roughness=0.8, specular=0.2))

    # Clutter between the trajectory and the photograph: some in the object's texture/colour.
    clutter_photo = bpy.data.images.load(a.clutter_texture) if a.clutter_texture else None
    for i in range(a.clutter):
        kind = rng.choice(["cube", "cylinder", "sphere"])
        size = radius * rng.uniform(0.5, 1.2)
        z = rng.uniform(far + size + 0.02, plane_z - size)
        x = rng.uniform(-0.6, 0.6) * z * width / fx
        y = rng.uniform(-0.6, 0.6) * z * height / fy
        if kind == "cube":
            bpy.ops.mesh.primitive_cube_add(size=size * 1.4, location=(x, y, z))
        elif kind == "cylinder":
            bpy.ops.mesh.primitive_cylinder_add(radius=size * 0.6, depth=size * 1.8, location=(x, y, z))
        else:
            bpy.ops.mesh.primitive_uv_sphere_add(radius=size * 0.8, location=(x, y, z))
        thing = bpy.context.active_object
        thing.rotation_euler = (rng.uniform(0, math.pi), rng.uniform(0, math.pi), rng.uniform(0, math.pi))
        if kind != "cube":
            bpy.ops.object.shade_smooth()
        bpy.ops.object.editmode_toggle()
        bpy.ops.uv.smart_project()
        bpy.ops.object.editmode_toggle()
        choice = i % 3
        if choice == 0 and object_image is not None:
            mat = principled("clutter%d" % i, image=object_image, roughness=0.4)
        elif choice == 0:
            mat = principled("clutter%d" % i, color=object_color, roughness=0.4)
        elif choice == 1 and clutter_photo is not None:
            mat = principled("clutter%d" % i, image=clutter_photo, roughness=0.6)
        else:
            mat = principled("clutter%d" % i, color=(rng.random(), rng.random(), rng.random(), 1.0),
                             roughness=rng.uniform(0.2, 0.8))
        thing.data.materials.append(mat)

    # Light: a soft key light above and beside the camera and a dim fill from the world.
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.6, 0.6, 0.65, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.15
    scene.world = world
    key_data = bpy.data.lights.new("key", "AREA")
    key_data.size = 0.4
    key_data.energy = 12.0 * plane_z * plane_z
    key = bpy.data.objects.new("key", key_data)
    scene.collection.objects.link(key)
    median_depth = sorted(depths)[len(depths) // 2]
    start = (rng.uniform(-0.5, 0.5), -0.6, 0.0)
    key.location = start
    key.rotation_euler = (0.0, 0.0, 0.0)
    track = key.constraints.new("TRACK_TO")
    target = bpy.data.objects.new("target", None)
    target.location = (0.0, 0.0, median_depth)
    scene.collection.objects.link(target)
    track.target = target
    track.track_axis, track.up_axis = "TRACK_NEGATIVE_Z", "UP_Y"
    if a.moving_light:
        # The key light sweeps around the object and dims and brightens (a door, a passing person).
        for f in range(0, len(poses), 10):
            angle = 2.0 * math.pi * f / max(1, len(poses))
            key.location = (0.7 * math.cos(angle), -0.6 + 0.3 * math.sin(angle), 0.1)
            key_data.energy = 12.0 * plane_z * plane_z * rng.uniform(0.3, 1.6)
            key.keyframe_insert("location", frame=f)
            key_data.keyframe_insert("energy", frame=f)

    # Depth of field: focused on the median depth, f/8 (the background a little soft).
    cam_data.dof.use_dof = True
    cam_data.dof.focus_distance = median_depth
    cam_data.dof.aperture_fstop = 8.0

    os.makedirs(a.output, exist_ok=True)
    scene.render.filepath = os.path.join(a.output, "######")
    bpy.ops.render.render(animation=True)
    for name in ("K.txt", "pose.txt", "visible.txt"):
        src = os.path.join(a.source, name)
        lines = open(src).read().splitlines(True)
        if name != "K.txt":
            keep, out = len(poses), []
            for line in lines:
                if line.startswith("#"):
                    out.append(line)
                elif keep > 0:
                    out.append(line)
                    keep -= 1
            lines = out
        open(os.path.join(a.output, name), "w").writelines(lines)
    with open(os.path.join(a.output, "generated_by.txt"), "w") as f:
        f.write("blender -b --factory-startup -noaudio -P scripts/photoreal_render.py -- %s\n" % " ".join(
            sys.argv[sys.argv.index("--") + 1:]))


main()
