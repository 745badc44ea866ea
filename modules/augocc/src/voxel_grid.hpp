// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_VOXEL_GRID_HPP
#define OPENCV_AUGOCC_VOXEL_GRID_HPP

#include <cstdint>
#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"
#include "opencv2/augocc/mesh.hpp"

/*
The one voxel grid of the module (DESIGN.md): dense, one byte per voxel, a rigid box pose, carving
against silhouettes, surface extraction and footprint splatting (matte + depth). File encoding:
clone/clone_codec.hpp.

Voxel (i, j, k) is the cube of edge h centred at origin + Rbox * (h * (i + 0.5, j + 0.5, k + 0.5)).
Its FOOTPRINT in an image is the set of pixel centres inside the bounding rectangle of its
projected cube (half extents from the projection's Jacobian at the centre; exact for the
scaled-orthographic model), plus the pixel its centre rounds to. Carving and rendering use this
one rule (VoxelProjector::footprint), which is what makes the key-frame mattes exact.
*/

namespace cv {
namespace augocc {
namespace detail {

//! Voxel coordinates (i, j, k) packed in 32 bits, 10 bits each (grids up to 1024 per axis).
inline uint32_t packVoxel(int i, int j, int k)
{
    return (uint32_t)i | ((uint32_t)j << 10) | ((uint32_t)k << 20);
}
inline void unpackVoxel(uint32_t p, int& i, int& j, int& k)
{
    i = (int)(p & 1023u);
    j = (int)((p >> 10) & 1023u);
    k = (int)(p >> 20);
}
//! Largest grid dimension that packVoxel() holds.
const int kMaxGridDim = 1023;

//! Surface voxels: packed coordinates and a 6-bit mask of exposed faces (-x,+x,-y,+y,-z,+z).
struct SurfaceVoxels
{
    std::vector<uint32_t> ijk;
    std::vector<uchar> faces;
    size_t size() const { return ijk.size(); }
};

/** @brief A camera seen from voxel coordinates: homogeneous pixel (u w, v w, w) = M (i,j,k)^T + c
and camera depth z = Z . (i,j,k) + z0 of a voxel centre. */
struct VoxelProjector
{
    Matx33d M;
    Vec3d c;
    Vec3d Z;
    double z0 = 0;
    bool affine = true;
    Size size;
    Vec3d viewDir;    //!< affine: viewing direction in voxel coordinates
    Vec3d camVoxel;   //!< perspective: camera centre in voxel coordinates
    double ruAffine = 0, rvAffine = 0;  //!< affine: footprint half extents in pixels
    Vec3i dims = Vec3i::all(kMaxGridDim + 1);  //!< the grid's size (renderers' bounds)

    /** @brief Pixel (rounded) of the centre of voxel (i, j, k). Returns false when the voxel is
    not in front of the camera. */
    inline bool centrePixel(double i, double j, double k, Point& px) const
    {
        const double u = M(0, 0) * i + (M(0, 1) * j + M(0, 2) * k + c[0]);
        const double v = M(1, 0) * i + (M(1, 1) * j + M(1, 2) * k + c[1]);
        const double w = affine ? 1.0 : M(2, 0) * i + (M(2, 1) * j + M(2, 2) * k + c[2]);
        if (!(w > 1e-12))
            return false;
        px = Point(cvRound(u / w), cvRound(v / w));
        return true;
    }

