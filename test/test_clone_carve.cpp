// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Pass 2 (Step 4): occlusion-aware silhouette carving; a key frame added to a built clone.

#include "test_clone_scenes.hpp"

namespace opencv_test {
namespace {

// A nearer object's silhouette is unknown, not outside: the hidden object keeps its whole shape.
TEST(Augocc_CloneBuilder, occlusion_aware_carving)
{
    const AnalyticScene s = makeScene(SCALED_ORTHOGRAPHIC, frontAndBack(), 30, 6);
    Ptr<CloneSet> aware = CloneBuilder::create()->build(s.rec, s.keyMasks);
    const Figures f = measure(*aware, s, "back", s.whole);
    std::cout << "hidden object, occlusion-aware: non-key mean IoU vs whole " << f.nonKeyMean
              << " min " << f.nonKeyMin << ", key min " << f.keyMin << std::endl;
    EXPECT_GE(f.nonKeyMean, kHiddenMeanIoU);
    EXPECT_GE(f.keyMin, kKeyFrameMinIoU);
    CloneBuilder::Params p;
    p.occlusionAware = false;
    Ptr<CloneSet> naive = CloneBuilder::create(p)->build(s.rec, s.keyMasks);
    const Figures g = measure(*naive, s, "back", s.whole);
    std::cout << "hidden object, paper's carving: non-key mean IoU vs whole " << g.nonKeyMean
              << std::endl;
    EXPECT_LT(g.nonKeyMean, f.nonKeyMean);
}

TEST(Augocc_CloneBuilder, add_key_frame)
{
    AnalyticScene s = makeScene(SCALED_ORTHOGRAPHIC, towerAndEll(), 30, 3);
    Ptr<CloneBuilder> b = CloneBuilder::create();
    Ptr<CloneSet> clones = b->build(s.rec, s.keyMasks);
    const int before = clones->voxelCount("ell");
    const int f = 7;
    const Mat mask = s.visible["ell"][f];
    b->addKeyFrame(*clones, s.rec, "ell", f, mask);
    EXPECT_LE(clones->voxelCount("ell"), before);
    std::vector<int> keys = s.keyFrames;
    keys.push_back(f);
    std::sort(keys.begin(), keys.end());
    EXPECT_EQ(clones->keyFrames("ell"), keys);
    EXPECT_EQ(clones->patchFrames("ell", f), std::vector<int>(1, f));
    Mat matte;
    clones->render("ell", f, s.rec.cameras[f], s.rec.imageSize, matte);
    EXPECT_GE(maskIoU(matte, mask), kKeyFrameMinIoU);
    EXPECT_THROW(b->addKeyFrame(*clones, s.rec, "nobody", f, mask), cv::Exception);
    EXPECT_THROW(b->addKeyFrame(*clones, s.rec, "ell", 1000, mask), cv::Exception);
}

} // namespace
} // namespace opencv_test
