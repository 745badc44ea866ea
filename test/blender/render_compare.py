# Blender side of test/blender/blender_test.sh, run after the exported shot.py in the same
# Blender: renders frames of the shot with transparent film (the clones are holdouts, so the alpha
# is the virtual objects' visible region), and compares that region with the alpha of augocc's
# virtual layer (`augocc composite --virtual-layer`) of the same frames.
# Usage: blender -b --python-exit-code 1 -P shot.py -P render_compare.py -- \
#            LAYER_DIR OUT_DIR MIN_IOU MAX_CENTROID_PX FRAME...
import os
import sys

import bpy
import numpy as np

args = sys.argv[sys.argv.index('--') + 1:]
layer_dir, out_dir = args[0], args[1]
min_iou, max_centroid_px = float(args[2]), float(args[3])
frames = [int(a) for a in args[4:]]

scene = bpy.context.scene
# Few samples suffice: with a pixel filter 0.01 px wide every ray passes through the pixel's
# centre, so the alpha of opaque surfaces and holdouts is exact (no noise), the rule
# augocc's rasteriser uses for the virtual objects (pixel centre inside the triangle).
scene.cycles.samples = 4
scene.cycles.filter_width = 0.01
scene.cycles.use_denoising = False
scene.cycles.max_bounces = 0
# The shot's compositor puts the footage behind the render (alpha 1 everywhere): keep only its
# Movie Distortion node, when the shot has a lens, so that the render is checked through the
# movie clip's distortion model as the shot applies it (augocc's layer is drawn through the lens).
tree = scene.node_tree if scene.use_nodes else None
distortion = [n for n in tree.nodes if n.bl_idname == 'CompositorNodeMovieDistortion'] \
    if tree else []
if distortion:
    out = next(n for n in tree.nodes if n.bl_idname == 'CompositorNodeComposite')
    out.use_alpha = True
    tree.links.new(distortion[0].outputs['Image'], out.inputs['Image'])
    scene.render.use_compositing = True
    print('blender_compare: through the movie clip\'s %s lens model (Movie Distortion node)'
          % distortion[0].clip.tracking.camera.distortion_model)
else:
    scene.render.use_compositing = False
scene.render.image_settings.file_format = 'PNG'
scene.render.image_settings.color_mode = 'RGBA'
# The shadow catcher's shadows are alpha too; augocc's composite draws no shadow.
bpy.data.objects['augocc_ground'].hide_render = True
os.makedirs(out_dir, exist_ok=True)


def alpha(path):
    img = bpy.data.images.load(path)
    w, h = img.size
    a = np.array(img.pixels[:], np.float32).reshape(h, w, 4)[::-1, :, 3]  # rows top-down
    bpy.data.images.remove(img)
    return a


def centroid(mask):
    ys, xs = np.nonzero(mask)
    return np.array([xs.mean(), ys.mean()])


failed = False
for f in frames:
    scene.frame_set(f + 1)  # Blender frame = augocc frame + 1
    scene.render.filepath = os.path.join(out_dir, '%04d.png' % f)
    bpy.ops.render.render(write_still=True)
    blender = alpha(scene.render.filepath) > 0.5
    augocc = alpha(os.path.join(layer_dir, '%04d.png' % f)) > 0.5
    union = np.logical_or(blender, augocc).sum()
    iou = np.logical_and(blender, augocc).sum() / union if union else 0.0
    d = np.linalg.norm(centroid(blender) - centroid(augocc)) if union else np.inf
    ok = iou >= min_iou and d <= max_centroid_px
    failed |= not ok
    print('blender_compare frame %d: visible region %d px (augocc %d px), IoU %.4f, centroid '
          'offset %.3f px %s' % (f, blender.sum(), augocc.sum(), iou, d, 'ok' if ok else 'FAIL'))
sys.exit(1 if failed else 0)
