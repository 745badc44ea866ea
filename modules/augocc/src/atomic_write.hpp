// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#ifndef OPENCV_AUGOCC_ATOMIC_WRITE_HPP
#define OPENCV_AUGOCC_ATOMIC_WRITE_HPP

#include <functional>
#include <opencv2/core.hpp>

/*
Checked writes for writeAtomically's writers. The libraries augocc writes through do not report
I/O errors: FileStorage and imwrite write with stdio and ignore what fwrite/fclose return (a full
disk gives exit 0 and a truncated or empty file), and VideoWriter::write returns nothing. So the
bytes are made in memory (FileStorage::MEMORY, imencode) and written here, every write(), fsync()
and close() checked; videos are opened again after release() and their frames counted. Failures
are StsError naming the output the user asked for and the OS reason ("No space left on device",
"Read-only file system", "Permission denied").
*/

namespace cv {
namespace augocc {
namespace detail {

/** @brief The temporary sibling of `path` that writeAtomically writes: `.STEM.tmpPID-K.EXT`
(PID of this process, K a counter), EXT the extension FileStorage / imwrite choose the format
from (`.yml.gz` kept whole). */
String tmpNameFor(const String& path);

/** @brief Removes temporaries of `path` (`.STEM.tmpN.EXT`, `.STEM.tmpN-K.EXT`) that a killed
earlier run left beside it; those of a process still running (N its PID) stay. */
void sweepStaleTemporaries(const String& path);

/** @brief Makes `tmp` durable and renames it onto `path` (an existing folder `path` is replaced
by a folder `tmp`): fsync of every file and folder under `tmp`, rename, fsync of the folder. */
void commitTemporary(const String& tmp, const String& path);

/** @brief std::filesystem::create_directories, failing with StsError naming `shown` (default
`dir`) and the OS reason. */
void createDirectories(const String& dir, const String& shown = String());

/** @brief Writes `size` bytes to `file` (created or truncated), then fsync and close, each
checked; StsError naming `shown` and the OS reason on failure. */
void writeFileBytes(const String& file, const void* data, size_t size, const String& shown);

/** @brief Encodes `img` as `file`'s extension asks (imencode) and writes it with
writeFileBytes; StsError naming `shown`. */
void writeImageFile(const String& file, InputArray img, const String& shown);

/** @brief Writes a FileStorage file: `fill` writes its nodes into a storage in memory (format
from `shown`'s name: .yml, .json, .xml, + .gz compressed here), then writeFileBytes.
`flags` are added to WRITE | MEMORY (FileStorage::BASE64 for raw data in base64). */
void writeStorageFile(const String& file, const std::function<void(FileStorage&)>& fill,
                      const String& shown, int flags = 0);

//! The text writeStorageFile would write for `shown` (before compression).
String storageText(const std::function<void(FileStorage&)>& fill, const String& shown,
                   int flags = 0);

//! writeStorageFile under writeAtomically.
void writeStorageAtomically(const String& path, const std::function<void(FileStorage&)>& fill,
                            int flags = 0);

/** @brief Creates `file` empty, so that a folder a library cannot write into (read-only,
permissions, missing) is an error with the OS reason before the library fails without one. */
void checkCreatable(const String& file, const String& shown);

/** @brief After VideoWriter::release(): `file` exists, is not empty, opens and holds `frames`
frames; else StsError naming `shown` (with "No space left on device" when its folder is full). */
void checkVideoFile(const String& file, int frames, const String& shown);

} // namespace detail
} // namespace augocc
} // namespace cv

#endif
