// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_SCENE_SYNTHESIZER_HPP
#define OPENCV_AUGOCC_SCENE_SYNTHESIZER_HPP

#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"
#include "opencv2/augocc/io.hpp"
#include "opencv2/augocc/mesh.hpp"

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief Everything a synthesized data set holds: frames and their ground truth.

World frame: y is up, the ground is the plane y = 0, objects stand on it near the origin; scene
size (the diameter of the objects' footprint) about 10 world units.
*/
struct CV_EXPORTS SyntheticScene
{
    std::vector<Mat> frames;          //!< BGR CV_8UC3, one per frame
    Reconstruction groundTruth;       //!< true camera of every frame, and true 3D point per track
    Tracks tracks;                    //!< measured tracks: noise, partial and outlier tracks per Params
    Tracks cleanTracks;               //!< noise-free projections of the same tracks (NaN where unobserved)
    std::vector<uchar> outlierTrack;  //!< 1 where track p is a gross outlier (not a 3D point)
    std::vector<String> objectNames;  //!< real objects, front to back is not implied
    std::vector<Mesh> objectMeshes;   //!< true geometry of each real object, world coordinates
    ObjectMasks wholeMasks;           //!< per object, every frame: the whole silhouette (as if alone)
    ObjectMasks visibleMasks;         //!< per object, every frame: the silhouette others leave visible
    ObjectMasks keyFrameMasks;        //!< the user's input: visible silhouettes in the key frames
    std::vector<int> keyFrames;       //!< key frames (first and last included)
    std::vector<Mat> depth;           //!< CV_32F camera-space z per pixel (+inf where nothing)
    std::vector<Mat> labels;          //!< CV_8U: 0 ground/background, i + 1 where object i is seen
};

/** @brief Renders, headless through OSMesa, a textured static scene (a ground plane and several
real objects: a box building in front, an L-shaped block, a mushroom-shaped tower like the paper's
hotel) seen by a camera orbiting far away, with its ground truth. Deterministic for a seed.
*/
class CV_EXPORTS SceneSynthesizer : public Algorithm
{
public:
    struct CV_EXPORTS Params
    {
        Params();  // defaults in the comments; defined in src/ (GCC: nested NSDMI + default arg)
        int frames;                         //!< number of frames (default 60)
        Size imageSize;                     //!< frame size (default 640x480)
        CameraModel model;                  //!< camera model of the frames (default SCALED_ORTHOGRAPHIC)
        double distanceRatio;               //!< PERSPECTIVE: camera distance / scene size (default 10)
        double orbitDegrees;                //!< azimuth swept by the camera over the sequence (default 50)
        double elevationDegrees;            //!< mean elevation of the camera above the ground (default 25)
        int numTracks;                      //!< tracks (3D points on the objects and ground) (default 600)
        double noiseSigma;                  //!< Gaussian pixel noise of `tracks` (per axis) (default 0.5)
        double partialFraction;             //!< fraction of tracks that start/end mid-sequence (default 0)
        double outlierFraction;             //!< fraction of tracks that are gross outliers (default 0)
        int numKeyFrames;                   //!< key frames, evenly spaced, first and last included (default 6)
        uint64 seed;                        //!< random seed (textures, points, noise) (default 1)
    };

    static Ptr<SceneSynthesizer> create(const Params& params);
    //! Creates a synthesizer with default Params.
    static Ptr<SceneSynthesizer> create();
    virtual Params getParams() const = 0;
    virtual void setParams(const Params& params) = 0;

    //! Synthesizes the whole sequence with its ground truth.
    virtual void synthesize(SyntheticScene& scene) const = 0;

    /** @brief Renders one frame of the sequence with virtual objects inserted using the true
    geometry (the compositor's ground truth).
    @param frame frame index.
    @param virtualObjects meshes in world coordinates.
    @param image output BGR CV_8UC3.
    @param supersample render at this factor and average down (anti-aliased ground truth).
    */
    virtual void renderWithVirtual(int frame, const std::vector<Mesh>& virtualObjects,
                                   OutputArray image, int supersample = 1) const = 0;
};

//! @}

} // namespace augocc
} // namespace cv

#endif
