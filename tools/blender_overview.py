# This file is part of augocc. License: Apache-2.0.
# The picture of doc/blender.md (left half): the shot built by an exported shot.py seen from a
# second camera, with the clones shown grey (not holdout) on a visible ground. Frame 4 of the
# test's orthographic shot (test/blender/blender_test.sh); writes /tmp/bt/overview.png.
# Usage: blender -b -P shot.py -P tools/blender_overview.py
import bpy, mathutils
s = bpy.context.scene
s.frame_set(5)
s.render.use_compositing = False
s.render.film_transparent = False
s.world.color = (0.15, 0.17, 0.22)
grey = bpy.data.materials.new('clone_grey'); grey.diffuse_color = (0.7, 0.7, 0.72, 1)
grey.use_nodes = True
grey.node_tree.nodes['Principled BSDF'].inputs['Base Color'].default_value = (0.35, 0.35, 0.4, 1)
for ob in s.objects:
    if ob.name.startswith('clone_'):
        ob.is_holdout = False
        ob.visible_shadow = True
        ob.data.materials.append(grey)
g = bpy.data.objects['augocc_ground']
g.is_shadow_catcher = False
gm = bpy.data.materials.new('ground'); gm.use_nodes = True
gm.node_tree.nodes['Principled BSDF'].inputs['Base Color'].default_value = (0.25, 0.3, 0.2, 1)
g.data.materials.append(gm)
ov = bpy.data.objects.new('overview', bpy.data.cameras.new('overview'))
s.collection.objects.link(ov)
ov.data.lens = 30
ov.location = (9, -12, 7)
target = mathutils.Vector((0, 0, 1.5))
ov.rotation_euler = (target - ov.location).to_track_quat('-Z', 'Y').to_euler()
s.camera = ov
s.render.resolution_x, s.render.resolution_y = 480, 300
s.cycles.samples = 24
s.render.image_settings.color_mode = 'RGB'
s.render.filepath = '/tmp/bt/overview.png'
bpy.ops.render.render(write_still=True)
