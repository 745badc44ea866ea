// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Issue 18's scenes, unlike the SceneSynthesizer's: objects made of convex vertical prisms (any
// convex footprint, slanted bottom and top planes: boxes, cylinders, shed and gable roofs, a
// building on sloping ground, an arch's legs and lintel), standing on the ground y = 0 (y up).
// Silhouettes are exact: each prism's is the convex hull of its projected corners, sampled at
// pixel centres; an object's visible silhouette is what is left after the objects nearer the
// camera (by centre depth, painter's order) are drawn.

#ifndef OPENCV_AUGOCC_TEST_CLONE_TOWN_HPP
#define OPENCV_AUGOCC_TEST_CLONE_TOWN_HPP

#include "test_clone_scenes.hpp"

namespace opencv_test {

//! y from `bottom` to `top` over a convex footprint (x, z); planes y = p[0] + p[1] x + p[2] z.
struct Prism
{
    std::vector<Point2d> footprint;  //!< convex, either orientation
    Vec3d bottom, top;

    std::vector<Vec3d> corners() const;
    bool contains(const Vec3d& X) const;
};

struct TownObject
{
    String name;
    std::vector<Prism> parts;
    Vec3d centre() const;
    bool contains(const Vec3d& X) const;
};

struct TownScene
{
    Reconstruction rec;
    std::vector<TownObject> objects;
    ObjectMasks whole;     // every frame, the whole silhouette
    ObjectMasks keyMasks;  // visible silhouettes in the key frames
    std::vector<int> keyFrames;
    bool isKey(int frame) const
    {
        return std::find(keyFrames.begin(), keyFrames.end(), frame) != keyFrames.end();
    }
    const TownObject& object(const String& name) const;
};

//! A vertical cylinder (a 48-gon prism) of radius r from y0 to y1 about (x, z).
Prism cylinderPrism(double x, double z, double r, double y0, double y1);
//! An axis-aligned box.
Prism boxPrism(const Vec3d& lo, const Vec3d& hi);

/** @brief Cameras orbiting `target` at elevation 25 degrees (the frames' azimuths spread over
`orbitDeg`), key frames every `keyStep` frames (numKeys of them), silhouettes and points.
Perspective cameras stand `dist` away; both models draw `ppu` pixels per unit at the target. */
TownScene makeTownScene(CameraModel model, const std::vector<TownObject>& objects,
                        const Vec3d& target, double dist, double ppu, double orbitDeg,
                        int keyStep, int numKeys, Size size);

//! The mushroom tower (stem r 0.55 under a cap r 1.5), a box in front hiding its foot in the last
//! key frames, and a cylinder silo.
std::vector<TownObject> mushroomObjects();
//! A gable-roofed house, a building on sloping ground, an arch, and a shed roof block that the
//! frames cut at the image border.
std::vector<TownObject> townObjects();

struct TownFigures
{
    double nonKeyMean = 0, nonKeyMin = 1, recallMin = 1, keyMin = 1;
    int worstFrame = -1, recallFrame = -1;
};
//! Non-key frames against the whole silhouette; key frames against the visible one outside the
//! nearer objects' (as measure() of test_clone_scenes.hpp).
TownFigures measureTown(const CloneSet& clones, const TownScene& s, const String& object);

} // namespace opencv_test

#endif
