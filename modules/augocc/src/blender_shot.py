# This file is part of augocc. License: Apache-2.0.
# The body of the script `augocc export-blender` writes (after SHOT_JSON, this shot's data); it
# is embedded in the library at build time (modules/augocc/CMakeLists.txt). Blender 3.4+.
#
# Conventions (the conversion is done by augocc, src/blender_export.cpp; this script applies it):
# - Blender frame = augocc frame + 1 (Blender numbers clips and image sequences from 1).
# - Everything is a child of the empty `augocc_world`, whose transform takes the reconstruction's
#   world to Blender's z-up world (x right of the mean view, y away from the viewer, z up, the
#   estimated ground at z = 0). Assets and camera keyframes are in the reconstruction's world.
# - OpenCV's camera looks down +z with y down; Blender's looks down -z with y up. The camera's
#   matrix (camera to world) therefore has the columns R^T * diag(1, -1, -1) and the camera centre
#   (an orthographic camera is moved back along its axis, which does not change its image, so that
#   nothing is behind it).
# - Sensor fit HORIZONTAL: ortho_scale = W / s, lens = fx * sensor_width / W, shift_x =
#   (W / 2 - cx - 0.5) / W, shift_y = (cy + 0.5 - H / 2) / W: OpenCV's pixel centres are at
#   integer coordinates (origin at the centre of the top-left pixel), Blender's frame spans
#   [0, W] x [0, H] with y up.

import json
import os

import bpy
import mathutils
import numpy as np

SHOT = json.loads(SHOT_JSON)


def script_folder():
    """The folder this script was written to, which holds its assets folder, however Blender
    runs it. `blender -b -P shot.py` sets __file__ to the script's path; the Scripting tab (Text
    Editor, Run Script) sets it to '<the .blend's path>/<text name>' instead, and the file on
    disk is the text's filepath. No sys.argv: Blender's own arguments are there."""
    candidates = [globals().get('__file__')]
    space = getattr(bpy.context, 'space_data', None)
    if space is not None and space.type == 'TEXT_EDITOR' and space.text is not None:
        candidates.append(space.text.filepath)
    candidates += [t.filepath for t in bpy.data.texts if t.name == SHOT['script']]
    candidates += [t.filepath for t in bpy.data.texts]
    for c in candidates:
        if not c:
            continue
        folder = os.path.dirname(os.path.abspath(bpy.path.abspath(c)))
        if os.path.isdir(os.path.join(folder, SHOT['assets'])):
            return folder
    raise RuntimeError('%s: its assets folder %s was not found beside it: open the script from '
                       'the folder augocc export-blender wrote it to (Text Editor: Text > Open) '
                       'and Run Script, or run: blender -b -P %s' %
                       (SHOT['script'], SHOT['assets'], SHOT['script']))


HERE = script_folder()


def shot_path(p):
    return p if os.path.isabs(p) else os.path.normpath(os.path.join(HERE, p))


def blender_frame(f):
    return f + 1


def read_ply(filepath):
    """The binary little-endian PLY augocc writes (writeMeshPly): vertices, faces, optional
    normals and colours. Returns (xyz, faces, normals or None, rgb or None)."""
    with open(filepath, 'rb') as f:
        elements = []
        line = f.readline().decode('ascii').strip()
        if line != 'ply':
            raise RuntimeError(filepath + ': not a PLY file')
        while True:
            line = f.readline().decode('ascii').strip()
            if line == 'end_header':
                break
            words = line.split()
            if words[0] == 'element':
                elements.append((words[1], int(words[2]), []))
            elif words[0] == 'property':
                elements[-1][2].append(words)
            elif words[0] == 'format' and words[1] != 'binary_little_endian':
                raise RuntimeError(filepath + ': expected binary_little_endian')
        data = f.read()
    types = {'float': '<f4', 'uchar': 'u1', 'int': '<i4'}
    xyz = np.zeros((0, 3), np.float32)
    faces = np.zeros((0, 3), np.int32)
    normals = rgb = None
    offset = 0
    for name, count, props in elements:
        if name == 'vertex':
            dt = np.dtype([(p[2], types[p[1]]) for p in props])
            v = np.frombuffer(data, dt, count, offset)
            offset += dt.itemsize * count
            xyz = np.stack([v['x'], v['y'], v['z']], 1)
            if 'nx' in dt.names:
                normals = np.stack([v['nx'], v['ny'], v['nz']], 1)
            if 'red' in dt.names:
                rgb = np.stack([v['red'], v['green'], v['blue']], 1) / 255.0
        elif name == 'face':
            dt = np.dtype([('n', 'u1'), ('i', '<i4', 3)])
            fc = np.frombuffer(data, dt, count, offset)
            offset += dt.itemsize * count
            if count and not np.all(fc['n'] == 3):
                raise RuntimeError(filepath + ': faces must be triangles')
            faces = fc['i']
    return xyz, faces, normals, rgb


