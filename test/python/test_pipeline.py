# This file is part of augocc. License: Apache-2.0.
"""The Python pipeline against the command line on the same synthesized shot: tracks,
reconstruction, mattes and composites equal bit for bit (both call the same library functions;
any difference is a binding bug), and the example of doc/python.md run as written."""
import os
import re

import cv2
import numpy as np
import pytest

from conftest import augocc, nan_equal, read_png, run_cli

SOURCE_DIR = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def test_tracks_equal_cli(cli, pipeline):
    a, b = pipeline["tracks"], cli["tracks"]
    assert a.points() > 50 and a.frames() == 12
    assert nan_equal(a.dense(), b.dense())
    # In-memory frames (cv2's arrays) track the same as the PNG pattern.
    frames = [cv2.imread(os.path.join(os.path.dirname(cli["dir"]), "frames", "%04d.png" % f))
              for f in range(a.frames())]
    assert nan_equal(augocc.FeatureTracker().track(frames).dense(), a.dense())


def test_reconstruction_equal_cli(cli, pipeline):
    a, b = pipeline["rec"], cli["rec"]
    assert len(a.cameras) == len(b.cameras) == 12
    for ca, cb in zip(a.cameras, b.cameras):
        assert ca.frame == cb.frame and ca.model == cb.model
        assert np.array_equal(ca.R, cb.R) and np.array_equal(ca.t, cb.t) and ca.s == cb.s
    assert nan_equal(a.points, b.points)


def test_mattes_equal_cli(cli, pipeline):
    a, b = pipeline["mattes"], cli["mattes"]
    assert sorted(a) == sorted(b) == ["building", "lblock", "tower"]
    for obj in a:
        assert sorted(a[obj]) == list(range(12))
        for f in a[obj]:
            assert a[obj][f].dtype == np.uint8 and a[obj][f].shape == (120, 160)
            assert np.array_equal(a[obj][f], b[obj][f]), (obj, f)
        assert a[obj][0].any()


def test_composite_equal_cli(shot, cli, pipeline):
    rec, clones = pipeline["rec"], pipeline["clones"]
    # The demo scene's sun, as `augocc composite` takes it: resolveSun() in the
    # reconstruction's world, the ground of estimateGround() receiving the virtual shadows.
    sun = augocc.resolveSun(augocc.readScene(shot["scene_path"]), rec)
    assert sun.enabled()
    ground = augocc.estimateGround(rec)
    comp = augocc.Compositor(lightRotation=ground.rotation(), ground=ground, sun=sun)
    assert comp.getParams().sun.sky == sun.sky and comp.getParams().shadowCatcher
    comp.setVirtualObjects(pipeline["meshes"])
    changed = 0
    for cam in rec.cameras:
        frame = shot["scene"].frames[cam.frame]
        out = comp.composite(frame, cam.frame, cam, clones)
        ref = read_png(cli["dir"] / "composite" / ("%04d.png" % cam.frame))
        assert out.dtype == np.uint8 and out.shape == (120, 160, 3)
        assert np.array_equal(out, ref), cam.frame
        changed += int((out != frame).any())
    assert changed == 12  # the virtual objects show in every frame
    # compositeSequence() is `augocc composite` itself.
    out_dir = shot["dir"] / "py_composite"
    n = augocc.compositeSequence(shot["pattern"], rec, clones, pipeline["meshes"], str(out_dir),
                                 mattesDir=str(shot["dir"] / "py_mattes"), sun=sun)
    assert n == 12
    for f in range(12):
        assert np.array_equal(read_png(out_dir / ("%04d.png" % f)),
                              read_png(cli["dir"] / "composite" / ("%04d.png" % f)))
    written = augocc.readMasks(str(shot["dir"] / "py_mattes"))
    for obj in written:
        for f in written[obj]:
            assert np.array_equal(written[obj][f], cli["mattes"][obj][f])


def test_sun_estimate_equal_cli(shot, cli, pipeline, tmp_path):
    """estimateSun() from Python on the frames `augocc sun` picks equals the command line's
    estimate (its scene block prints the direction to 6 decimals and the sky to 4)."""
    rec, clones = pipeline["rec"], pipeline["clones"]
    out = tmp_path / "sun.yml"
    run_cli("sun", "--input", shot["pattern"], "--reconstruction", cli["dir"] /
            "reconstruction.yml", "--clones", cli["dir"] / "clones.yml.gz", "--out", out)
    frames = augocc.sunEstimationFrames(rec, 6)
    assert len(frames) == 6 and frames[0] == rec.cameras[0].frame
    images = [shot["scene"].frames[f] for f in frames]
    ground = augocc.estimateGround(rec)
    est = augocc.estimateSun(images, frames, rec, clones, ground)
    fs = cv2.FileStorage(str(out), cv2.FILE_STORAGE_READ)
    node = fs.getNode("sun")
    d = [node.getNode("direction").at(k).real() for k in range(3)]
    assert np.allclose(est.direction, d, rtol=0, atol=5.1e-7), (est.direction, d)
    assert abs(min(0.99, max(0.0, est.sky)) - node.getNode("sky").real()) <= 5.1e-5
    assert est.frames == 6 and est.groundSamples > 0
    assert abs(np.linalg.norm(est.direction) - 1) < 1e-9
    # Keyword parameters reach the C++ call: without the jackknife no uncertainty is computed.
    quick = augocc.estimateSun(images, frames, rec, clones, ground, jackknifeGroups=0)
    assert quick.angularSigmaDeg == -1 and est.angularSigmaDeg >= 0
    assert np.allclose(quick.direction, est.direction, rtol=0, atol=1e-12)
    sun = augocc.toSun(est, penumbra=0.05)
    assert sun.enabled() and sun.penumbra == 0.05 and sun.sky == est.sky
    # Bad input raises with the C++ message.
    with pytest.raises(augocc.error, match="frame"):
        augocc.estimateSun(images[:2], frames, rec, clones, ground)


