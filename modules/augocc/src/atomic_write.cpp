// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// All-or-nothing outputs: write under a temporary name with every I/O call checked, make it
// durable, rename. See atomic_write.hpp for why the libraries' own writers are not trusted.

#include "precomp.hpp"

#include "atomic_write.hpp"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <zlib.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

namespace fs = std::filesystem;

namespace cv {
namespace augocc {

namespace {

// Below this much free space a write that failed without a reason failed for want of space.
const double kFullDiskBytes = 1 << 20;

String osReason(int err)
{
    char buf[256];
    // GNU strerror_r: thread-safe (writers run in parallel_for_), returns the message.
    return String(strerror_r(err, buf, sizeof(buf)));
}

[[noreturn]] void failWithErrno(const String& shown, const char* what, int err)
{
    CV_Error(Error::StsError, shown + ": " + what + ": " + osReason(err));
}

// `name` split as tmpNameFor names it: "clones.yml.gz" -> ("clones", ".yml.gz").
void splitName(const String& name, String& stem, String& ext)
{
    const String gz = ".gz";
    fs::path p(name);
    if (name.size() > gz.size() && name.compare(name.size() - gz.size(), gz.size(), gz) == 0)
        p = fs::path(name.substr(0, name.size() - gz.size()));
    else
        p = fs::path(name);
    stem = p.stem().string();
    ext = name.substr(stem.size());
}

bool endsWith(const String& s, const String& tail)
{
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// fsync of an open file or folder; EINVAL: this file system has nothing to sync.
void syncPath(const fs::path& p, bool directory, const String& shown)
{
    const int fd = ::open(p.c_str(), (directory ? O_RDONLY | O_DIRECTORY : O_RDONLY) | O_CLOEXEC);
    if (fd < 0)
        failWithErrno(shown, "cannot open to sync", errno);
    if (::fsync(fd) != 0 && errno != EINVAL)
    {
        const int err = errno;
        ::close(fd);
        failWithErrno(shown, "cannot sync to disk", err);
    }
    ::close(fd);
}

void syncTree(const fs::path& p, const String& shown)
{
    std::error_code ec;
    if (fs::is_directory(fs::symlink_status(p, ec)))
    {
        fs::directory_iterator it(p, ec), end;
        for (; !ec && it != end; it.increment(ec))
            syncTree(it->path(), shown);
        if (ec)
            CV_Error(Error::StsError, shown + ": cannot list " + p.string() + ": " + ec.message());
        syncPath(p, true, shown);
    }
    else if (fs::is_regular_file(fs::symlink_status(p, ec)))
        syncPath(p, false, shown);
}

bool processAlive(long pid)
{
    if (pid <= 0 || pid != (long)(pid_t)pid)
        return false;
    if (::kill((pid_t)pid, 0) != 0 && errno != EPERM)
        return false;
    // A killed writer whose parent died too stays a zombie where PID 1 does not reap orphans
    // (containers, micro-VMs): kill(pid, 0) still succeeds. Its state in /proc says it is dead.
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string line;
    if (!std::getline(stat, line))
        return true;  // no /proc: trust kill()
    // "PID (COMM) STATE ...": COMM may hold spaces and parentheses, so the last ')' ends it.
    const size_t close = line.rfind(')');
    if (close == std::string::npos || close + 2 >= line.size())
        return true;
    const char state = line[close + 2];
    return state != 'Z' && state != 'X' && state != 'x';
}

// The folder that holds `path` ("." for a bare name).
fs::path parentOf(const String& path)
{
    const fs::path parent = fs::path(path).parent_path();
    return parent.empty() ? fs::path(".") : parent;
}

String gzipCompress(const String& text, const String& shown)
{
    z_stream z;
    std::memset(&z, 0, sizeof(z));
    // windowBits 15 + 16: a gzip stream, as gzopen() (and so FileStorage) reads and writes it.
    if (deflateInit2(&z, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) !=
        Z_OK)
        CV_Error(Error::StsNoMem, shown + ": cannot start gzip compression");
    String out(deflateBound(&z, (uLong)text.size()), '\0');
    z.next_in = (Bytef*)text.data();
    z.avail_in = (uInt)text.size();
    z.next_out = (Bytef*)&out[0];
    z.avail_out = (uInt)out.size();
    const int rc = deflate(&z, Z_FINISH);
    out.resize(z.total_out);
    deflateEnd(&z);
    if (rc != Z_STREAM_END)
        CV_Error(Error::StsInternal, shown + cv::format(": gzip compression failed (%d)", rc));
    return out;
}

uint32_t readBig32(const unsigned char* p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

uint32_t readLittle32(const unsigned char* p)
{
    return (uint32_t)p[3] << 24 | (uint32_t)p[2] << 16 | (uint32_t)p[1] << 8 | p[0];
}

// Whether the top-level structure of an MP4/MOV (ISO BMFF boxes, a moov among them) or AVI
// (RIFF chunks) file spans the file exactly; true for other containers. A writer stopped by a
// full disk leaves them short or without their index, and FFmpeg would complain on stderr
// ("moov atom not found") if it were asked to open them.
bool containerComplete(const String& file)
{
    String ext = fs::path(file).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return (char)std::tolower(c); });
    const bool bmff = ext == ".mp4" || ext == ".mov" || ext == ".m4v";
    if (!bmff && ext != ".avi")
        return true;
    FILE* f = std::fopen(file.c_str(), "rb");
    if (!f)
        return false;
    std::error_code ec;
    const uint64_t size = fs::file_size(file, ec);
    uint64_t pos = 0;
    bool moov = !bmff, ok = !ec;
    while (ok && pos < size)
    {
        unsigned char h[16];
        ok = fseeko(f, (off_t)pos, SEEK_SET) == 0 && std::fread(h, 1, 8, f) == 8;
        if (!ok)
            break;
        uint64_t len;
        if (bmff)
        {
            len = readBig32(h);
            if (len == 1)  // 64-bit size follows the type
            {
                ok = std::fread(h + 8, 1, 8, f) == 8;
                len = (uint64_t)readBig32(h + 8) << 32 | readBig32(h + 12);
            }
            else if (len == 0)  // the last box, to the end of the file
                len = size - pos;
            moov = moov || std::memcmp(h + 4, "moov", 4) == 0;
            ok = ok && len >= 8;
        }
        else
        {
            ok = std::memcmp(h, "RIFF", 4) == 0;
            len = 8 + (uint64_t)readLittle32(h + 4);
            len += len & 1;  // chunks are padded to an even size
        }
        pos += len;
    }
    std::fclose(f);
    return ok && moov && pos == size;
}

} // namespace

namespace detail {

String tmpNameFor(const String& path)
{
    static std::atomic<int> counter(0);
    String stem, ext;
    splitName(fs::path(path).filename().string(), stem, ext);
    const String name = "." + stem + cv::format(".tmp%ld-%d", (long)::getpid(), ++counter) + ext;
    return (fs::path(path).parent_path() / name).string();
}

void sweepStaleTemporaries(const String& path)
{
    String stem, ext;
    splitName(fs::path(path).filename().string(), stem, ext);
    const String head = "." + stem + ".tmp";
    std::error_code ec;
    fs::directory_iterator it(parentOf(path), ec), end;
    std::vector<fs::path> stale;
    for (; !ec && it != end; it.increment(ec))
    {
        const String name = it->path().filename().string();
        if (name.size() <= head.size() + ext.size() || name.compare(0, head.size(), head) != 0 ||
            !endsWith(name, ext))
            continue;
        // N or N-K between head and ext: N the writer's PID (K its counter) or, before the
        // PID was in the name, a tick count.
        const String mid = name.substr(head.size(), name.size() - head.size() - ext.size());
        const size_t dash = mid.find('-');
        const String n = mid.substr(0, dash), k = dash == String::npos ? "" : mid.substr(dash + 1);
        auto digits = [](const String& s) {
            return !s.empty() && s.size() < 12 &&
                   std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
        };
        if (!digits(n) || (dash != String::npos && !digits(k)))
            continue;
        if (dash != String::npos && processAlive(std::stol(n)))
            continue;  // another writer, still at work
        stale.push_back(it->path());
    }
    for (const fs::path& p : stale)
    {
        CV_LOG_INFO(NULL, "augocc: removing " << p.string() << ", left by an interrupted run");
        fs::remove_all(p, ec);
    }
}

void commitTemporary(const String& tmp, const String& path)
{
    syncTree(tmp, path);
    std::error_code ec;
    if (fs::is_directory(path) && fs::is_directory(tmp))
        fs::remove_all(path, ec);
    fs::rename(tmp, path, ec);
    if (ec)
        CV_Error(Error::StsError, path + ": cannot rename from " + tmp + ": " + ec.message());
    syncPath(parentOf(path), true, path);
}

void createDirectories(const String& dir, const String& shown)
{
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec)
        CV_Error(Error::StsError, (shown.empty() ? dir : shown) + ": cannot create folder: " +
                 ec.message());
}

void writeFileBytes(const String& file, const void* data, size_t size, const String& shown)
{
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0)
        failWithErrno(shown, "cannot create", errno);
    const char* p = static_cast<const char*>(data);
    size_t left = size;
    while (left > 0)
    {
        const ssize_t n = ::write(fd, p, std::min(left, (size_t)1 << 30));
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
        {
            const int err = n < 0 ? errno : EIO;
            ::close(fd);
            failWithErrno(shown, "cannot write", err);
        }
        p += n;
        left -= (size_t)n;
    }
    if (::fsync(fd) != 0 && errno != EINVAL)
    {
        const int err = errno;
        ::close(fd);
        failWithErrno(shown, "cannot sync to disk", err);
    }
    if (::close(fd) != 0)
        failWithErrno(shown, "cannot write", errno);
}

void writeImageFile(const String& file, InputArray img, const String& shown)
{
    String ext = fs::path(file).extension().string();
    if (ext.empty())
        ext = fs::path(shown).extension().string();
    std::vector<uchar> buf;
    if (!cv::imencode(ext, img, buf) || buf.empty())
        CV_Error(Error::StsError, shown + ": cannot encode the image as " + ext);
    writeFileBytes(file, buf.data(), buf.size(), shown);
}

String storageText(const std::function<void(FileStorage&)>& fill, const String& shown, int flags)
{
    const String name = fs::path(shown).filename().string();
    const bool gz = endsWith(name, ".gz");
    // With MEMORY, the name only picks the format; FileStorage compresses files, not memory.
    FileStorage storage(gz ? name.substr(0, name.size() - 3) : name,
                        FileStorage::WRITE | FileStorage::MEMORY | flags);
    if (!storage.isOpened())
        CV_Error(Error::StsError, shown + ": cannot start a FileStorage in memory");
    fill(storage);
    // A `fill` that released the storage would leave nothing to write: never a valid file.
    if (!storage.isOpened())
        CV_Error(Error::StsInternal, shown + ": the FileStorage was released before it was "
                 "written");
    return storage.releaseAndGetString();
}

void writeStorageFile(const String& file, const std::function<void(FileStorage&)>& fill,
                      const String& shown, int flags)
{
    const String text = storageText(fill, shown, flags);
    if (endsWith(fs::path(shown).filename().string(), ".gz"))
    {
        const String packed = gzipCompress(text, shown);
        writeFileBytes(file, packed.data(), packed.size(), shown);
    }
    else
        writeFileBytes(file, text.data(), text.size(), shown);
}

void writeStorageAtomically(const String& path, const std::function<void(FileStorage&)>& fill,
                            int flags)
{
    writeAtomically(path, [&](const String& tmp) { writeStorageFile(tmp, fill, path, flags); });
}

void checkCreatable(const String& file, const String& shown)
{
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0)
        failWithErrno(shown, "cannot create", errno);
    ::close(fd);
}

