// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Issue 18: clones of scenes unlike the synthesizer's (test_clone_town.hpp), with the true
// cameras and 6 key frames. Per pass, how much of the true volume it removes (the diagnostic the
// issue asks the suite to keep), and the targets on the finished clones.

#include "test_clone_town.hpp"
#include "clone/passes.hpp"

namespace opencv_test {
namespace {

using augocc::detail::CloneSetImpl;
using augocc::detail::ObjectClone;
using augocc::detail::PassContext;

// Small frames and grids keep each case to about a second.
const Size kTownSize(320, 240);
// Key frames every 10 frames, 6 of them (the issue: every 9-12 frames, 6 key frames).
const int kKeyStep = 10, kNumKeys = 6;
// Perspective: the camera about 5 scene sizes away (the scenes span about 9 units).
const double kPerspectiveDist = 45;

TownScene mushroomScene(CameraModel model)
{
    return makeTownScene(model, mushroomObjects(), Vec3d(0, 1.2, 0), kPerspectiveDist, 26, 70,
                         kKeyStep, kNumKeys, kTownSize);
}

// The border object leaves the frame in the first frames (ppu 30: x 7.8 is beyond the right edge
// at azimuth -35).
TownScene townScene(CameraModel model)
{
    return makeTownScene(model, townObjects(), Vec3d(1.5, 1.0, -0.5), kPerspectiveDist, 30, 70,
                         kKeyStep, kNumKeys, kTownSize);
}

// Uniform samples of an object's volume.
std::vector<Vec3d> volumeSamples(const TownObject& o, int n, RNG& rng)
{
    Vec3d lo(1e30, 1e30, 1e30), hi = -lo;
    for (const Prism& p : o.parts)
        for (const Vec3d& c : p.corners())
            for (int a = 0; a < 3; a++)
            {
                lo[a] = std::min(lo[a], c[a]);
                hi[a] = std::max(hi[a], c[a]);
            }
    std::vector<Vec3d> out;
    while ((int)out.size() < n)
    {
        const Vec3d X(rng.uniform(lo[0], hi[0]), rng.uniform(lo[1], hi[1]),
                      rng.uniform(lo[2], hi[2]));
        if (o.contains(X))
            out.push_back(X);
    }
    return out;
}

// Deeper than `d` inside the object along the six axis directions.
bool deepInside(const TownObject& o, const Vec3d& X, double d)
{
    for (int a = 0; a < 3; a++)
        for (int s = -1; s <= 1; s += 2)
        {
            Vec3d Y = X;
            Y[a] += s * d;
            if (!o.contains(Y))
                return false;
        }
    return true;
}

bool inGrid(const ObjectClone& obj, const Vec3d& X)
{
    const Vec3d v = obj.grid.toVoxel(X);
    const int i = cvRound(v[0]), j = cvRound(v[1]), k = cvRound(v[2]);
    return obj.grid.inside(i, j, k) && obj.grid.data[obj.grid.index(i, j, k)];
}

// What one pass did to one object's true volume.
struct PassLoss
{
    double lost = 0;      // fraction of the true volume the pass removed
    double deepLost = 0;  // fraction of the volume deeper than 1.5 voxels inside it removed
    double recallMin = 1; // worst non-key recall of the whole silhouette by the grid alone after it
};

const char* const kPassNames[] = {"box", "carve", "grid growth", "unobserved", "patches"};
const int kPasses = 5;

struct ObjectLosses
{
    PassLoss pass[kPasses];
    double kept = 1;  // fraction of the true volume the finished grid holds
};

// Runs CloneBuilder::build()'s passes one at a time (no tracks: no free-space pass) and measures
// each on every object.
std::map<String, ObjectLosses> measurePasses(const TownScene& s, const CloneBuilder::Params& params,
                                             Ptr<CloneSet>& clones)
{
    Ptr<CloneSetImpl> set = makePtr<CloneSetImpl>();
    set->patchRule = params.patches.rule;
    for (const auto& o : s.keyMasks)
        for (const auto& m : o.second)
            set->add(o.first).masks[m.first] = m.second.clone();
    PassContext ctx(s.rec, *set, params);
    ctx.keyFrameMasks = &s.keyMasks;
    RNG rng(18);
    std::map<String, std::vector<Vec3d> > samples;
    std::map<String, std::vector<uchar> > deep, held;
    for (const TownObject& o : s.objects)
    {
        samples[o.name] = volumeSamples(o, 4000, rng);
        held[o.name].assign(samples[o.name].size(), 1);
    }
    std::map<String, ObjectLosses> out;
    for (int p = 0; p < kPasses; p++)
    {
        if (p == 3)
        {
            const augocc::detail::ObservedSurfaces observed =
                augocc::detail::observeSurfaces(*set, s.rec, params.unobserved);
            ctx.observed = &observed;
            for (const String& name : set->objectNames())
                augocc::detail::passUnobserved(set->get(name), ctx);
            ctx.observed = nullptr;
        }
        else
            for (const String& name : set->objectNames())
            {
                ObjectClone& obj = set->get(name);
                if (p == 0) augocc::detail::passBox(obj, ctx);
                if (p == 1) augocc::detail::passCarve(obj, ctx);
                if (p == 2) augocc::detail::passGridGrowth(obj, ctx);
                if (p == 4) augocc::detail::passPatches(obj, ctx);
            }
        for (const TownObject& o : s.objects)
        {
            const ObjectClone& obj = set->get(o.name);
            const std::vector<Vec3d>& X = samples[o.name];
            if (p == 0)
            {
                deep[o.name].resize(X.size());
                for (size_t q = 0; q < X.size(); q++)
                    deep[o.name][q] = deepInside(o, X[q], 1.5 * obj.grid.h);
            }
            int lost = 0, deepLost = 0, nDeep = 0;
            for (size_t q = 0; q < X.size(); q++)
            {
                nDeep += deep[o.name][q];
                if (held[o.name][q] && !inGrid(obj, X[q]))
                {
                    held[o.name][q] = 0;
                    lost++;
                    deepLost += deep[o.name][q];
                }
            }
            PassLoss& l = out[o.name].pass[p];
            l.lost = (double)lost / X.size();
            l.deepLost = (double)deepLost / std::max(1, nDeep);
            // The grid alone (no patches: they apply to one key frame each).
            for (const Camera& cam : s.rec.cameras)
            {
                if (s.isKey(cam.frame))
                    continue;
                Mat matte;
                const auto patches = obj.patches;
                const_cast<ObjectClone&>(obj).patches.clear();
                set->render(o.name, cam.frame, cam, s.rec.imageSize, matte, noArray());
                const_cast<ObjectClone&>(obj).patches = patches;
                const Mat& whole = s.whole.at(o.name).at(cam.frame);
                l.recallMin = std::min(l.recallMin, (double)countNonZero(matte & whole) /
                                                        std::max(1, countNonZero(whole)));
            }
        }
    }
    for (auto& o : out)
    {
        int n = 0;
        for (uchar h : held[o.first])
            n += h;
        o.second.kept = (double)n / held[o.first].size();
    }
    clones = set;
    return out;
}

void printLosses(const char* tag, const std::map<String, ObjectLosses>& losses)
{
    for (const auto& o : losses)
    {
        std::cout << tag << " " << o.first << ": true volume removed per pass (all / deeper than "
                  << "1.5 voxels / grid-only non-key recall min):";
        for (int p = 0; p < kPasses; p++)
            std::cout << cv::format(" %s %.4f/%.4f/%.4f", kPassNames[p], o.second.pass[p].lost,
                                    o.second.pass[p].deepLost, o.second.pass[p].recallMin);
        std::cout << cv::format("; kept %.4f", o.second.kept) << std::endl;
    }
}

typedef testing::TestWithParam<int> Augocc_CloneBuilder_Town;

// Sampling: 4000 volume samples per object, so one lost sample is 0.00025.
const double kMaxDeepLoss = 0.001;
const double kMaxUnobservedDeepLoss = 0.07;

TEST_P(Augocc_CloneBuilder_Town, pass_diagnostic)
{
    const CameraModel model = (CameraModel)GetParam();
    for (int sceneId = 0; sceneId < 2; sceneId++)
    {
        const TownScene s = sceneId == 0 ? mushroomScene(model) : townScene(model);
        Ptr<CloneSet> clones;
        const std::map<String, ObjectLosses> losses = measurePasses(s, CloneBuilder::Params(),
                                                                    clones);
        const String tag = cv::format("[town %s %s]", sceneId ? "town" : "mushroom",
                                      cameraModelName(model).c_str());
        printLosses(tag.c_str(), losses);
        for (const auto& o : losses)
        {
            SCOPED_TRACE(tag + " " + o.first);
            // Steps 1-4 and the growth keep every voxel deeper than 1.5 voxels inside the true
            // object (exact cameras: the visual hull holds it; measured 0 since the trimmed box
            // gives back its contiguous points). Before, the box cut 1.2% / 1.5% of the tower.
            for (int p = 0; p < 3; p++)
                EXPECT_LE(o.second.pass[p].deepLost, kMaxDeepLoss) << kPassNames[p];
            // The unobserved runs are not bounded here: they remove 17-49% of the true volume of
            // every object but the border shed and the house (interior runs under a top seen at a
            // grazing angle, whose voxels fall outside the 1.5-voxel depth tolerance of the
            // nearest footprint; no matte changes). Open (issue 18, doc/clones.md).
        }
        for (const TownObject& o : s.objects)
        {
            const TownFigures f = measureTown(*clones, s, o.name);
            std::cout << tag << " " << o.name << cv::format(": key min %.4f, non-key mean %.4f "
                      "worst %.4f (frame %d), recall min %.4f (frame %d)", f.keyMin, f.nonKeyMean,
                      f.nonKeyMin, f.worstFrame, f.recallMin, f.recallFrame) << std::endl;
        }
    }
}

// Issue 18's targets (true cameras, 6 key frames, silhouettes only): non-key mean IoU >= 0.98 and
// worst >= 0.95 for unhidden objects, mean >= 0.97 for hidden ones, recall >= 0.995 in every
// non-key frame. Measured 2026-12-02 (orthographic / perspective): the mushroom tower (hidden)
// 0.985 / 0.983, recall min 0.9970 / 0.9941 (before the box fix 0.979 / 0.975, 0.9879 / 0.9897);
// the box in front of it 0.983 / 0.981, worst 0.965 / 0.964, recall min 0.9960 / 0.9941. Not met
// yet, bounded below at the measured figures less about 0.005 so that they cannot fall unseen: the
// other objects' non-key mean (silo 0.972 / 0.976, house 0.982 / 0.980, hillside 0.979 / 0.975,
// arch 0.972, border 0.969 / 0.980: the visual hull between key frames 14 degrees apart), worst
// frame (arch 0.924, border 0.915; the hillside 0.943 / 0.951 since Step 1's box without tracks
// ends at the first wide horizontal gap: 0.958 / 0.860 perspective before, its box stretched 5
// units deep by ground points hidden behind it) and recall (arch 0.962, silo 0.978,
// border 0.969: carving keeps a voxel only when its whole footprint is in a silhouette, so a ring
// of about a pixel goes in the frames between key frames, where only the nearest key frame's
// patches help).
const double kTownMeanIoU = 0.98, kTownMinIoU = 0.95, kTownHiddenMeanIoU = 0.97;
const double kTowerRecall = 0.994;  // target 0.995, met orthographic (0.9970); perspective 0.9941
const double kFrontRecall = 0.993;  // target 0.995; measured 0.9941 (perspective)
const double kTownFloorMean = 0.964, kTownFloorMin = 0.91, kTownFloorRecall = 0.957;

TEST_P(Augocc_CloneBuilder_Town, accuracy)
{
    const CameraModel model = (CameraModel)GetParam();
    for (int sceneId = 0; sceneId < 2; sceneId++)
    {
        const TownScene s = sceneId == 0 ? mushroomScene(model) : townScene(model);
        Ptr<CloneSet> clones = CloneBuilder::create()->build(s.rec, s.keyMasks);
        for (const TownObject& o : s.objects)
        {
            const TownFigures f = measureTown(*clones, s, o.name);
            SCOPED_TRACE(cameraModelName(model) + " " + o.name);
            EXPECT_GE(f.keyMin, kKeyFrameMinIoU);
            if (o.name == "tower")
            {
                EXPECT_GE(f.nonKeyMean, kTownHiddenMeanIoU);
                EXPECT_GE(f.recallMin, kTowerRecall);
            }
            else if (o.name == "front")
            {
                EXPECT_GE(f.nonKeyMean, kTownMeanIoU);
                EXPECT_GE(f.nonKeyMin, kTownMinIoU);
                EXPECT_GE(f.recallMin, kFrontRecall);
            }
            else
            {
                EXPECT_GE(f.nonKeyMean, kTownFloorMean);
                EXPECT_GE(f.nonKeyMin, kTownFloorMin);
                EXPECT_GE(f.recallMin, kTownFloorRecall);
            }
        }
    }
}

INSTANTIATE_TEST_SUITE_P(/**/, Augocc_CloneBuilder_Town,
                         testing::Values((int)SCALED_ORTHOGRAPHIC, (int)PERSPECTIVE));

} // namespace
} // namespace opencv_test