def mesh_object(scene, name, filepath, parent):
    xyz, faces, normals, rgb = read_ply(shot_path(filepath))
    me = bpy.data.meshes.new(name)
    me.vertices.add(len(xyz))
    me.vertices.foreach_set('co', xyz.astype(np.float32).ravel())
    me.loops.add(3 * len(faces))
    me.loops.foreach_set('vertex_index', faces.astype(np.int32).ravel())
    me.polygons.add(len(faces))
    me.polygons.foreach_set('loop_start', np.arange(0, 3 * len(faces), 3, dtype=np.int32))
    me.polygons.foreach_set('loop_total', np.full(len(faces), 3, np.int32))
    me.update()
    me.validate()
    if normals is not None and len(faces):
        me.polygons.foreach_set('use_smooth', np.ones(len(faces), bool))
        me.use_auto_smooth = True
        me.normals_split_custom_set_from_vertices([tuple(n) for n in normals])
    if rgb is not None:
        attr = me.color_attributes.new('Col', 'FLOAT_COLOR', 'POINT')
        rgba = np.concatenate([rgb, np.ones((len(rgb), 1))], 1).astype(np.float32)
        attr.data.foreach_set('color', rgba.ravel())
    ob = bpy.data.objects.new(name, me)
    scene.collection.objects.link(ob)
    ob.parent = parent
    return ob


def srgb_to_linear(c):
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def new_scene():
    """The scene the shot is built in. `blender -b`: the factory settings' empty scene. The
    Scripting tab: a scene of its own, `augocc_shot`, made the window's scene; the open file's
    other scenes stay (resetting the file would free the text that is running), and a shot built
    by an earlier run is replaced."""
    if bpy.context.window is None:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        return bpy.context.scene
    old = bpy.data.scenes.get('augocc_shot')
    scene = bpy.data.scenes.new('augocc_shot')
    bpy.context.window.scene = scene
    if old is not None:
        for ob in list(old.objects):
            bpy.data.objects.remove(ob)
        bpy.data.scenes.remove(old)
        # Its meshes, materials, clip and world now have no user (Blender drops such data when
        # the file is saved anyway).
        bpy.data.orphans_purge(do_recursive=True)
        scene.name = 'augocc_shot'
    return scene


def setup_scene(scene):
    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.samples = SHOT['samples']
    # Debian's Blender 3.4 is built without OpenImageDenoise, and Cycles then refuses to render
    # with denoising on ("Build without OpenImageDenoiser"): off; turn it on where Blender has it.
    scene.cycles.use_denoising = False
    scene.render.resolution_x = SHOT['width']
    scene.render.resolution_y = SHOT['height']
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = 1
    scene.render.pixel_aspect_y = 1
    fps = SHOT['fps']
    scene.render.fps = max(1, round(fps))
    scene.render.fps_base = scene.render.fps / fps
    scene.frame_start = blender_frame(SHOT['first_frame'])
    scene.frame_end = blender_frame(SHOT['end_frame'] - 1)
    # Transparent film: the footage goes behind the render in the compositor; the alpha is the
    # virtual objects where no clone (holdout) hides them, plus the shadow catcher's shadows.
    scene.render.film_transparent = True
    scene.view_settings.view_transform = 'Standard'
    return scene


def add_camera(scene, world):
    data = bpy.data.cameras.new('augocc_camera')
    data.type = SHOT['model']
    data.sensor_fit = 'HORIZONTAL'
    data.sensor_width = SHOT['sensor_width']
    data.clip_start = SHOT['clip_start']
    data.clip_end = SHOT['clip_end']
    cam = bpy.data.objects.new('augocc_camera', data)
    scene.collection.objects.link(cam)
    cam.parent = world
    cam.rotation_mode = 'QUATERNION'
    scene.camera = cam
    last = None
    for c in SHOT['cameras']:
        fr = blender_frame(c['frame'])
        m = mathutils.Matrix([c['matrix'][4 * i:4 * i + 4] for i in range(4)])
        loc, rot, _ = m.decompose()
        if last is not None and last.dot(rot) < 0:
            rot.negate()  # the same rotation, no flip in the interpolation
        last = rot
        cam.location = loc
        cam.rotation_quaternion = rot
        cam.keyframe_insert('location', frame=fr)
        cam.keyframe_insert('rotation_quaternion', frame=fr)
        if 'ortho_scale' in c:
            data.ortho_scale = c['ortho_scale']
            data.keyframe_insert('ortho_scale', frame=fr)
        else:
            data.lens = c['lens']
            data.keyframe_insert('lens', frame=fr)
        data.shift_x = c['shift_x']
        data.shift_y = c['shift_y']
        data.keyframe_insert('shift_x', frame=fr)
        data.keyframe_insert('shift_y', frame=fr)
    for ad in (cam.animation_data, data.animation_data):
        for fc in ad.action.fcurves:
            for k in fc.keyframe_points:
                k.interpolation = 'LINEAR'
    return cam