void checkVideoFile(const String& file, int frames, const String& shown)
{
    // The encoder's failures reach no caller (VideoWriter::write returns void): judge the file.
    auto fail = [&](const String& what) {
        struct statvfs st;
        const bool full = ::statvfs(parentOf(file).c_str(), &st) == 0 &&
                          (double)st.f_bavail * (double)st.f_frsize < kFullDiskBytes;
        CV_Error(Error::StsError, shown + ": " + what + (full ? ": " + osReason(ENOSPC)
                                                              : String(" (the video encoder "
                                                                       "gave no reason)")));
    };
    std::error_code ec;
    const uintmax_t size = fs::file_size(file, ec);
    if (ec || size == 0)
        fail("the video writer wrote nothing");
    if (!containerComplete(file))
        fail("the video written is incomplete");
    VideoCapture cap(file, CAP_FFMPEG);
    if (!cap.isOpened())
        fail("the video written cannot be read back");
    int n = (int)cap.get(CAP_PROP_FRAME_COUNT);
    if (n != frames)
    {
        // Some containers (mkv) give no exact count: count the frames themselves.
        n = 0;
        while (cap.grab())
            n++;
    }
    if (n != frames)
        fail(cv::format("the video written holds %d of its %d frames", n, frames));
}

} // namespace detail