    /** @brief Footprint of voxel (i, j, k): pixel rectangle [x0, x1] x [y0, y1] (inclusive, not
    clipped) and the centre's depth. Returns false when the voxel is not in front of the camera. */
    inline bool footprint(double i, double j, double k, int& x0, int& x1, int& y0, int& y1,
                          double& depth) const
    {
        // Row part first (M(:,1) j + M(:,2) k + c, then + M(:,0) i): the row walk and the
        // renderer evaluate it once per voxel row and get the same bits.
        const double hx = M(0, 0) * i + (M(0, 1) * j + M(0, 2) * k + c[0]);
        const double hy = M(1, 0) * i + (M(1, 1) * j + M(1, 2) * k + c[1]);
        double u, v, ru, rv;
        if (affine)
        {
            u = hx;
            v = hy;
            ru = ruAffine;
            rv = rvAffine;
        }
        else
        {
            const double w = M(2, 0) * i + M(2, 1) * j + M(2, 2) * k + c[2];
            if (!(w > 1e-12))
                return false;
            const double iw = 1.0 / w;
            u = hx * iw;
            v = hy * iw;
            ru = 0.5 * iw * (std::abs(M(0, 0) - u * M(2, 0)) + std::abs(M(0, 1) - u * M(2, 1)) +
                             std::abs(M(0, 2) - u * M(2, 2)));
            rv = 0.5 * iw * (std::abs(M(1, 0) - v * M(2, 0)) + std::abs(M(1, 1) - v * M(2, 1)) +
                             std::abs(M(1, 2) - v * M(2, 2)));
        }
        // Beyond 2^30 px the pixel arithmetic below would overflow int (readers reject such
        // cameras; this keeps any other caller defined): the voxel is off every image.
        if (!(std::abs(u) + ru < 1073741824.0 && std::abs(v) + rv < 1073741824.0))
            return false;
        const int pu = cvRound(u), pv = cvRound(v);
        x0 = std::min(cvCeil(u - ru), pu);
        x1 = std::max(cvFloor(u + ru), pu);
        y0 = std::min(cvCeil(v - rv), pv);
        y1 = std::max(cvFloor(v + rv), pv);
        depth = Z[0] * i + (Z[1] * j + Z[2] * k + z0);
        return true;
    }
};

/** @brief Pixels every footprint of the projector's grid lies in (the footprints of its corner
voxels, and a pixel), within the image; the whole image when a corner is behind the camera. */
CV_EXPORTS Rect projectedBounds(const VoxelProjector& proj);

/** @brief One key frame prepared for carving: keep-label image (silhouette or unknown = 255,
outside = 0) padded by `pad` keep pixels, and the chessboard distance of every pixel to the
nearest pixel of the other label. */
struct CarveView
{
    VoxelProjector proj;
    Mat keep;   //!< CV_8U, padded
    Mat dist;   //!< CV_8S, padded: +D kept, -D outside, D the chessboard distance to the other
                //!< label saturated at 127 (only over `roi`; +1 elsewhere, which forces exact tests)
    int pad = 0;
    Rect roi;   //!< padded coordinates: every voxel footprint of the grid lies in it
    /** Affine views: voxel rows all move the same way in the image, (sx, sy) the signs of the
    step. `dist` then counts only the other label's pixels in the quadrant ahead
    {(x' - x) sx >= 0, (y' - y) sy >= 0}, which the rest of the row can reach (quadrantDistance). */
    bool quadrant = false;
    int sx = 1, sy = 1;
    int rad = 0;  //!< quadrant views: footprints lie within rad pixels of the centre's pixel
    /** Quadrant views: per pixel of `roi` two bytes, what the row walk needs from one cache line.
    Byte 0 (signed): outside pixels -D, D the quadrant distance to a kept pixel; kept pixels the
    quadrant distance of q = (x - sx rad, y - sy rad) to an outside pixel (0 when q is outside).
    Byte 1: which of the 8 neighbours are outside (bit order row by row, the centre left out). */
    Mat walk;
};

/** @brief Chessboard distance of every pixel of `roi` to the nearest pixel of the other label in
the quadrant {(x' - x) sx >= 0, (y' - y) sy >= 0} of `roi`, saturated at 127 and signed (+ where
`label` is nonzero): one raster pass from the quadrant's far corner. Exact: a chessboard path
between two pixels of a rectangle can stay in it and move monotonically. */
CV_EXPORTS void quadrantDistance(const Mat& label, const Rect& roi, int sx, int sy, Mat& dist);

//! Chessboard distance of every pixel to the nearest pixel of the other label (CV_16U).
CV_EXPORTS Mat labelDistance(const Mat& label);

class CV_EXPORTS VoxelGrid
{
public:
    Vec3i dims = Vec3i(0, 0, 0);
    Matx33d Rbox = Matx33d::eye();  //!< box axes (columns) in world coordinates
    Vec3d origin = Vec3d(0, 0, 0);  //!< world position of the grid's corner
    double h = 1;                   //!< voxel edge, world units
    std::vector<uchar> data;        //!< 1 = inside, x fastest then y then z