def add_footage(scene, cam):
    if not SHOT['footage']:
        return None
    clip = bpy.data.movieclips.load(shot_path(SHOT['footage']))
    clip.frame_start = blender_frame(0)
    scene.active_clip = clip
    d = SHOT['distortion']
    if d:
        tc = clip.tracking.camera
        tc.sensor_width = SHOT['sensor_width']
        tc.units = 'PIXELS'
        tc.pixel_aspect = 1
        tc.focal_length_pixels = d['focal_px']
        # In the clip's pixels as the Movie Distortion node and the undistorted background use
        # them: pixel centres at integers, rows from the bottom (augocc wrote (cx, H - 1 - cy)).
        if hasattr(tc, 'principal_point_pixels'):  # Blender 3.5+
            tc.principal_point_pixels = d['principal_px']
        else:
            tc.principal = d['principal_px']
        tc.distortion_model = d['model']
        if d['model'] == 'POLYNOMIAL':
            tc.k1, tc.k2, tc.k3 = d['k1'], d['k2'], d['k3']
        else:
            tc.brown_k1, tc.brown_k2, tc.brown_k3, tc.brown_k4 = d['k1'], d['k2'], d['k3'], 0
            tc.brown_p1, tc.brown_p2 = d['brown_p1'], d['brown_p2']
    cam.data.show_background_images = True
    bg = cam.data.background_images.new()
    bg.source = 'MOVIE_CLIP'
    bg.clip = clip
    bg.clip_user.use_render_undistorted = bool(d)
    bg.alpha = 1.0
    return clip


def add_compositor(scene, clip):
    """Footage behind the render; the render distorted by the clip's lens first."""
    if clip is None:
        return
    scene.use_nodes = True
    tree = scene.node_tree
    tree.nodes.clear()
    layers = tree.nodes.new('CompositorNodeRLayers')
    footage = tree.nodes.new('CompositorNodeMovieClip')
    footage.clip = clip
    over = tree.nodes.new('CompositorNodeAlphaOver')
    out = tree.nodes.new('CompositorNodeComposite')
    render = layers.outputs['Image']
    if SHOT['distortion']:
        distort = tree.nodes.new('CompositorNodeMovieDistortion')
        distort.clip = clip
        distort.distortion_type = 'DISTORT'
        tree.links.new(render, distort.inputs['Image'])
        render = distort.outputs['Image']
    tree.links.new(footage.outputs['Image'], over.inputs[1])
    tree.links.new(render, over.inputs[2])
    tree.links.new(over.outputs['Image'], out.inputs['Image'])


def add_clones(scene, world):
    """The real objects' clones as holdouts: the trimmed model always, each key frame's patch
    voxels in the frames whose patch set holds it. Without a sun they cast no shadow: the real
    objects' shadows are in the footage already. Under the scene's sun they cast shadows onto
    the virtual objects (as augocc's compositor does) and are shadow catchers themselves: Cycles
    computes a catcher's shadow as the ratio of its light with and without the non-catcher
    objects, so a clone's own shadow on the ground (in both) does not darken the footage a second
    time, while the virtual objects' shadows on the clones do (augocc's catcher takes them too)."""
    sunny = SHOT['sun'] is not None
    frames = range(SHOT['first_frame'], SHOT['end_frame'])

    def as_clone(ob):
        ob.is_holdout = True
        ob.visible_shadow = sunny
        ob.is_shadow_catcher = sunny

    for c in SHOT['clones']:
        ob = mesh_object(scene, 'clone_' + c['name'], c['file'], world)
        as_clone(ob)
        for p in c['patches']:
            po = mesh_object(scene, 'clone_%s_patches_%04d' % (c['name'], p['key_frame']), p['file'],
                             world)
            as_clone(po)
            shown = set(p['frames'])
            previous = None
            for f in frames:
                hidden = f not in shown
                if hidden != previous:
                    po.hide_render = po.hide_viewport = hidden
                    po.keyframe_insert('hide_render', frame=blender_frame(f))
                    po.keyframe_insert('hide_viewport', frame=blender_frame(f))
                    previous = hidden


