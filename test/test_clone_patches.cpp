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
// Bounds: uncovered silhouette pixels at most 0.1% of the silhouette (kKeyFrameMinIoU's budget),
// never more than without the patches. The scene must give the pass work: without patches the
// worst key frame misses silhouette pixels (measured 0.15% orthographic, 0.11% perspective, the
// L-block's rims that the other key frames cut; the tower's at most 0.03%).
const double kMaxMissedFraction = 1 - kKeyFrameMinIoU;

TEST(Augocc_CloneBuilder_Patches, cover_key_frames_exactly)
{
    for (int model = SCALED_ORTHOGRAPHIC; model <= PERSPECTIVE; model++)
    {
        const AnalyticScene s = makeScene((CameraModel)model, towerAndEll(), 30, 6);
        Ptr<CloneSet> clones = CloneBuilder::create()->build(s.rec, s.keyMasks);
        augocc::detail::CloneSetImpl& set = dynamic_cast<augocc::detail::CloneSetImpl&>(*clones);
        const CloneBuilder::Params params;
        const augocc::detail::PassContext ctx(s.rec, set, params);
        double worstWithout = 0;
        int64 made = 0;
        for (const String& name : set.objectNames())
        {
            augocc::detail::ObjectClone& obj = set.get(name);
            std::map<int, double> without;
            obj.patches.clear();
            for (int f : s.keyFrames)
            {
                Mat matte;
                set.render(name, f, s.rec.camera(f), s.rec.imageSize, matte, noArray());
                const Mat& sil = s.keyMasks.at(name).at(f);
                without[f] = (double)countNonZero(sil & ~matte) / countNonZero(sil);
                worstWithout = std::max(worstWithout, without[f]);
            }
            made += augocc::detail::passPatches(obj, ctx);
            for (int f : s.keyFrames)
            {
                Mat matte;
                set.render(name, f, s.rec.camera(f), s.rec.imageSize, matte, noArray());
                const Mat& sil = s.keyMasks.at(name).at(f);
                const double missed = (double)countNonZero(sil & ~matte) / countNonZero(sil);
                EXPECT_EQ(countNonZero(matte & ~sil), 0) << name << " frame " << f;
                EXPECT_LE(missed, kMaxMissedFraction) << name << " frame " << f;
                EXPECT_LE(missed, without[f]) << name << " frame " << f;
            }
        }
        std::cout << cameraModelName((CameraModel)model) << ": worst key frame missed without "
                  << "patches " << 100 * worstWithout << "%, " << made << " patch voxels"
                  << std::endl;
        EXPECT_GT(made, 0);
        EXPECT_GT(worstWithout, 0.0);
    }
}

} // namespace
} // namespace opencv_test
