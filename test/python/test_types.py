# This file is part of augocc. License: Apache-2.0.
"""The contract types' numpy views, keyword Params, errors, callbacks, the GIL and the
lifetime of returned arrays, the synthesizer and the silhouette editor."""
import gc
import os
import sys
import threading
import time

import cv2
import numpy as np
import pytest

from conftest import augocc, nan_equal, run_cli


def test_camera_project_vectorised(shot):
    scene = shot["scene"]
    gt = scene.groundTruth
    pts = gt.points
    ok = np.isfinite(pts).all(axis=1)
    clean = scene.cleanTracks.dense()
    for cam in gt.cameras:
        uv = cam.project(pts[ok])
        assert uv.shape == (ok.sum(), 2) and uv.dtype == np.float64
        # cleanTracks are the exact projections stored as float32: half an ulp at 160 px is
        # 4e-6 px.
        assert np.abs(uv - clean[cam.frame][ok]).max() < 1e-4
        # project() per row is Camera::project: the same as one point at a time.
        assert np.array_equal(uv[:3], np.array([cam.project(p)[0] for p in pts[ok][:3]]))
        z = cam.depth(pts[ok])
        assert z.shape == (ok.sum(),) and (z > 0).all()
    cam = gt.cameras[0]
    assert cam.R.shape == (3, 3) and cam.t.shape == (3,)
    assert np.allclose(cam.R @ cam.R.T, np.eye(3), atol=1e-12)
    c2 = augocc.Camera.orthographic(cam.R, cam.t, cam.s, cam.pp, frame=3)
    assert np.array_equal(c2.project(pts[ok]), cam.project(pts[ok])) and c2.frame == 3
    assert synth_camera_equal(shot["synth"].getCamera(4), gt.camera(4))


def synth_camera_equal(a, b):
    return (a.frame == b.frame and np.array_equal(a.R, b.R) and np.array_equal(a.t, b.t)
            and a.s == b.s)


def test_tracks_views_and_io(shot, tmp_path):
    t = shot["scene"].tracks
    dense = t.dense()
    assert dense.shape == (t.frames(), t.points(), 2) and dense.dtype == np.float32
    idx, uv = t.obs_index, t.obs_uv
    assert idx.shape == (t.observations(), 2) and idx.dtype == np.int32
    assert np.array_equal(dense[idx[:, 0], idx[:, 1]], uv)
    again = augocc.Tracks.fromObservations(t.imageSize, t.frames(), t.points(), idx, uv)
    assert nan_equal(again.dense(), dense)
    assert nan_equal(augocc.Tracks.fromDense(t.imageSize, dense).dense(), dense)
    path = str(tmp_path / "tracks.yml")
    augocc.writeTracks(path, t)
    assert nan_equal(augocc.readTracks(path).dense(), dense)
    rec = shot["scene"].groundTruth
    augocc.writeReconstruction(str(tmp_path / "rec.yml"), rec)
    back = augocc.readReconstruction(str(tmp_path / "rec.yml"))
    assert nan_equal(back.points, rec.points) and back.imageSize == (160, 120)


def test_bad_input_raises_the_cpp_message(tmp_path):
    bad = tmp_path / "tracks.yml"
    bad.write_text("%YAML:1.0\n---\nframes: 3\n")
    with pytest.raises(augocc.error) as e:
        augocc.readTracks(str(bad))
    assert isinstance(e.value, cv2.error)  # `except cv2.error` catches it too
    assert str(bad) in str(e.value) and str(bad) in e.value.err
    assert e.value.code < 0 and e.value.file.endswith(".cpp")
    # The command line reports the same library message (exit 2, CONTRACT.md).
    r = run_cli("sfm", "--tracks", bad, "--out", tmp_path / "rec.yml", check=False)
    assert r.returncode == 2 and e.value.err in r.stderr
    with pytest.raises(augocc.error, match="nothing_here.yml.gz"):
        augocc.CloneSet.load(str(tmp_path / "nothing_here.yml.gz"))
    with pytest.raises(augocc.error, match="frames"):
        augocc.SceneSynthesizer(frames=1)
    with pytest.raises(TypeError, match="noSuchParam"):
        augocc.FeatureTracker(noSuchParam=3)


def test_keyword_params():
    b = augocc.CloneBuilder(voxelPixels=2.0, freeSpace=dict(minViews=0, maxViews=5),
                            box=dict(orientation=1))
    p = b.getParams()
    assert p.voxelPixels == 2.0 and p.freeSpace.minViews == 0 and p.freeSpace.maxViews == 5
    assert p.box.orientation == 1 and p.patches.raysPerPixel == 2  # the rest are defaults
    t = augocc.FeatureTracker(maxTracks=50, winSize=(21, 21))
    assert t.getParams().maxTracks == 50 and t.getParams().winSize == (21, 21)
    c = augocc.Compositor(supersample=1)
    assert c.getParams().supersample == 1 and c.renderSize((160, 120)) == (160, 120)


