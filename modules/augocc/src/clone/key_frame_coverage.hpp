// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Carving beyond the visual hull (photo-consistency, free space) under the key-frame silhouettes'
// protection: what both carvers share (the frames they use, the key-frame cover bookkeeping).

#ifndef OPENCV_AUGOCC_KEY_FRAME_COVERAGE_HPP
#define OPENCV_AUGOCC_KEY_FRAME_COVERAGE_HPP

#include "clone/clone_set.hpp"

namespace cv {
namespace augocc {
namespace detail {

//! At most maxViews cameras (0: all), evenly spaced over the reconstruction's (fixed indices: the
//! same for any thread count).
inline std::vector<const Camera*> evenlySpacedCameras(const Reconstruction& rec, int maxViews)
{
    const int total = (int)rec.cameras.size();
    const int n = maxViews > 0 ? std::min(total, maxViews) : total;
    std::vector<const Camera*> use(n);
    for (int c = 0; c < n; c++)
        use[c] = &rec.cameras[n > 1 ? (int)((int64)c * (total - 1) / (n - 1)) : 0];
    return use;
}

// Key-frame protection: per key frame, how many surface voxels' footprints cover each pixel. The
// union of the surface's footprints is the clone's matte (the renderer draws only the surface),
// so a carve that would bring a silhouette pixel to zero is refused: the user's silhouettes stay
// covered by the model itself, not only by patch voxels.
class KeyFrameCoverage
{
public:
    KeyFrameCoverage(VoxelGrid& g, const ObjectClone& obj, const Reconstruction& rec) : g_(g)
    {
        for (const auto& m : obj.masks)
        {
            sil_.push_back(&m.second);
            proj_.push_back(g_.projector(rec.camera(m.first), m.second.size()));
        }
        count_.resize(sil_.size());
        const SurfaceVoxels s = g_.surface();
        parallel_for_(Range(0, (int)sil_.size()), [&](const Range& r) {
            for (int q = r.start; q < r.end; q++)
            {
                count_[q].create(sil_[q]->size(), CV_16U);
                count_[q].setTo(Scalar(0));
                for (uint32_t v : s.ijk)
                {
                    int i, j, k;
                    unpackVoxel(v, i, j, k);
                    add(q, i, j, k, 1);
                }
            }
        });
    }

    bool isSurface(int i, int j, int k) const
    {
        const VoxelGrid& g = g_;
        return i == 0 || j == 0 || k == 0 || i + 1 == g.dims[0] || j + 1 == g.dims[1] ||
               k + 1 == g.dims[2] || !g.data[g.index(i - 1, j, k)] ||
               !g.data[g.index(i + 1, j, k)] || !g.data[g.index(i, j - 1, k)] ||
               !g.data[g.index(i, j + 1, k)] || !g.data[g.index(i, j, k - 1)] ||
               !g.data[g.index(i, j, k + 1)];
    }

    /** Carves voxel (i, j, k) (inside, on the surface) unless a key-frame silhouette pixel would
    lose its last cover; the neighbours it exposes join the surface (exposed()). True when
    carved. */
    bool tryCarve(int i, int j, int k)
    {
        static const int nb[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0},
                                     {0, 1, 0},  {0, 0, -1}, {0, 0, 1}};
        exposed_.clear();
        for (int n = 0; n < 6; n++)
        {
            const int a = i + nb[n][0], b = j + nb[n][1], c = k + nb[n][2];
            if (g_.inside(a, b, c) && g_.data[g_.index(a, b, c)] && !isSurface(a, b, c))
                exposed_.push_back(Vec3i(a, b, c));
        }
        // The check without touching the counts: a pixel of the voxel's footprint keeps its
        // cover when its count, plus the exposed voxels' footprints that hold it, stays above
        // one (the same test as adding them first and taking them back on refusal, which cost
        // twice the adds of every refused carve).
        for (size_t q = 0; q < count_.size(); q++)
        {
            int x0, x1, y0, y1;
            double z;
            if (!proj_[q].footprint(i, j, k, x0, x1, y0, y1, z))
                continue;
            const Mat& s = *sil_[q];
            const Mat& c = count_[q];
            x0 = std::max(x0, 0);
            y0 = std::max(y0, 0);
            x1 = std::min(x1, s.cols - 1);
            y1 = std::min(y1, s.rows - 1);
            rects_.clear();
            bool rectsReady = false;
            for (int y = y0; y <= y1; y++)
            {
                const uchar* sr = s.ptr<uchar>(y);
                const ushort* cr = c.ptr<ushort>(y);
                for (int x = x0; x <= x1; x++)
                {
                    if (!sr[x] || cr[x] > 1)
                        continue;
                    if (!rectsReady)
                    {
                        for (const Vec3i& e : exposed_)
                        {
                            Vec4i r;
                            if (proj_[q].footprint(e[0], e[1], e[2], r[0], r[1], r[2], r[3], z))
                                rects_.push_back(r);
                        }
                        rectsReady = true;
                    }
                    int cover = cr[x];
                    for (const Vec4i& r : rects_)
                        cover += x >= r[0] && x <= r[1] && y >= r[2] && y <= r[3];
                    if (cover <= 1)
                        return false;
                }
            }
        }
        for (size_t q = 0; q < count_.size(); q++)
            for (const Vec3i& e : exposed_)
                add(q, e[0], e[1], e[2], 1);
        for (size_t q = 0; q < count_.size(); q++)
            add(q, i, j, k, -1);
        g_.data[g_.index(i, j, k)] = 0;
        return true;
    }

    //! The voxels the last successful tryCarve() brought to the surface.
    const std::vector<Vec3i>& exposed() const { return exposed_; }

private:
    void add(size_t q, int i, int j, int k, int d)
    {
        int x0, x1, y0, y1;
        double z;
        if (!proj_[q].footprint(i, j, k, x0, x1, y0, y1, z))
            return;
        Mat& c = count_[q];
        for (int y = std::max(y0, 0); y <= std::min(y1, c.rows - 1); y++)
        {
            ushort* row = c.ptr<ushort>(y);
            for (int x = std::max(x0, 0); x <= std::min(x1, c.cols - 1); x++)
                row[x] = (ushort)std::min(65535, std::max(0, row[x] + d));
        }
    }

    VoxelGrid& g_;
    std::vector<const Mat*> sil_;
    std::vector<VoxelProjector> proj_;
    std::vector<Mat> count_;
    std::vector<Vec3i> exposed_;
    std::vector<Vec4i> rects_;  // tryCarve: the exposed voxels' footprints in one key frame
};

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
