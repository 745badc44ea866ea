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
        exposed_.clear();
        exposedBy(Vec3i(i, j, k), exposed_);
        for (size_t q = 0; q < count_.size(); q++)
            if (!allowed(q, Vec3i(i, j, k), exposed_.data(), exposed_.size(), rects_))
                return false;
        for (size_t q = 0; q < count_.size(); q++)
            apply(q, Vec3i(i, j, k), exposed_.data(), exposed_.size(), 1);
        g_.data[g_.index(i, j, k)] = 0;
        return true;
    }

    /** tryCarve() on each of `cands` in order, skipping those no longer inside or on the surface
    when their turn comes: the same carves, with the key frames' counts kept in parallel.
    Attempts go in batches: tentatively carved in order (each one's exposed voxels found as
    tryCarve finds them), then every key frame walks the batch on its own counts until a voxel it
    refuses; the batch holds up to the first refusal of any key frame (the counts of the walks
    beyond it are taken back), that voxel stays, and the attempts after it start again.
    carved[n]: candidate n was carved; exposedOf[n]: the voxels it brought to the surface. */
    void carveInOrder(const std::vector<Vec3i>& cands, std::vector<uchar>& carved,
                      std::vector<std::vector<Vec3i>>& exposedOf)
    {
        const size_t N = cands.size();
        carved.assign(N, 0);
        exposedOf.assign(N, std::vector<Vec3i>());
        const int nk = (int)count_.size();
        std::vector<size_t> who;   // attempt -> candidate
        std::vector<Vec3i> flat;   // the attempts' exposed voxels, attempt after attempt
        std::vector<size_t> start; // attempt -> its first in flat
        std::vector<int> stop(nk);
        size_t batch = 64, next = 0;
        while (next < N)
        {
            who.clear();
            flat.clear();
            start.assign(1, 0);
            for (; next < N && who.size() < batch; next++)
            {
                const Vec3i& v = cands[next];
                if (!g_.data[g_.index(v[0], v[1], v[2])] || !isSurface(v[0], v[1], v[2]))
                    continue;
                exposedBy(v, flat);
                g_.data[g_.index(v[0], v[1], v[2])] = 0;
                who.push_back(next);
                start.push_back(flat.size());
            }
            const int A = (int)who.size();
            if (A == 0)
                break;
            parallel_for_(Range(0, nk), [&](const Range& r) {
                std::vector<Vec4i> rects;
                for (int q = r.start; q < r.end; q++)
                {
                    stop[q] = A;
                    for (int a = 0; a < A; a++)
                    {
                        const Vec3i* e = flat.data() + start[a];
                        const size_t ne = start[a + 1] - start[a];
                        if (!allowed(q, cands[who[a]], e, ne, rects))
                        {
                            stop[q] = a;
                            break;
                        }
                        apply(q, cands[who[a]], e, ne, 1);
                    }
                }
            });
            const int ok = *std::min_element(stop.begin(), stop.end());
            if (ok < A)
                parallel_for_(Range(0, nk), [&](const Range& r) {
                    for (int q = r.start; q < r.end; q++)
                        for (int a = ok; a < stop[q]; a++)
                            apply(q, cands[who[a]], flat.data() + start[a],
                                  start[a + 1] - start[a], -1);
                });
            for (int a = 0; a < ok; a++)
            {
                carved[who[a]] = 1;
                exposedOf[who[a]].assign(flat.begin() + start[a], flat.begin() + start[a + 1]);
            }
            if (ok < A)
            {
                // Attempt ok is refused: the grid as it was before it, the rest tried again.
                for (int a = A - 1; a >= ok; a--)
                {
                    const Vec3i& v = cands[who[a]];
                    g_.data[g_.index(v[0], v[1], v[2])] = 1;
                }
                next = who[ok] + 1;
                batch = std::max<size_t>(16, batch / 4);
            }
            else
                batch = std::min<size_t>(4096, batch * 2);
        }
    }

    //! The voxels the last successful tryCarve() brought to the surface.
    const std::vector<Vec3i>& exposed() const { return exposed_; }

private:
    // The neighbours of v (inside, on the surface) that carving it brings to the surface.
    void exposedBy(const Vec3i& v, std::vector<Vec3i>& out) const
    {
        static const int nb[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0},
                                     {0, 1, 0},  {0, 0, -1}, {0, 0, 1}};
        for (int n = 0; n < 6; n++)
        {
            const int a = v[0] + nb[n][0], b = v[1] + nb[n][1], c = v[2] + nb[n][2];
            if (g_.inside(a, b, c) && g_.data[g_.index(a, b, c)] && !isSurface(a, b, c))
                out.push_back(Vec3i(a, b, c));
        }
    }

    /* Whether key frame q lets v go when it exposes e[0..ne): every silhouette pixel of v's
    footprint keeps a cover, counting the exposed voxels' footprints, without touching the counts
    (adding them first and taking them back on refusal cost twice the adds of every refused
    carve). */
    bool allowed(size_t q, const Vec3i& v, const Vec3i* e, size_t ne,
                 std::vector<Vec4i>& rects) const
    {
        int x0, x1, y0, y1;
        double z;
        if (!proj_[q].footprint(v[0], v[1], v[2], x0, x1, y0, y1, z))
            return true;
        const Mat& s = *sil_[q];
        const Mat& c = count_[q];
        x0 = std::max(x0, 0);
        y0 = std::max(y0, 0);
        x1 = std::min(x1, s.cols - 1);
        y1 = std::min(y1, s.rows - 1);
        rects.clear();
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
                    for (size_t n = 0; n < ne; n++)
                    {
                        Vec4i r;
                        if (proj_[q].footprint(e[n][0], e[n][1], e[n][2], r[0], r[1], r[2], r[3],
                                               z))
                            rects.push_back(r);
                    }
                    rectsReady = true;
                }
                int cover = cr[x];
                for (const Vec4i& r : rects)
                    cover += x >= r[0] && x <= r[1] && y >= r[2] && y <= r[3];
                if (cover <= 1)
                    return false;
            }
        }
        return true;
    }

    // Key frame q's counts after carving v (sign 1) or back before it (-1): its exposed voxels
    // e[0..ne) join the surface, v leaves it.
    void apply(size_t q, const Vec3i& v, const Vec3i* e, size_t ne, int sign)
    {
        for (size_t n = 0; n < ne; n++)
            add(q, e[n][0], e[n][1], e[n][2], sign);
        add(q, v[0], v[1], v[2], -sign);
    }

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
    std::vector<Vec4i> rects_;  // tryCarve: scratch of allowed()
};

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
