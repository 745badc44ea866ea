// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Pass 5: vertical runs no frame sees.

#include "test_clone_scenes.hpp"
#include "clone/clone_set.hpp"

namespace opencv_test {
namespace {

// Vertical runs of voxels that no frame sees (Params::unobserved): on the synthesized scene the
// tower's lower shaft is behind the building in the first key frames and behind its own front in
// the last, so the visual hull keeps a wedge behind it that shows in its matte as if alone. Measured
// 2026-12-01 (orthographic), tower's non-key mean IoU with its whole silhouette 0.9654 -> 0.9717
// (worst frame 0.920 -> 0.942), recall 0.99698 -> 0.99688; building and L-block within 0.0005.
// Since the box gives back trimmed points at faces no key frame sees (2026-12-02): 0.9662 ->
// 0.9719 (worst 0.919 -> 0.939).
// Bounds: the tower gains at least 0.005; no object's recall loses more than 0.001, nor its IoU.
// With the unseen runs opened (keepNearSeen 1, regrowFromUnseen 3; 2026-12-08) the figures are
// the same to 1e-4 (tower 0.9719 against 0.9719 when every unseen run goes) and the surface is
// half as large.
TEST(Augocc_CloneBuilder_Unobserved, synth_tower)
{
    SyntheticScene s;
    SceneSynthesizer::create()->synthesize(s);
    CloneBuilder::Params keep;
    keep.unobserved.enabled = false;
    Ptr<CloneSet> a = CloneBuilder::create(keep)->build(s.groundTruth, s.keyFrameMasks, &s.tracks);
    Ptr<CloneSet> b = CloneBuilder::create()->build(s.groundTruth, s.keyFrameMasks, &s.tracks);
    CloneBuilder::Params every;
    every.unobserved.keepNearSeen = 0;
    every.unobserved.regrowFromUnseen = 0;
    Ptr<CloneSet> c = CloneBuilder::create(every)->build(s.groundTruth, s.keyFrameMasks,
                                                         &s.tracks);
    auto surface = [](const Ptr<CloneSet>& set, const String& name) {
        return (double)dynamic_cast<const cv::augocc::detail::CloneSetImpl&>(*set).get(name).surface.size();
    };
    for (const String& name : b->objectNames())
    {
        std::cout << name << ": surface voxels " << surface(a, name) << " without the pass, "
                  << surface(b, name) << " with it, " << surface(c, name)
                  << " when every unseen run goes" << std::endl;
        // Runs removed under a top only partly seen leave shafts whose walls are surface: every
        // unseen run gone gave 2.2-3.0x the surface of the clone without the pass (2026-12-08:
        // 154k / 208k / 159k voxels against 70k / 79k / 54k); the opened runs 1.24-1.52x.
        EXPECT_LE(surface(b, name), 1.6 * surface(a, name)) << name;
        EXPECT_LT(surface(b, name), 0.7 * surface(c, name)) << name;
        const SynthFigures fa = measureSynth(*a, s, name), fb = measureSynth(*b, s, name);
        std::cout << name << ": non-key mean IoU " << fa.nonKeyMean << " -> " << fb.nonKeyMean
                  << ", worst " << fa.nonKeyMin << " -> " << fb.nonKeyMin << ", recall "
                  << fa.recall << " -> " << fb.recall << ", voxels " << a->voxelCount(name)
                  << " -> " << b->voxelCount(name) << std::endl;
        EXPECT_GE(fb.keyMin, kKeyFrameMinIoU) << name;
        EXPECT_GE(fb.recall, fa.recall - 0.001) << name;
        EXPECT_GE(fb.nonKeyMean, fa.nonKeyMean - 0.001) << name;
        if (name == "tower")
        {
            EXPECT_GE(fb.nonKeyMean, fa.nonKeyMean + 0.005);
        }
    }
}

} // namespace
} // namespace opencv_test
