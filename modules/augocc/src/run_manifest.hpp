// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Resume of `augocc run` (runPipeline): one small manifest per stage beside its output, saying
// what the output was made from (input signatures, the options that matter) and what the output
// itself was when complete. A re-run reuses an output whose manifest matches.

#ifndef OPENCV_AUGOCC_RUN_MANIFEST_HPP
#define OPENCV_AUGOCC_RUN_MANIFEST_HPP

#include <utility>
#include <vector>
#include <opencv2/core.hpp>

namespace cv {
namespace augocc {
namespace detail {

/** @brief What a file or folder is now, as a short string: for a file its size, modification
time (ns) and, for files of at most kHashedBytes, the CRC-32 of its content; for a folder the
same of every file under it (sorted, names relative to it) folded into one line; "missing" when
absent. A printf pattern (`frames/%04d.png`) stands for its folder. Equal signatures: unchanged
for every purpose of the resume (a file rewritten within the same nanosecond with the same size
but other content of more than kHashedBytes is the one change it misses). */
String pathSignature(const String& path);

/** @brief pathSignature() without the content hash: size and modification time of the file, or
of every file under the folder. Cheap enough to take again when a stage ends (inputReplaced). */
String quickSignature(const String& path);

//! Files up to this size are hashed by content in pathSignature() (masks, scene, calibration).
const size_t kHashedBytes = (size_t)4 << 20;

//! What one stage of a run was made from.
struct StageManifest
{
    String stage;  //!< "track", "sfm", "clone", "matte", "composite"
    std::vector<std::pair<String, String> > inputs;   //!< name -> pathSignature()
    std::vector<std::pair<String, String> > options;  //!< name -> value as text
    //! path -> quickSignature() when the stage started reading it (not written to the file).
    std::vector<std::pair<String, String> > watched;

    void input(const String& name, const String& path)
    {
        inputs.push_back({name, pathSignature(path)});
        watched.push_back({path, quickSignature(path)});
    }
    /** An input whose signatures are already known (the frames: signed once per run, before the
    first stage reads them); `path` empty: not a file (nothing to watch). */
    void signedInput(const String& name, const String& signature, const String& path = String(),
                     const String& quick = String())
    {
        inputs.push_back({name, signature});
        if (!path.empty())
            watched.push_back({path, quick});
    }
    void option(const String& name, const String& value) { options.push_back({name, value}); }
    void option(const String& name, double value);
};

/** @brief The manifest of a stage whose output is `output`: `output` minus its extensions plus
`.manifest.yml` (tracks.yml -> tracks.manifest.yml, mattes -> mattes.manifest.yml). */
String manifestPath(const String& output);

/** @brief true when `output` exists, its manifest exists and records `m` exactly, and `output`'s
signature is the one recorded when it was complete. A manifest that cannot be read is no
match (the stage runs again). */
bool manifestMatches(const StageManifest& m, const String& output);

//! Removes `output`'s manifest (before the stage rewrites `output`).
void removeManifest(const String& output);

/** @brief Writes `output`'s manifest atomically: `m` and `output`'s signature now (call after it).
First checks that no input of `m` was replaced or rewritten while the stage read it (its
quickSignature() differs from the stage's start): then the output, made from a mixture of two
versions, is removed and StsError names the input ("changed while the run read it"). */
void writeManifest(const StageManifest& m, const String& output);

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
