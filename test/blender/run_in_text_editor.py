# Blender side of test/blender/scripting_tab_test.sh: runs an exported shot.py the way an artist
# does in Blender's Scripting tab (the file opened in a Text Editor, Run Script), twice, in
# Blender's interface (the test starts it under Xvfb), and checks the shot it built: one scene
# `augocc_shot` (the second run replaced the first), every clone, patch set and virtual object
# of the script's data, and the camera's world matrix at every frame equal to the script's
# keyframes (augocc_world's transform times the camera matrix) within 1e-5 (float32 keyframes
# of values of order 1-10). Exits 0 when every check passes, 1 otherwise.
# Usage: blender --factory-startup -P run_in_text_editor.py -- SHOT_PY
import json
import os
import re
import sys
import traceback

import bpy
import mathutils

shot_py = sys.argv[sys.argv.index('--') + 1]
with open(shot_py) as f:
    SHOT = json.loads(re.search(r"SHOT_JSON = r'''\n(.*?)\n'''", f.read(), re.S).group(1))


def matrix(v):
    return mathutils.Matrix([v[4 * i:4 * i + 4] for i in range(4)])


def check():
    failures = []
    win = bpy.context.window_manager.windows[0]
    area = max(win.screen.areas, key=lambda a: a.width * a.height)
    area.type = 'TEXT_EDITOR'
    text = bpy.data.texts.load(shot_py)
    area.spaces.active.text = text
    os.chdir('/')  # the script finds its assets from its own file, not the working folder
    for run in range(2):
        with bpy.context.temp_override(window=win, area=area, space_data=area.spaces.active,
                                       edit_text=text):
            bpy.ops.text.run_script()
    scene = win.scene
    shots = [s.name for s in bpy.data.scenes if s.name.startswith('augocc_shot')]
    if scene.name != 'augocc_shot' or shots != ['augocc_shot']:
        failures.append('window scene %s, shot scenes %s' % (scene.name, shots))
    expected = {'augocc_world', 'augocc_camera', 'augocc_ground', 'augocc_sun'}
    for c in SHOT['clones']:
        expected.add('clone_' + c['name'])
        expected |= {'clone_%s_patches_%04d' % (c['name'], p['key_frame']) for p in c['patches']}
    expected |= {o['name'] for o in SHOT['objects']}
    names = {o.name for o in scene.objects}
    if names != expected:
        failures.append('objects: missing %s, unexpected %s' %
                        (sorted(expected - names), sorted(names - expected)))
    if SHOT['footage'] and scene.active_clip is None:
        failures.append('no movie clip')
    world = matrix(SHOT['world_matrix'])
    worst = 0.0
    for c in SHOT['cameras']:
        scene.frame_set(c['frame'] + 1)
        want = world @ matrix(c['matrix'])
        got = scene.camera.matrix_world
        worst = max(worst, max(abs(got[i][j] - want[i][j]) for i in range(4) for j in range(4)))
    if worst > 1e-5:
        failures.append('camera matrix off by %g' % worst)
    print('scripting_tab: %d objects, %d camera keyframes (largest matrix difference %.2g), %s'
          % (len(names), len(SHOT['cameras']), worst,
             'ok' if not failures else 'FAIL: ' + '; '.join(failures)))
    return 1 if failures else 0


def run():
    try:
        status = check()
    except Exception:
        traceback.print_exc()
        status = 1
    sys.stdout.flush()
    os._exit(status)


# After the interface is up (the window and its areas exist then).
bpy.app.timers.register(run, first_interval=0.5)