def test_progress_callbacks_and_gil(shot):
    reports = []
    tracks = augocc.FeatureTracker(progress=reports.append).track(shot["pattern"])
    assert reports and all(r.stage == "track" for r in reports)
    assert reports[-1].done == reports[-1].total == 12
    # The GIL is released in recoverCameras: another Python thread runs meanwhile.
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    sfm_reports = []
    th = threading.Thread(target=tick)
    th.start()
    t0 = time.perf_counter()
    rec, rep = augocc.recoverCameras(tracks, report=True, progress=sfm_reports.append)
    t1 = time.perf_counter()
    stop.set()
    th.join()
    assert len(rec.cameras) == 12 and rep.chosenModel in ("scaled_orthographic", "perspective")
    assert sfm_reports and sfm_reports[0].stage == "sfm"
    assert sum(t0 < t < t1 for t in ticks) >= 3


def test_callback_exception_propagates(shot):
    def boom(p):
        raise RuntimeError("stop here")
    with pytest.raises(RuntimeError, match="stop here"):
        augocc.FeatureTracker(progress=boom).track(shot["pattern"])


def test_lifetime_of_returned_arrays():
    synth = augocc.SceneSynthesizer(frames=3, imageSize=(64, 48), numKeyFrames=2, numTracks=40)
    scene = synth.synthesize()
    frame = scene.frames[1]
    masks = scene.keyFrameMasks
    gt = scene.groundTruth
    points = gt.points
    R = gt.cameras[0].R
    copies = [frame.copy(), masks["building"][0].copy(), points.copy(), R.copy()]
    # Arrays keep the C++ data alive (a capsule owning a cv::Mat reference is their base).
    assert type(frame.base).__name__ == "PyCapsule"
    del scene, synth, gt, masks["lblock"]
    gc.collect()
    junk = [np.full((48, 64, 3), 7, np.uint8) for _ in range(50)]  # reuse freed memory
    assert np.array_equal(frame, copies[0])
    assert np.array_equal(masks["building"][0], copies[1])
    assert nan_equal(points, copies[2]) and np.array_equal(R, copies[3])
    base = frame.base
    n = sys.getrefcount(base)
    view = frame[10:20]
    assert sys.getrefcount(base) == n  # a numpy view references the array, not the capsule
    del view, junk


def test_synthesizer(shot):
    synth, scene = shot["synth"], shot["scene"]
    assert synth.getObjectNames() == scene.objectNames == ["building", "lblock", "tower"]
    assert np.array_equal(synth.renderFrame(7), scene.frames[7])
    assert scene.keyFrames == [0, 5, 11] or len(scene.keyFrames) == 3
    assert sorted(scene.keyFrameMasks["building"]) == scene.keyFrames
    p = synth.getParams()
    assert p.frames == 12 and p.imageSize == (160, 120)
    box = augocc.Mesh.box((-0.5, 0, -0.5), (0.5, 1, 0.5))
    assert box.vertices.shape[1] == 3 and box.faces.shape[1] == 3
    img = synth.renderWithVirtual(3, [box])
    assert img.shape == (120, 160, 3) and not np.array_equal(img, scene.frames[3])
    assert len(scene.depth) == 12 and scene.depth[0].dtype == np.float32


def test_synthesizer_write_streams(shot, tmp_path):
    # write() renders frame by frame: the same frames and masks as synthesize() holds.
    synth, scene = shot["synth"], shot["scene"]
    synth.write(str(tmp_path / "data"))
    for f in (0, 11):
        frame = cv2.imread(str(tmp_path / "data" / "frames" / ("%04d.png" % f)))
        assert np.array_equal(frame, scene.frames[f])
        mask = cv2.imread(str(tmp_path / "data" / "gt" / "masks" / "tower" / ("%04d.png" % f)),
                          cv2.IMREAD_UNCHANGED)
        assert np.array_equal(mask, scene.wholeMasks["tower"][f])
    assert sorted(os.listdir(tmp_path / "data" / "input" / "masks" / "lblock")) == [
        "%04d.png" % f for f in scene.keyFrames]


def test_silhouette_editor_headless(shot):
    frame = shot["scene"].frames[0]
    ed = augocc.SilhouetteEditor()
    ed.setImage(frame)
    assert ed.getImageSize() == (160, 120)
    ed.setSegmentMode(augocc.SilhouetteEditor.STRAIGHT)
    for p in [(40, 30), (100, 30), (100, 80), (40, 80)]:
        assert ed.addPoint(p) == p  # straight clicks are not snapped
    assert ed.closeContour() and ed.getContourCount() == 1
    mask = ed.getMask()
    ref = np.zeros((120, 160), np.uint8)
    cv2.fillPoly(ref, [np.array([(40, 30), (100, 30), (100, 80), (40, 80)], np.int32)], 255)
    assert np.array_equal(mask, ref)  # an axis-aligned rectangle has no ambiguous pixel
    assert ed.undo() and ed.getContourCount() == 1 and ed.hasOpenContour()
    assert ed.redo() and not ed.hasOpenContour()
    # An existing mask loaded for editing comes back within the outline tolerance (1 px).
    truth = shot["scene"].visibleMasks["building"][0]
    ed.loadMask(truth)
    got = ed.getMask() > 127
    inside = truth > 127
    iou = (got & inside).sum() / (got | inside).sum()
    assert iou > 0.9  # 1 px polygon tolerance on a ~40 px wide silhouette
    canvas = frame.copy()
    ed.drawOverlay(canvas)
    assert not np.array_equal(canvas, frame)
    snapped = ed.snapMask(truth)
    assert snapped.shape == truth.shape and snapped.dtype == np.uint8
