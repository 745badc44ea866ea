# This file is part of augocc. License: Apache-2.0.
"""Shared fixtures: one small synthesized shot (160x120, 12 frames) written as PNG frames and
key-frame masks, and the `augocc` command line run on it stage by stage (track, sfm, clone,
matte, composite), so that the Python pipeline can be compared with the CLI bit for bit."""
import os
import shutil
import subprocess

import cv2
import numpy as np
import pytest

augocc = pytest.importorskip("augocc")

SYNTH = dict(frames=12, imageSize=(160, 120), numKeyFrames=3, numTracks=300)


def augocc_bin():
    path = os.environ.get("AUGOCC_BIN", "")
    if not path or not os.path.exists(path):
        path = shutil.which("augocc") or ""
    return path


def run_cli(*args, check=True):
    exe = augocc_bin()
    if not exe:
        pytest.skip("the augocc command line is not found (set AUGOCC_BIN)")
    r = subprocess.run([exe, "--quiet"] + [str(a) for a in args], capture_output=True,
                       text=True)
    if check and r.returncode != 0:
        raise AssertionError("augocc %s failed (%d): %s" % (args[0], r.returncode, r.stderr))
    return r



@pytest.fixture(scope="session")
def shot(tmp_path_factory):
    """The synthesized shot on disk and in memory."""
    d = tmp_path_factory.mktemp("shot")
    synth = augocc.SceneSynthesizer(**SYNTH)
    scene = synth.synthesize()
    os.makedirs(d / "frames")
    for f, img in enumerate(scene.frames):
        cv2.imwrite(str(d / "frames" / ("%04d.png" % f)), img)
    augocc.writeMasks(str(d / "masks"), scene.keyFrameMasks)
    scene_path = str(d / "scene.yml")
    augocc.writeScene(scene_path, augocc.demoVirtualScene(scene_path))
    return dict(dir=d, synth=synth, scene=scene, pattern=str(d / "frames" / "%04d.png"),
                masks=str(d / "masks"), scene_path=scene_path)


@pytest.fixture(scope="session")
def cli(shot):
    """The command line's outputs on the shot."""
    d = shot["dir"] / "cli"
    os.makedirs(d)
    run_cli("track", "--input", shot["pattern"], "--out", d / "tracks.yml")
    run_cli("sfm", "--tracks", d / "tracks.yml", "--out", d / "reconstruction.yml")
    run_cli("clone", "--reconstruction", d / "reconstruction.yml", "--masks", shot["masks"],
            "--tracks", d / "tracks.yml", "--out", d / "clones.yml.gz")
    run_cli("matte", "--reconstruction", d / "reconstruction.yml", "--clones",
            d / "clones.yml.gz", "--out", d / "mattes")
    run_cli("composite", "--input", shot["pattern"], "--reconstruction",
            d / "reconstruction.yml", "--clones", d / "clones.yml.gz", "--scene",
            shot["scene_path"], "--out", d / "composite")
    return dict(dir=d, tracks=augocc.readTracks(str(d / "tracks.yml")),
                rec=augocc.readReconstruction(str(d / "reconstruction.yml")),
                mattes=augocc.readMasks(str(d / "mattes")))


@pytest.fixture(scope="session")
def pipeline(shot):
    """The Python pipeline on the shot: the same library calls as the CLI's stages."""
    tracks = augocc.FeatureTracker().track(shot["pattern"])
    rec = augocc.recoverCameras(tracks)
    clones = augocc.CloneBuilder().build(rec, augocc.readMasks(shot["masks"]), tracks)
    mattes = augocc.renderMattes(clones, rec)
    meshes = augocc.placeScene(augocc.readScene(shot["scene_path"]), rec, clones)
    return dict(tracks=tracks, rec=rec, clones=clones, mattes=mattes, meshes=meshes)


def read_png(path):
    img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    assert img is not None, path
    return img


def nan_equal(a, b):
    return a.shape == b.shape and np.array_equal(a, b, equal_nan=True)