void writeAtomically(const String& path, const std::function<void(const String& tmpPath)>& writer)
{
    detail::sweepStaleTemporaries(path);
    const String tmp = detail::tmpNameFor(path);
    auto removeTmp = [&tmp]() {
        std::error_code ec;
        fs::remove_all(tmp, ec);
    };
    try
    {
        writer(tmp);
        std::error_code ec;
        if (!fs::exists(tmp, ec))
            CV_Error(Error::StsError, path + ": nothing was written");
        detail::commitTemporary(tmp, path);
    }
    catch (const fs::filesystem_error& e)
    {
        removeTmp();
        CV_Error(Error::StsError, path + ": cannot write: " + e.code().message());
    }
    catch (...)
    {
        removeTmp();
        throw;
    }
}

void writeFileAtomically(const String& path, const String& bytes, bool executable)
{
    writeAtomically(path, [&](const String& tmp) {
        detail::writeFileBytes(tmp, bytes.data(), bytes.size(), path);
        if (executable && ::chmod(tmp.c_str(), 0755) != 0)
            failWithErrno(path, "cannot be made executable", errno);
    });
}

void writeImageAtomically(const String& path, InputArray image)
{
    // The temporary keeps the extension (tmpNameFor), which picks the format.
    writeAtomically(path, [&](const String& tmp) { detail::writeImageFile(tmp, image, path); });
}

} // namespace augocc
} // namespace cv
