// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_CLONE_BUILDER_HPP
#define OPENCV_AUGOCC_CLONE_BUILDER_HPP

#include <vector>
#include <opencv2/core.hpp>
#include "opencv2/augocc/camera.hpp"
#include "opencv2/augocc/io.hpp"

namespace cv {
namespace augocc {

//! @addtogroup augocc
//! @{

/** @brief The clones of the real objects (the paper's Section 6): per object a dense voxel grid
(the trimmed model) and a set of patch voxels per key frame.

This is what the compositor and `augocc matte` consume. (Outline fixed by the foundation; the
clone builder's work extends it.)
*/
class CV_EXPORTS CloneSet
{
public:
    virtual ~CloneSet();

    //! Names of the objects, sorted.
    virtual std::vector<String> objectNames() const = 0;

    /** @brief Renders one object's clone into a frame: matte and camera-space depth.
    @param object object name (one of objectNames()).
    @param frame frame index; selects the patch set that applies to it.
    @param camera the frame's camera.
    @param imageSize frame size.
    @param matte output CV_8U, 255 where the clone (with the frame's patches) projects, else 0.
    @param depth optional output CV_32F, camera-space z of the nearest clone surface, +inf elsewhere.
    */
    virtual void render(const String& object, int frame, const Camera& camera, Size imageSize,
                        OutputArray matte, OutputArray depth = noArray()) const = 0;

    //! Saves to a FileStorage file (`.yml.gz` recommended); atomic.
    virtual void save(const String& path) const = 0;
    //! Loads a file written by save(); throws naming the file on error.
    static Ptr<CloneSet> load(const String& path);
};

//! @}

} // namespace augocc
} // namespace cv

#endif
