// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Partial clone sets (CloneBuilder::buildPart, mergeParts): the fingerprints of the inputs a part
// was built from, and the merge of parts into one set.

#include "precomp.hpp"
#include "clone/clone_parts.hpp"

#include <set>
#include <sstream>

namespace cv {
namespace augocc {
namespace detail {

namespace {

// 64-bit FNV-1a: not cryptographic, only to tell inputs apart that were not meant to differ.
struct Fnv
{
    uint64_t h = 1469598103934665603ULL;

    void bytes(const void* p, size_t n)
    {
        const uchar* b = (const uchar*)p;
        for (size_t i = 0; i < n; i++)
        {
            h ^= b[i];
            h *= 1099511628211ULL;
        }
    }
    void i64(int64 v) { bytes(&v, sizeof v); }
    void f64(double v) { bytes(&v, sizeof v); }
    void str(const String& s)
    {
        i64((int64)s.size());
        bytes(s.data(), s.size());
    }
    String hex() const { return cv::format("%016llx", (unsigned long long)h); }
};

// "name=value" with 17 significant digits (the value exactly).
void word(std::ostringstream& t, const char* name, double v)
{
    t << (t.tellp() > 0 ? " " : "") << name << "=" << cv::format("%.17g", v);
}

// How a part is named in messages: its file, else its number and objects.
String partName(const CloneSetImpl& part, size_t index)
{
    if (!part.part.source.empty())
        return part.part.source;
    String names;
    for (const auto& o : part.objects())
        names += (names.empty() ? "'" : ", '") + o.first + "'";
    return cv::format("part %d (objects %s)", (int)index + 1, names.c_str());
}

// The first word of `a` that `b` does not have ("name=value" lists of the same names).
String firstDifference(const String& a, const String& b)
{
    std::istringstream wa(a), wb(b);
    for (String x, y; wa >> x;)
    {
        if (!(wb >> y))
            return x;
        if (x != y)
            return x + " (here " + y + ")";
    }
    return String("the parameter list");
}

// StsBadArg unless `part` was built from the inputs `expected` describes.
void checkInputs(const CloneSetImpl& part, const String& name, const PartInfo& expected,
                 const String& against)
{
    const String who = "CloneBuilder::mergeParts: " + name;
    if (part.part.params != expected.params)
        CV_Error(Error::StsBadArg, who + ": built with other parameters than " + against + ": " +
                 firstDifference(part.part.params, expected.params) +
                 " (give every job the same clone options)");
    if (part.part.reconstruction != expected.reconstruction)
        CV_Error(Error::StsBadArg, who + ": built from another reconstruction than " + against);
    if (part.part.masks != expected.masks || part.part.allObjects != expected.allObjects)
        CV_Error(Error::StsBadArg, who + ": built from other key-frame masks than " + against);
    if (part.part.tracks != expected.tracks)
        CV_Error(Error::StsBadArg, who + (part.part.tracks == "none"
                                              ? String(": built without tracks, unlike ")
                                              : expected.tracks == "none"
                                                    ? String(": built with tracks, unlike ")
                                                    : String(": built from other tracks than ")) +
                 against);
}

} // namespace

String paramsText(const CloneBuilder::Params& p)
{
    std::ostringstream t;
    word(t, "voxelPixels", p.voxelPixels);
    word(t, "maxVoxels", (double)p.maxVoxels);
    word(t, "occlusionAware", p.occlusionAware);
    word(t, "box.minPoints", p.box.minPoints);
    word(t, "box.trimFraction", p.box.trimFraction);
    word(t, "box.orientation", p.box.orientation);
    for (int k = 0; k < 3; k++)
        word(t, cv::format("box.userRotation[%d]", k).c_str(), p.box.userRotation[k]);
    word(t, "box.maxEnlargeIterations", p.box.maxEnlargeIterations);
    word(t, "patches.raysPerPixel", p.patches.raysPerPixel);
    word(t, "patches.rule", p.patches.rule);
    word(t, "freeSpace.minViews", p.freeSpace.minViews);
    word(t, "freeSpace.edgeMargin", p.freeSpace.edgeMargin);
    word(t, "freeSpace.planarDeg", p.freeSpace.planarDeg);
    word(t, "freeSpace.marginVoxels", p.freeSpace.marginVoxels);
    word(t, "freeSpace.maxEdgeRatio", p.freeSpace.maxEdgeRatio);
    word(t, "freeSpace.maxReprojPx", p.freeSpace.maxReprojPx);
    word(t, "freeSpace.maxViews", p.freeSpace.maxViews);
    word(t, "unobserved.enabled", p.unobserved.enabled);
    word(t, "unobserved.views", p.unobserved.views);
    word(t, "unobserved.depthTolVoxels", p.unobserved.depthTolVoxels);
    word(t, "unobserved.keepNearSeen", p.unobserved.keepNearSeen);
    word(t, "unobserved.regrowFromUnseen", p.unobserved.regrowFromUnseen);
    word(t, "unobserved.maxTiltDeg", p.unobserved.maxTiltDeg);
    // The photo parameters do not change a part (refine() runs after the merge) but are kept so
    // that parts and merge agree on every option: one rule, no exceptions to remember.
    word(t, "photo.threshold", p.photo.threshold);
    word(t, "photo.minAgreement", p.photo.minAgreement);
    word(t, "photo.minViews", p.photo.minViews);
    word(t, "photo.rounds", p.photo.rounds);
    word(t, "photo.patchStep", p.photo.patchStep);
    word(t, "photo.maxViews", p.photo.maxViews);
    return t.str();
}

String fingerprintReconstruction(const Reconstruction& rec)
{
    Fnv f;
    f.i64(rec.model);
    f.i64(rec.imageSize.width);
    f.i64(rec.imageSize.height);
    f.i64((int64)rec.cameras.size());
    for (const Camera& c : rec.cameras)
    {
        f.i64(c.model);
        f.i64(c.frame);
        f.bytes(c.R.val, sizeof c.R.val);
        f.bytes(c.t.val, sizeof c.t.val);
        f.f64(c.s);
        f.bytes(c.K.val, sizeof c.K.val);
        f.f64(c.pp.x);
        f.f64(c.pp.y);
        f.i64((int64)c.distortion.size());
        for (double d : c.distortion)
            f.f64(d);
    }
    f.i64(rec.points.rows);
    f.i64(rec.points.cols);
    f.i64(rec.points.type());
    for (int r = 0; r < rec.points.rows; r++)
        f.bytes(rec.points.ptr(r), rec.points.cols * rec.points.elemSize());
    return f.hex();
}

String fingerprintMasks(const ObjectMasks& masks)
{
    Fnv f;
    f.i64((int64)masks.size());
    Mat bin;
    for (const auto& o : masks)
    {
        f.str(o.first);
        f.i64((int64)o.second.size());
        for (const auto& m : o.second)
        {
            f.i64(m.first);
            f.i64(m.second.cols);
            f.i64(m.second.rows);
            f.i64(m.second.type());
            if (m.second.empty())
                continue;
            bin = m.second > 127;  // what the builder reads of a mask
            for (int r = 0; r < bin.rows; r++)
                f.bytes(bin.ptr(r), bin.cols * bin.elemSize());
        }
    }
    return f.hex();
}

String fingerprintTracks(const Tracks* tracks)
{
    if (!tracks)
        return "none";
    Fnv f;
    f.i64(tracks->imageSize.width);
    f.i64(tracks->imageSize.height);
    f.i64(tracks->frames());
    f.i64(tracks->points());
    f.i64(tracks->observations());
    for (int i = 0; i < tracks->observations(); i++)
    {
        const Point2f uv = tracks->uv(i);
        const int fp[2] = {tracks->frameOf(i), tracks->pointOf(i)};
        f.bytes(fp, sizeof fp);
        f.bytes(&uv.x, sizeof uv.x);
        f.bytes(&uv.y, sizeof uv.y);
    }
    return f.hex();
}

Ptr<CloneSetImpl> combineParts(const std::vector<CloneSetImpl*>& parts, const PartInfo& expected)
{
    if (parts.empty())
        CV_Error(Error::StsBadArg, "CloneBuilder::mergeParts: no part");
    std::map<String, String> owner;  // object -> the part holding it
    for (size_t i = 0; i < parts.size(); i++)
    {
        CV_Assert(parts[i]);
        const CloneSetImpl& part = *parts[i];
        const String name = partName(part, i);
        if (!part.partial)
            CV_Error(Error::StsBadArg, "CloneBuilder::mergeParts: " + name + ": a complete clone "
                     "set, not a part made by CloneBuilder::buildPart (augocc clone --object)");
        checkInputs(part, name, expected, "the inputs given to the merge");
        for (const auto& o : part.objects())
        {
            auto it = owner.find(o.first);
            if (it != owner.end())
                CV_Error(Error::StsBadArg, "CloneBuilder::mergeParts: object '" + o.first +
                         "' is in two parts: " + it->second + " and " + name);
            if (!std::binary_search(expected.allObjects.begin(), expected.allObjects.end(),
                                    o.first))
                CV_Error(Error::StsBadArg, "CloneBuilder::mergeParts: " + name + ": object '" +
                         o.first + "' is not an object of the masks");
            owner[o.first] = name;
        }
    }
    for (const String& object : expected.allObjects)
        if (!owner.count(object))
            CV_Error(Error::StsBadArg, "CloneBuilder::mergeParts: object '" + object + "' of the "
                     "masks is in no part (build it with buildPart, augocc clone --object " +
                     object + ")");
    Ptr<CloneSetImpl> set = makePtr<CloneSetImpl>();
    set->patchRule = parts[0]->patchRule;
    for (CloneSetImpl* part : parts)
    {
        for (const String& name : part->objectNames())
        {
            set->insert(std::move(part->get(name)));
            part->erase(name);
        }
    }
    return set;
}

} // namespace detail
} // namespace augocc
} // namespace cv