def object_material(name, color, color_attribute):
    """Under the scene's sun a Lambertian (Diffuse BSDF) of albedo `color` (augocc's ambient +
    diffuse colour, lit by sky and sun as add_ground_and_sun() sets them); without it the
    Principled BSDF of before."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    r, g, b = (srgb_to_linear(min(1.0, v)) for v in color)
    if SHOT['sun'] is not None:
        nodes.remove(nodes['Principled BSDF'])
        bsdf = nodes.new('ShaderNodeBsdfDiffuse')
        links.new(bsdf.outputs['BSDF'], nodes['Material Output'].inputs['Surface'])
        bsdf.inputs['Color'].default_value = (r, g, b, 1)
    else:
        bsdf = nodes['Principled BSDF']
        bsdf.inputs['Base Color'].default_value = (r, g, b, 1)
        bsdf.inputs['Roughness'].default_value = 0.8
    if color_attribute:
        attr = nodes.new('ShaderNodeVertexColor')
        attr.layer_name = color_attribute
        color_in = bsdf.inputs['Color'] if SHOT['sun'] is not None else bsdf.inputs['Base Color']
        if SHOT['sun'] is not None:
            # albedo = vertex colour * (ambient + diffuse), as augocc's base * (a + d)
            mix = nodes.new('ShaderNodeMixRGB')
            mix.blend_type = 'MULTIPLY'
            mix.inputs['Fac'].default_value = 1.0
            links.new(attr.outputs['Color'], mix.inputs['Color1'])
            mix.inputs['Color2'].default_value = (r, g, b, 1)
            links.new(mix.outputs['Color'], color_in)
        else:
            links.new(attr.outputs['Color'], color_in)
    return mat


def add_objects(scene, world):
    for o in SHOT['objects']:
        ob = mesh_object(scene, o['name'], o['file'], world)
        attrs = ob.data.color_attributes
        ob.data.materials.append(object_material(o['name'], o['color'],
                                                 attrs[0].name if attrs else None))


def add_ground_and_sun(scene, world):
    """The estimated ground as a shadow catcher, and the light. Under the scene's sun
    (lighting.hpp: a real surface's pixel is rho (s + (1 - s) V max(0, n . L)), s the sky share):
    a SUN light of strength pi (1 - s) (Cycles: a white Lambertian facing a sun of strength E
    has radiance E / pi) and a uniform world of radiance s (a white Lambertian under it: s),
    so that the catcher's ratio with and without the virtual objects is augocc's
    (s + (1 - s) c V_all) / (s + (1 - s) c V_real) up to the sky the objects hide (ambient
    occlusion, which augocc's constant sky leaves out). The sun's angular diameter is augocc's
    penumbra over the virtual objects' mean height above the ground (augocc's penumbra is a
    width on the receiver). Without a sun: the fixed light of before."""
    me = bpy.data.meshes.new('augocc_ground')
    me.from_pydata([tuple(v) for v in SHOT['ground']], [], [(0, 1, 2, 3)])
    ground = bpy.data.objects.new('augocc_ground', me)
    scene.collection.objects.link(ground)
    ground.parent = world
    ground.is_shadow_catcher = True
    sun_data = bpy.data.lights.new('augocc_sun', 'SUN')
    sun = bpy.data.objects.new('augocc_sun', sun_data)
    scene.collection.objects.link(sun)
    sun.parent = world
    # A sun shines along its -z: its +z points towards the light.
    sun.rotation_mode = 'QUATERNION'
    sun.rotation_quaternion = mathutils.Vector(SHOT['sun_direction']).to_track_quat('Z', 'Y')
    world_data = bpy.data.worlds.new('augocc_world')
    scene.world = world_data
    if SHOT['sun'] is None:
        sun_data.energy = 3.0
        world_data.color = (0.3, 0.3, 0.3)  # ambient
        return
    sky = SHOT['sun']['sky']
    sun_data.energy = np.pi * (1 - sky)
    sun_data.angle = SHOT['sun']['angle']
    world_data.color = (sky, sky, sky)
    world_data.use_nodes = True
    world_data.node_tree.nodes['Background'].inputs['Color'].default_value = (sky, sky, sky, 1)
    world_data.node_tree.nodes['Background'].inputs['Strength'].default_value = 1.0


def build_shot():
    scene = setup_scene(new_scene())
    world = bpy.data.objects.new('augocc_world', None)
    scene.collection.objects.link(world)
    world.matrix_world = mathutils.Matrix(
        [SHOT['world_matrix'][4 * i:4 * i + 4] for i in range(4)])
    cam = add_camera(scene, world)
    clip = add_footage(scene, cam)
    add_compositor(scene, clip)
    add_clones(scene, world)
    add_objects(scene, world)
    add_ground_and_sun(scene, world)
    scene.frame_set(scene.frame_start)
    if SHOT['blend']:
        bpy.ops.wm.save_as_mainfile(filepath=shot_path(SHOT['blend']))


build_shot()
