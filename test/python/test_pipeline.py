# This file is part of augocc. License: Apache-2.0.
"""The Python pipeline against the command line on the same synthesized shot: tracks,
reconstruction, mattes and composites equal bit for bit (both call the same library functions;
any difference is a binding bug), and the example of doc/python.md run as written."""
import os
import re

import cv2
import numpy as np
import pytest

from conftest import augocc, nan_equal, read_png

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
    comp = augocc.Compositor(lightRotation=augocc.estimateGround(rec).rotation())
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
                                 mattesDir=str(shot["dir"] / "py_mattes"))
    assert n == 12
    for f in range(12):
        assert np.array_equal(read_png(out_dir / ("%04d.png" % f)),
                              read_png(cli["dir"] / "composite" / ("%04d.png" % f)))
    written = augocc.readMasks(str(shot["dir"] / "py_mattes"))
    for obj in written:
        for f in written[obj]:
            assert np.array_equal(written[obj][f], cli["mattes"][obj][f])


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