def test_scene_sun_forms(shot, pipeline, tmp_path):
    """A scene's sun set from Python is written, read back and resolved as the C++ reads it."""
    rec = pipeline["rec"]
    ground = augocc.estimateGround(rec)
    scene = augocc.readScene(shot["scene_path"])
    demo = augocc.demoSun()
    assert scene.sun.form == augocc.SceneSun.SUN_AZIMUTH_ELEVATION
    assert (scene.sun.azimuthDeg, scene.sun.elevationDeg) == (demo.azimuthDeg, demo.elevationDeg)
    d = augocc.resolveSun(scene, rec).direction
    assert np.allclose(d, augocc.sunDirection(ground, demo.azimuthDeg, demo.elevationDeg),
                       rtol=0, atol=1e-12)
    # A date and place: resolveSun() is solarPosition() then sunDirection().
    az, el = augocc.solarPosition(2026, 6, 21, 12.0, 48.85, 2.35)
    assert 0 <= az < 360 and 0 < el < 90
    scene.sun = augocc.SceneSun(form=augocc.SceneSun.SUN_DATE_TIME, date="2026-06-21",
                                time="12:00", latitudeDeg=48.85, longitudeDeg=2.35, sky=0.3)
    path = str(tmp_path / "scene.yml")
    augocc.writeScene(path, scene)
    back = augocc.readScene(path)
    assert back.sun.form == augocc.SceneSun.SUN_DATE_TIME and back.sun.date == "2026-06-21"
    sun = augocc.resolveSun(back, rec)
    assert np.allclose(sun.direction, augocc.sunDirection(ground, az, el), rtol=0, atol=1e-9)
    assert sun.sky == pytest.approx(0.3)
    # No sun: a disabled Sun, the fixed light.
    scene.sun = augocc.SceneSun()
    assert not augocc.resolveSun(scene, rec).enabled()
    with pytest.raises(augocc.error, match="sky must be in"):
        augocc.Compositor(sun=augocc.Sun(direction=(0, 1, 0), sky=1.5))


def test_clone_set_save_load_render_add_key_frame(shot, pipeline, tmp_path):
    clones, rec = pipeline["clones"], pipeline["rec"]
    path = str(tmp_path / "clones.yml.gz")
    clones.save(path)
    loaded = augocc.CloneSet.load(path)
    assert loaded.objectNames() == clones.objectNames()
    cam = rec.camera(5)
    for obj in clones.objectNames():
        m1, z1 = clones.render(obj, 5, cam, (160, 120), depth=True)
        m2 = loaded.render(obj, 5, cam, (160, 120))
        assert np.array_equal(m1, m2) and np.array_equal(m1, pipeline["mattes"][obj][5])
        assert z1.dtype == np.float32 and np.isinf(z1[m1 == 0]).all()
        assert np.isfinite(z1[m1 > 0]).all()
        assert loaded.voxelCount(obj) == clones.voxelCount(obj) > 0
        assert len(clones.gridSize(obj)) == 3 and clones.voxelSize(obj) > 0
    # A new key frame of the building: frame 2 becomes one, with its patch voxels.
    obj = "building"
    assert 2 not in loaded.keyFrames(obj)
    mask = shot["scene"].visibleMasks[obj][2]
    augocc.CloneBuilder().addKeyFrame(loaded, rec, obj, 2, mask)
    assert 2 in loaded.keyFrames(obj)
    assert loaded.patchFrames(obj, 2) == [2]
    # In a key frame the clone with its patches covers the silhouette (clone_builder.hpp: the
    # patch voxels make up the rest exactly), and never a pixel outside it.
    matte = loaded.render(obj, 2, rec.camera(2), (160, 120))
    inside = mask > 127
    assert not (matte[~inside] > 0).any()
    assert (matte[inside] > 0).mean() > 0.99  # rays per pixel 2: a rare footprint may miss


def test_doc_example_runs(tmp_path, monkeypatch):
    with open(os.path.join(SOURCE_DIR, "doc", "python.md")) as f:
        blocks = re.findall(r"```python\n(.*?)```", f.read(), re.S)
    assert len(blocks) == 1
    assert len(blocks[0].strip().splitlines()) <= 24
    monkeypatch.chdir(tmp_path)
    exec(compile(blocks[0], "doc/python.md", "exec"), {})
    assert len(os.listdir(tmp_path / "shot")) >= 12 + 3
    out = read_png(tmp_path / "shot" / "composite_0005.png")
    assert out.shape == (120, 160, 3)