    //! Allocates the grid with every voxel set to `value`.
    void create(const Vec3i& dims, const Matx33d& Rbox, const Vec3d& origin, double h,
                uchar value);
    bool empty() const { return data.empty(); }
    int64 total() const { return (int64)dims[0] * dims[1] * dims[2]; }
    size_t index(int i, int j, int k) const
    {
        return ((size_t)k * dims[1] + j) * dims[0] + i;
    }
    bool inside(int i, int j, int k) const
    {
        return i >= 0 && j >= 0 && k >= 0 && i < dims[0] && j < dims[1] && k < dims[2];
    }
    //! World position of voxel centre (i, j, k) (fractional indices allowed).
    Vec3d centre(double i, double j, double k) const
    {
        return origin + Rbox * Vec3d(h * (i + 0.5), h * (j + 0.5), h * (k + 0.5));
    }
    //! Continuous voxel coordinates of a world point (voxel centres at integers).
    Vec3d toVoxel(const Vec3d& Xw) const
    {
        const Vec3d b = Rbox.t() * (Xw - origin);
        return Vec3d(b[0] / h - 0.5, b[1] / h - 0.5, b[2] / h - 0.5);
    }
    //! Number of voxels inside.
    int64 count() const;

    //! The camera in voxel coordinates.
    VoxelProjector projector(const Camera& camera, Size imageSize) const;
    //! Prepares a key frame: `keep` is CV_8U, nonzero = silhouette or unknown.
    CarveView carveView(const Camera& camera, const Mat& keep) const;
    /** @brief Carves every voxel whose footprint holds a pixel labelled outside in any view
    (pixels off the image are unknown). Parallel over z slices; deterministic. */
    void carve(const std::vector<CarveView>& views);
    //! True when voxel (i, j, k)'s footprint lies in the keep region of `view`.
    bool footprintKept(const CarveView& view, int i, int j, int k) const;

    //! Voxels inside with at least one face on a voxel outside (or on the grid's border).
    SurfaceVoxels surface() const;

    //! Exposed faces of the surface as a mesh in world coordinates (two triangles per face).
    Mesh surfaceMesh(const SurfaceVoxels& s) const;
    //! Pixel rectangle (clipped to the image) holding every voxel footprint of the grid.
    Rect imageBounds(const VoxelProjector& proj) const { return projectedBounds(proj); }
    //! Cubes of a list of voxels as a mesh in world coordinates.
    Mesh cubesMesh(const std::vector<uint32_t>& voxels) const;
};

/** @brief Splats voxel footprints: zmin (CV_32F, +inf initialised by the caller) takes the nearest
centre depth; zmax (optional) the farthest. The buffers cover the image from `offset` on. With
`frontOnly`, voxels with no exposed face turned to the camera are skipped (they cannot change the
footprint union). `faces` may be null (every voxel drawn). */
CV_EXPORTS void splatVoxels(const VoxelProjector& proj, const uint32_t* ijk, const uchar* faces,
                            size_t n, bool frontOnly, Mat& zmin, Mat* zmax,
                            Point offset = Point());

//! A list of voxels to render (not owned).
struct VoxelList
{
    const uint32_t* ijk = nullptr;
    const uchar* faces = nullptr;
    size_t n = 0;
    bool frontOnly = false;
};

/** @brief Nearest depth of the footprints of several voxel lists (CV_32F, +inf elsewhere), in
parallel over voxel chunks; identical for any thread count. This is the matte/depth renderer. */
CV_EXPORTS void renderDepth(const VoxelGrid& grid, const VoxelProjector& proj,
                            const std::vector<VoxelList>& lists, Mat& zmin);

/** @brief The matte renderDepth() implies (CV_8U, 255 where its depth is finite, 0 elsewhere),
without the depth: a byte per pixel instead of a float. */
CV_EXPORTS void renderCoverage(const VoxelGrid& grid, const VoxelProjector& proj,
                               const std::vector<VoxelList>& lists, Mat& cover);

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
