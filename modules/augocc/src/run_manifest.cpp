// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "precomp.hpp"

#include "atomic_write.hpp"
#include "run_manifest.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <zlib.h>

namespace fs = std::filesystem;

namespace cv {
namespace augocc {
namespace detail {

namespace {

uLong crcOfFile(const fs::path& p, uLong crc)
{
    std::ifstream in(p, std::ios::binary);
    std::vector<char> buf(1 << 16);
    while (in)
    {
        in.read(buf.data(), (std::streamsize)buf.size());
        const std::streamsize n = in.gcount();
        if (n > 0)
            crc = crc32_z(crc, reinterpret_cast<const Bytef*>(buf.data()), (z_size_t)n);
    }
    return crc;
}

String fileSignature(const fs::path& p, bool hashed = true)
{
    std::error_code ec;
    const uintmax_t size = fs::file_size(p, ec);
    if (ec)
        return "unreadable";
    const auto mtime = fs::last_write_time(p, ec);
    if (ec)
        return "unreadable";
    const long long ns = (long long)std::chrono::duration_cast<std::chrono::nanoseconds>(
                             mtime.time_since_epoch()).count();
    String s = cv::format("%llu %lld", (unsigned long long)size, ns);
    if (hashed && size <= kHashedBytes)
        s += cv::format(" %08lx", (unsigned long)crcOfFile(p, crc32_z(0L, Z_NULL, 0)));
    return s;
}

} // namespace

static String signatureOf(const String& path, bool hashed)
{
    fs::path p(path);
    if (path.find('%') != String::npos)
        p = p.parent_path().empty() ? fs::path(".") : p.parent_path();
    std::error_code ec;
    if (!fs::exists(p, ec))
        return "missing";
    if (!fs::is_directory(p, ec))
        return fileSignature(p, hashed);
    std::vector<std::pair<String, String> > entries;
    for (fs::recursive_directory_iterator it(p, ec), end; !ec && it != end; it.increment(ec))
        if (it->is_regular_file(ec))
            entries.push_back({fs::relative(it->path(), p, ec).generic_string(),
                               fileSignature(it->path(), hashed)});
    if (ec)
        return "unreadable";
    std::sort(entries.begin(), entries.end());
    uLong crc = crc32_z(0L, Z_NULL, 0);
    for (const auto& e : entries)
    {
        const String line = e.first + " " + e.second + "\n";
        crc = crc32_z(crc, reinterpret_cast<const Bytef*>(line.data()), line.size());
    }
    return cv::format("folder %d %08lx", (int)entries.size(), (unsigned long)crc);
}

String pathSignature(const String& path)
{
    return signatureOf(path, true);
}

String quickSignature(const String& path)
{
    return signatureOf(path, false);
}

void StageManifest::option(const String& name, double value)
{
    option(name, cv::format("%.17g", value));
}

String manifestPath(const String& output)
{
    fs::path p(output);
    String stem = p.filename().string();
    const size_t dot = stem.find('.');
    if (dot != String::npos && dot > 0)
        stem = stem.substr(0, dot);
    return (p.parent_path() / (stem + ".manifest.yml")).string();
}

bool manifestMatches(const StageManifest& m, const String& output)
{
    const String path = manifestPath(output);
    std::error_code ec;
    if (!fs::exists(output, ec) || !fs::exists(path, ec))
        return false;
    try
    {
        FileStorage fsm(path, FileStorage::READ);
        if (!fsm.isOpened() || (String)fsm["stage"] != m.stage)
            return false;
        auto same = [&](const char* key, const std::vector<std::pair<String, String> >& want) {
            const FileNode n = fsm[key];
            if (!n.isSeq() || (size_t)n.size() != want.size())
                return false;
            for (size_t i = 0; i < want.size(); i++)
                if ((String)n[(int)i]["name"] != want[i].first ||
                    (String)n[(int)i]["value"] != want[i].second)
                    return false;
            return true;
        };
        return same("inputs", m.inputs) && same("options", m.options) &&
               (String)fsm["output"] == pathSignature(output);
    }
    catch (const cv::Exception&)
    {
        return false;
    }
}

void removeManifest(const String& output)
{
    std::error_code ec;
    fs::remove(manifestPath(output), ec);
}

void writeManifest(const StageManifest& m, const String& output)
{
    for (const auto& w : m.watched)
        if (quickSignature(w.first) != w.second)
        {
            std::error_code ec;
            fs::remove_all(output, ec);
            CV_Error(Error::StsError,
                     w.first + ": changed while the run read it (its files' sizes or times differ "
                     "from the start of the " + m.stage + " stage); " + output +
                     " was made from two versions and is not kept: run again");
        }
    const String sig = pathSignature(output);
    writeStorageAtomically(manifestPath(output), [&](FileStorage& fsm) {
        fsm << "stage" << m.stage;
        auto list = [&](const char* key, const std::vector<std::pair<String, String> >& v) {
            fsm << key << "[";
            for (const auto& e : v)
                fsm << "{" << "name" << e.first << "value" << e.second << "}";
            fsm << "]";
        };
        list("inputs", m.inputs);
        list("options", m.options);
        fsm << "output" << sig;
    });
}

} // namespace detail
} // namespace augocc
} // namespace cv
