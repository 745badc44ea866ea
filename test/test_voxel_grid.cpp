// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "test_precomp.hpp"
#include "test_clone_scenes.hpp"
#include "voxel_grid.hpp"
#include "clone/clone_codec.hpp"
#include "clone/key_frame_coverage.hpp"

namespace opencv_test {
namespace {

using namespace cv;
using namespace cv::augocc;
using namespace cv::augocc::detail;

// A camera on an orbit around the origin (test_clone_scenes' orbitCamera, target at the origin).
Camera lookAtCamera(CameraModel model, double azimuthDeg, double elevationDeg, double dist,
                    Size size, double pixelsPerUnit)
{
    return orbitCamera(model, azimuthDeg, elevationDeg, dist, Vec3d(0, 0, 0), size,
                       pixelsPerUnit, 0);
}

Mat blobMask(Size size, RNG& rng)
{
    Mat m(size, CV_8U, Scalar(0));
    for (int q = 0; q < 6; q++)
        circle(m, Point(size.width / 2 + rng.uniform(-60, 60), size.height / 2 + rng.uniform(-60, 60)),
               rng.uniform(20, 70), Scalar(255), FILLED);
    return m;
}

// A grid of `dims` voxels of edge 0.03 turned by `rodrigues`, centred at `centre`, carved by the
// blob silhouettes of three views 50 degrees apart (holes, thin parts).
VoxelGrid carvedBlobGrid(CameraModel model, const Vec3i& dims, const Vec3d& rodrigues,
                         const Vec3d& centre, Size size, RNG& rng)
{
    VoxelGrid g;
    const Matx33d Rb = rotationFromRodrigues(rodrigues);
    const double h = 0.03;
    g.create(dims, Rb, Rb * (Vec3d(-dims[0], -dims[1], -dims[2]) * (0.5 * h)) + centre, h, 1);
    std::vector<CarveView> views;
    for (int v = 0; v < 3; v++)
        views.push_back(g.carveView(lookAtCamera(model, 50.0 * v - 40, 20, 30, size, 40),
                                    blobMask(size, rng)));
    g.carve(views);
    return g;
}

typedef testing::TestWithParam<int> Augocc_VoxelGrid_P;

// The row walk skips voxels by distance bounds: its result must equal the plain per-voxel test.
TEST_P(Augocc_VoxelGrid_P, carve_equals_brute_force)
{
    const CameraModel model = (CameraModel)GetParam();
    RNG rng(7);
    const Size size(320, 240);
    // Voxels of about 2.6 pixels (footprints of several pixels), of about 0.8 pixel (the affine
    // walk's neighbour-mask test), and a grid that reaches off the image (unknown pixels).
    const double edges[3] = {0.065, 0.02, 0.02};
    const Vec3d shifts[3] = {Vec3d(0, 0, 0), Vec3d(0, 0, 0), Vec3d(3.2, 0.5, 0)};
    for (int c = 0; c < 3; c++)
    {
        VoxelGrid g;
        const Matx33d Rb = rotationFromRodrigues(Vec3d(0.1, 0.5, -0.2));
        const double h = edges[c];
        const Vec3i dims(c == 0 ? 70 : 200, c == 0 ? 60 : 180, c == 0 ? 50 : 150);
        g.create(dims, Rb, Rb * (Vec3d(-dims[0], -dims[1], -dims[2]) * (0.5 * h)) + shifts[c], h, 1);
        std::vector<CarveView> views;
        for (int v = 0; v < 3; v++)
        {
            const Camera cam = lookAtCamera(model, 40.0 * v - 30, 20, 30, size, 40);
            views.push_back(g.carveView(cam, blobMask(size, rng)));
        }
        VoxelGrid fast = g;
        fast.carve(views);
        int64 mismatches = 0, kept = 0;
        for (int k = 0; k < g.dims[2]; k++)
            for (int j = 0; j < g.dims[1]; j++)
                for (int i = 0; i < g.dims[0]; i++)
                {
                    bool keep = true;
                    for (const CarveView& v : views)
                        keep = keep && g.footprintKept(v, i, j, k);
                    kept += keep;
                    mismatches += keep != (fast.data[fast.index(i, j, k)] != 0);
                }
        EXPECT_EQ(mismatches, 0) << c;
        EXPECT_GT(kept, 1000) << c;
        EXPECT_LT(kept, g.total()) << c;
    }
}

INSTANTIATE_TEST_SUITE_P(/**/, Augocc_VoxelGrid_P, testing::Values((int)SCALED_ORTHOGRAPHIC,
                                                                    (int)PERSPECTIVE));

TEST(Augocc_VoxelGrid, label_distance_matches_opencv)
{
    RNG rng(5);
    const Mat m = blobMask(Size(200, 150), rng);
    Mat dk, dc;
    distanceTransform(m, dk, DIST_C, 3);
    distanceTransform(m == 0, dc, DIST_C, 3);
    Mat ref = dk + dc, mine;
    labelDistance(m).convertTo(mine, CV_32F);
    EXPECT_MAT_NEAR(mine, ref, 0.0);
}

// The carve's one-pass quadrant distance against its definition, for all four quadrants and a roi.
TEST(Augocc_VoxelGrid, quadrant_distance_matches_definition)
{
    RNG rng(11);
    const Mat m = blobMask(Size(90, 70), rng);
    const Rect roi(7, 5, 70, 55);
    for (int sx : {-1, 1})
        for (int sy : {-1, 1})
        {
            Mat d(m.size(), CV_8SC1, Scalar(0));
            quadrantDistance(m, roi, sx, sy, d);
            int bad = 0;
            for (int y = roi.y; y < roi.br().y; y++)
                for (int x = roi.x; x < roi.br().x; x++)
                {
                    const bool a = m.at<uchar>(y, x) != 0;
                    int best = 127;
                    for (int yy = roi.y; yy < roi.br().y; yy++)
                        for (int xx = roi.x; xx < roi.br().x; xx++)
                            if ((xx - x) * sx >= 0 && (yy - y) * sy >= 0 &&
                                (m.at<uchar>(yy, xx) != 0) != a)
                                best = std::min(best, std::max(std::abs(xx - x), std::abs(yy - y)));
                    bad += d.at<schar>(y, x) != (a ? best : -best);
                }
            EXPECT_EQ(bad, 0) << sx << " " << sy;
        }
}

TEST(Augocc_VoxelGrid, codec_roundtrip_and_surface)
{
    VoxelGrid g;
    g.create(Vec3i(20, 30, 40), Matx33d::eye(), Vec3d(0, 0, 0), 0.1, 0);
    RNG rng(3);
    for (int k = 5; k < 35; k++)
        for (int j = 4; j < 26; j++)
            for (int i = 2; i < 18; i++)
                g.data[g.index(i, j, k)] = rng.uniform(0, 10) > 0 ? 1 : 0;
    const std::vector<uchar> bytes = encodeGrid(g.data, g.dims[0], g.dims[1] * g.dims[2]);
    std::vector<uchar> back;
    decodeGrid(bytes, g.dims[0], g.dims[1] * g.dims[2], back, "test");
    EXPECT_TRUE(back == g.data);
    std::vector<uchar> bad = bytes;
    bad.pop_back();
    EXPECT_THROW(decodeGrid(bad, g.dims[0], g.dims[1] * g.dims[2], back, "test"), cv::Exception);
    // Base64 blobs through FileStorage, every length modulo 3.
    for (size_t n : {0, 1, 2, 3, 5000, 6001})
    {
        std::vector<uchar> blob(n);
        for (size_t q = 0; q < n; q++)
            blob[q] = (uchar)(q * 7 + 3);
        FileStorage w(".yml", FileStorage::WRITE | FileStorage::MEMORY);
        writeBlob(w, "b", blob);
        const std::string text = w.releaseAndGetString();
        FileStorage r(text, FileStorage::READ | FileStorage::MEMORY);
        EXPECT_TRUE(readBlob(r["b"], "test") == blob) << n;
    }

    // A solid block's surface: all voxels but the interior ones.
    VoxelGrid b;
    b.create(Vec3i(10, 12, 14), Matx33d::eye(), Vec3d(0, 0, 0), 1.0, 1);
    EXPECT_EQ((int64)b.surface().size(), b.total() - (int64)8 * 10 * 12);
}

// A solid block's matte is its projected outline (hole-free) whatever the view.
// renderCoverage (mattes without depth) must draw exactly the footprints renderDepth draws:
// carved blobs (holes, thin parts), the front-facing surface culled as the renderer culls it, a
// second list drawn whole (patch voxels), both camera models, a grid reaching off the image.
TEST(Augocc_VoxelGrid, coverage_equals_depth_matte)
{
    const Size size(320, 240);
    RNG rng(11);
    for (int model = 0; model < 2; model++)
        for (double az : {0.0, 47.0})
        {
            const VoxelGrid g = carvedBlobGrid((CameraModel)model, Vec3i(120, 110, 100),
                                               Vec3d(0.2, -0.4, 0.1),
                                               Vec3d(az > 0 ? 2.0 : 0.0, 0, 0), size, rng);
            const SurfaceVoxels s = g.surface();
            ASSERT_GT(s.size(), (size_t)1000);
            std::vector<uint32_t> extra;  // every 7th inside voxel, as a patch list
            for (size_t q = 0; q < s.size(); q += 7)
                extra.push_back(s.ijk[q]);
            std::vector<VoxelList> lists(2);
            lists[0].ijk = s.ijk.data();
            lists[0].faces = s.faces.data();
            lists[0].n = s.size();
            lists[0].frontOnly = true;
            lists[1].ijk = extra.data();
            lists[1].n = extra.size();
            const Camera cam = lookAtCamera((CameraModel)model, az + 13, 28, 30, size, 40);
            const VoxelProjector p = g.projector(cam, size);
            Mat z, cover;
            renderDepth(g, p, lists, z);
            renderCoverage(g, p, lists, cover);
            const Mat fromDepth = z < std::numeric_limits<float>::infinity();
            EXPECT_GT(countNonZero(cover), 1000) << "model " << model << " az " << az;
            EXPECT_EQ(cv::norm(cover, fromDepth, NORM_INF), 0) << "model " << model << " az "
                                                                << az;
        }
}

// The splat passes over the voxels of a row whose footprint cannot meet the buffer (bounds per
// row, both camera models): drawn into a window at an offset, it must equal the window's crop
// of the whole image's depth, for windows inside, across the image's edges and off it, small
// ones too, and for a perspective camera close enough that rows cross behind it.
TEST(Augocc_VoxelGrid, splat_window_equals_crop)
{
    const Size size(320, 240);
    const float inf = std::numeric_limits<float>::infinity();
    RNG rng(5);
    for (int model = 0; model < 2; model++)
        for (double dist : {30.0, 1.0})
        {
            if (model == SCALED_ORTHOGRAPHIC && dist < 10)
                continue;
            const VoxelGrid g = carvedBlobGrid((CameraModel)model, Vec3i(90, 100, 80),
                                               Vec3d(0.3, 0.5, -0.2), Vec3d(0, 0, 0), size, rng);
            const SurfaceVoxels s = g.surface();
            ASSERT_GT(s.size(), (size_t)1000);
            const Camera cam = lookAtCamera((CameraModel)model, 23, 31, dist, size,
                                            dist < 10 ? 120 : 40);
            const VoxelProjector p = g.projector(cam, size);
            for (bool front : {true, false})
            {
                Mat whole(size, CV_32F, Scalar(inf));
                splatVoxels(p, s.ijk.data(), s.faces.data(), s.size(), front, whole, nullptr);
                ASSERT_GT(countNonZero(whole < inf), 2000) << "model " << model;
                const Rect windows[] = {Rect(100, 70, 60, 50), Rect(-20, -10, 90, 80),
                                        Rect(280, 200, 100, 100), Rect(150, 120, 3, 2),
                                        Rect(0, 0, 320, 240), Rect(400, 10, 20, 20)};
                for (const Rect& w : windows)
                {
                    Mat win(w.size(), CV_32F, Scalar(inf));
                    splatVoxels(p, s.ijk.data(), s.faces.data(), s.size(), front, win, nullptr,
                                w.tl());
                    Mat expect(w.size(), CV_32F, Scalar(inf));
                    const Rect in = w & Rect(Point(), size);
                    if (!in.empty())
                        whole(in).copyTo(expect(in - w.tl()));
                    EXPECT_EQ(countNonZero(win != expect), 0)
                        << "model " << model << " dist " << dist << " window " << w;
                }
            }
        }
}

// KeyFrameCoverage::carveInOrder (the free-space pass: key frames' counts in parallel, batches
// taken back at the first refusal) must carve exactly what tryCarve() one by one carves: a
// carved block whose silhouettes refuse many carves (every other candidate is in a key frame's
// silhouette), candidates off the surface and repeated ones.
TEST(Augocc_VoxelGrid, carve_in_order_equals_one_by_one)
{
    const Size size(320, 240);
    RNG rng(5);
    for (int model = 0; model < 2; model++)
    {
        ObjectClone obj;
        const double h = 0.04;
        const Vec3i dims(60, 50, 55);
        obj.grid.create(dims, Matx33d::eye(), Vec3d(-dims[0], -dims[1], -dims[2]) * (0.5 * h),
                        h, 1);
        Reconstruction rec;
        rec.model = (CameraModel)model;
        rec.imageSize = size;
        std::vector<CarveView> views;
        for (int v = 0; v < 4; v++)
        {
            Camera cam = lookAtCamera((CameraModel)model, 45.0 * v - 60, 25, 30, size, 40);
            cam.frame = v;
            rec.cameras.push_back(cam);
            const Mat sil = blobMask(size, rng);
            obj.masks[v] = sil;
            views.push_back(obj.grid.carveView(cam, sil));
        }
        obj.grid.carve(views);
        // Candidates: the surface, then inner voxels (off the surface until peeled), repeated.
        std::vector<Vec3i> cands;
        const SurfaceVoxels surf = obj.grid.surface();
        for (uint32_t p : surf.ijk)
        {
            int i, j, k;
            unpackVoxel(p, i, j, k);
            cands.push_back(Vec3i(i, j, k));
        }
        for (int q = 0; q < 20000; q++)
            cands.push_back(cands[(size_t)rng.uniform(0, (int)cands.size())]);
        ASSERT_GT(surf.size(), (size_t)1000);
        VoxelGrid gridA = obj.grid, gridB = obj.grid;
        std::vector<uchar> carvedA(cands.size(), 0);
        std::vector<std::vector<Vec3i>> exposedA(cands.size());
        {
            KeyFrameCoverage cov(gridA, obj, rec);
            for (size_t n = 0; n < cands.size(); n++)
            {
                const Vec3i& v = cands[n];
                if (!gridA.data[gridA.index(v[0], v[1], v[2])] ||
                    !cov.isSurface(v[0], v[1], v[2]) || !cov.tryCarve(v[0], v[1], v[2]))
                    continue;
                carvedA[n] = 1;
                exposedA[n] = cov.exposed();
            }
        }
        std::vector<uchar> carvedB;
        std::vector<std::vector<Vec3i>> exposedB;
        {
            KeyFrameCoverage cov(gridB, obj, rec);
            cov.carveInOrder(cands, carvedB, exposedB);
        }
        int carved = 0, refused = 0;
        for (size_t n = 0; n < cands.size(); n++)
        {
            carved += carvedA[n];
            refused += !carvedA[n] && n < surf.size();
        }
        EXPECT_GT(carved, 1000) << "model " << model;
        EXPECT_GT(refused, 100) << "model " << model << ": the key frames must refuse some";
        EXPECT_TRUE(carvedA == carvedB) << "model " << model;
        EXPECT_TRUE(exposedA == exposedB) << "model " << model;
        EXPECT_TRUE(gridA.data == gridB.data) << "model " << model;
    }
}

TEST(Augocc_VoxelGrid, splat_is_hole_free)
{
    const Size size(320, 240);
    for (int model = 0; model < 2; model++)
        for (double az : {0.0, 33.0, 71.0})
        {
            const Camera cam = lookAtCamera((CameraModel)model, az, 25, 30, size, 40);
            VoxelGrid g;
            g.create(Vec3i(80, 60, 70), Matx33d::eye(), Vec3d(-1.6, -1.2, -1.4), 0.04, 1);
            const SurfaceVoxels s = g.surface();
            const VoxelProjector p = g.projector(cam, size);
            Mat z(size, CV_32F, Scalar(std::numeric_limits<float>::infinity()));
            splatVoxels(p, s.ijk.data(), s.faces.data(), s.size(), true, z, nullptr);
            Mat matte = z < std::numeric_limits<float>::infinity();
            // Reference: convex hull of the block's 8 corners, sampled at pixel centres.
            std::vector<Point2f> c;
            for (int q = 0; q < 8; q++)
            {
                const Point2d uv = cam.project(g.centre(q & 1 ? 79.5 : -0.5, q & 2 ? 59.5 : -0.5,
                                                        q & 4 ? 69.5 : -0.5));
                c.push_back(Point2f((float)uv.x, (float)uv.y));
            }
            std::vector<Point2f> hull;
            convexHull(c, hull);
            Mat ref(size, CV_8U, Scalar(0));
            for (int y = 0; y < size.height; y++)
                for (int x = 0; x < size.width; x++)
                    if (pointPolygonTest(hull, Point2f((float)x, (float)y), false) >= 0)
                        ref.at<uchar>(y, x) = 255;
            // Footprints are pixel-centre rectangles around each voxel: at most one pixel more
            // than the exact outline on the border, never a hole inside.
            Mat inner;
            erode(ref, inner, Mat());
            EXPECT_EQ(countNonZero(inner & ~matte), 0) << "model " << model << " az " << az;
            Mat outer;
            dilate(ref, outer, Mat());
            EXPECT_EQ(countNonZero(matte & ~outer), 0) << "model " << model << " az " << az;
        }
}

} // namespace
} // namespace opencv_test
