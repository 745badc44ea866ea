// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Pass 6 (Step 5): patch voxels per key frame, run alone on a carved clone.

#include "test_clone_scenes.hpp"
#include "clone/passes.hpp"

namespace opencv_test {
namespace {

// The pass's contract, per key frame of an object no other hides: the clone with the frame's
// patches covers the silhouette exactly (no pixel outside it: a patch's footprint must stay in the
// silhouette; none of it missed but for rim pixels no voxel centre falls in), and the patches
// are what makes it so. The tower and the L-block of the analytic scene are both seen whole in
// their key frames.
// Bounds: uncovered silhouette pixels at most 0.1% of the silhouette (kKeyFrameMinIoU's budget);
// without the patches at least one key frame misses more than that (the visual hull of six
// views leaves each view's rim to the patches: measured 0.4-2% per frame).
const double kMaxMissedFraction = 1 - kKeyFrameMinIoU;

TEST(Augocc_CloneBuilder_Patches, cover_key_frames_exactly)
{
    for (int model = SCALED_ORTHOGRAPHIC; model <= PERSPECTIVE; model++)
    {
        const AnalyticScene s = makeScene((CameraModel)model, towerAndEll(), 30, 6);
        Ptr<CloneSet> clones = CloneBuilder::create()->build(s.rec, s.keyMasks);
        detail::CloneSetImpl& set = dynamic_cast<detail::CloneSetImpl&>(*clones);
        const CloneBuilder::Params params;
        const detail::PassContext ctx(s.rec, set, params);
        for (const String& name : set.objectNames())
        {
            detail::ObjectClone& obj = set.get(name);
            double worstWithout = 0;
            obj.patches.clear();
            for (int f : s.keyFrames)
            {
                Mat matte;
                set.render(name, f, s.rec.camera(f), s.rec.imageSize, matte);
                const Mat& sil = s.keyMasks.at(name).at(f);
                worstWithout = std::max(worstWithout,
                                        (double)countNonZero(sil & ~matte) / countNonZero(sil));
            }
            const int64 made = detail::passPatches(obj, ctx);
            EXPECT_GT(made, 0) << name;
            for (int f : s.keyFrames)
            {
                Mat matte;
                set.render(name, f, s.rec.camera(f), s.rec.imageSize, matte);
                const Mat& sil = s.keyMasks.at(name).at(f);
                EXPECT_EQ(countNonZero(matte & ~sil), 0) << name << " frame " << f;
                EXPECT_LE((double)countNonZero(sil & ~matte) / countNonZero(sil),
                          kMaxMissedFraction) << name << " frame " << f;
            }
            EXPECT_GT(worstWithout, kMaxMissedFraction) << name;
        }
    }
}

} // namespace
} // namespace opencv_test
