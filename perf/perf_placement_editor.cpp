// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "perf_precomp.hpp"

namespace {

using namespace cv;
using namespace cv::augocc;

// `augocc place`'s live preview at 1280x720: the synthesized shot with its true cameras and the
// clones of its three real objects, a virtual sphere of about 100k triangles standing beside the
// building. Built once (the clones take a while).
struct PlaceInputs
{
    SyntheticScene scene;
    Ptr<CloneSet> clones;
    VirtualScene virtualScene;
};

const PlaceInputs& placeInputs()
{
    static const PlaceInputs in = [] {
        PlaceInputs p;
        SceneSynthesizer::Params sp;
        sp.frames = 3;
        sp.numKeyFrames = 2;
        sp.orbitDegrees = 10;
        sp.imageSize = Size(1280, 720);
        SceneSynthesizer::create(sp)->synthesize(p.scene);
        p.clones = CloneBuilder::create()->build(p.scene.groundTruth, p.scene.keyFrameMasks);
        SceneObject o;
        o.name = "sphere";
        // 2 * 317 * 158 = 100172 triangles (perf_compositor.cpp's sphere).
        Mesh m = Mesh::sphere(0.5f, 317, 158);
        m.transform(Matx44d(1, 0, 0, 0, 0, 1, 0, 0.5, 0, 0, 1, 0, 0, 0, 0, 1));
        m.material.diffuse = Vec3f(0.8f, 0.5f, 0.3f);
        o.meshes = {m};
        o.placement = SceneObject::PLACE_BESIDE;
        o.anchor = "building";
        o.size = 0.5;
        p.virtualScene.objects = {o};
        return p;
    }();
    return in;
}

// One step of a drag as the window runs it: the cursor moves a few pixels, the object follows on
// the ground (re-placed, re-lit, re-uploaded), the frame is composited with occlusion
// (preview = 1 step; frames/s = 1000 / ms).
void Augocc_PlacementEditor_dragPreview(benchmark::State& state)
{
    const PlaceInputs& in = placeInputs();
    PlacementEditor::Params p;
    p.supersample = (int)state.range(0);
    Ptr<PlacementEditor> ed = PlacementEditor::create(in.scene.groundTruth, in.clones,
                                                      in.virtualScene, p);
    ed->setFrame(1, in.scene.frames[1]);
    const Point start = Point(ed->getCamera().project(ed->getBasePoint(0)));
    Mat preview;
    ed->render(preview);  // context, first upload
    if (!ed->beginDrag(start))
    {
        state.SkipWithError("the sphere is not under its base point");
        return;
    }
    int i = 0;
    for (auto _ : state)
    {
        // Back and forth over 40 px, 4 px a step.
        const int k = i++ % 20;
        ed->dragTo(start + Point(4 * (k < 10 ? k : 20 - k), 0));
        ed->render(preview);
        benchmark::DoNotOptimize(preview.data);
    }
    ed->endDrag();
    if (preview.empty())
        state.SkipWithError("empty preview");
}
BENCHMARK(Augocc_PlacementEditor_dragPreview)
    ->Name("Augocc_PlacementEditor/drag_preview_720p_100k_tris")
    ->ArgNames({"supersample"})->Arg(1)->Arg(3)->Unit(benchmark::kMillisecond)->UseRealTime();

// Scrubbing: another frame shown, the scene unchanged (no re-upload).
void Augocc_PlacementEditor_scrubPreview(benchmark::State& state)
{
    const PlaceInputs& in = placeInputs();
    PlacementEditor::Params p;
    p.supersample = (int)state.range(0);
    Ptr<PlacementEditor> ed = PlacementEditor::create(in.scene.groundTruth, in.clones,
                                                      in.virtualScene, p);
    Mat preview;
    int f = 0;
    ed->setFrame(0, in.scene.frames[0]);
    ed->render(preview);
    for (auto _ : state)
    {
        f = (f + 1) % (int)in.scene.frames.size();
        ed->setFrame(f, in.scene.frames[f]);
        ed->render(preview);
        benchmark::DoNotOptimize(preview.data);
    }
    if (preview.empty())
        state.SkipWithError("empty preview");
}
BENCHMARK(Augocc_PlacementEditor_scrubPreview)
    ->Name("Augocc_PlacementEditor/scrub_preview_720p_100k_tris")
    ->ArgNames({"supersample"})->Arg(1)->Arg(3)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
