// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Pass 3: the grid grows to hold the visual hull the key frames need beyond Step 3's box.

#include "test_clone_scenes.hpp"
#include "clone/passes.hpp"

namespace opencv_test {
namespace {

// Step 3's box cut short: the top quarter of the tower's box taken off (as when few tracks place
// it, or a cap is wider than its points suggest), the grid made from it and carved. The carved
// clone then misses the tower's top in every frame, patches alone covering it in the key frames.
// passGridGrowth must take the missing part back: the non-key mean IoU with the whole silhouette
// within 0.01 of the clone built from the full box (measured 0.987 / 0.991 full, 0.982 / 0.985
// grown, orthographic / perspective), and well above the cut clone's (0.816 / 0.811).
const double kMaxIoULossAfterGrowth = 0.01;

double nonKeyMeanIoU(const augocc::detail::CloneSetImpl& set, const AnalyticScene& s, const String& name)
{
    double sum = 0;
    int n = 0;
    for (const Camera& cam : s.rec.cameras)
    {
        if (std::find(s.keyFrames.begin(), s.keyFrames.end(), cam.frame) != s.keyFrames.end())
            continue;
        Mat matte;
        set.render(name, cam.frame, cam, s.rec.imageSize, matte, noArray());
        sum += maskIoU(matte, s.whole.at(name).at(cam.frame));
        n++;
    }
    return sum / n;
}

TEST(Augocc_CloneBuilder_GridGrowth, restores_a_cut_box)
{
    for (int model = SCALED_ORTHOGRAPHIC; model <= PERSPECTIVE; model++)
    {
        const AnalyticScene s = makeScene((CameraModel)model, towerAndEll(), 30, 6);
        Ptr<CloneSet> clones = CloneBuilder::create()->build(s.rec, s.keyMasks);
        augocc::detail::CloneSetImpl& set = dynamic_cast<augocc::detail::CloneSetImpl&>(*clones);
        CloneBuilder::Params params;
        params.unobserved.enabled = false;
        augocc::detail::PassContext ctx(s.rec, set, params);
        ctx.keyFrameMasks = &s.keyMasks;  // 0 / 255, as build() hands them over
        augocc::detail::ObjectClone& tower = set.get("tower");
        // The reference: Steps 1-4 and the growth from the full box, no patches.
        augocc::detail::passBox(tower, ctx);
        augocc::detail::passCarve(tower, ctx);
        augocc::detail::passGridGrowth(tower, ctx);
        tower.patches.clear();
        const double full = nonKeyMeanIoU(set, s, "tower");
        // The cut box along the grid axis nearest the vertical (the box's second axis: up).
        augocc::detail::passBox(tower, ctx);
        augocc::detail::Box cut = tower.box;
        cut.hi[1] -= 0.25 * (cut.hi[1] - cut.lo[1]);
        tower.box = cut;
        augocc::detail::makeGrid(tower, cut, ctx);
        augocc::detail::passCarve(tower, ctx);
        const double before = nonKeyMeanIoU(set, s, "tower");
        const int64 grown = augocc::detail::passGridGrowth(tower, ctx);
        const double after = nonKeyMeanIoU(set, s, "tower");
        std::cout << cameraModelName((CameraModel)model) << " tower non-key IoU: full box "
                  << full << ", cut box " << before << ", grown " << after << " (+" << grown
                  << " voxels)" << std::endl;
        EXPECT_GT(grown, 0);
        EXPECT_GE(after, full - kMaxIoULossAfterGrowth);
        EXPECT_GT(after - before, 2 * kMaxIoULossAfterGrowth);
    }
}

} // namespace
} // namespace opencv_test
