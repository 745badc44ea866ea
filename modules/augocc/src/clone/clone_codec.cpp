// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "precomp.hpp"
#include "clone/clone_codec.hpp"

#include <cstring>

namespace cv {
namespace augocc {
namespace detail {

namespace {

const char kB64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

int b64Value(char c)
{
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
}

} // namespace

void putVarint(std::vector<uchar>& out, uint64_t v)
{
    while (v >= 0x80)
    {
        out.push_back((uchar)(v | 0x80));
        v >>= 7;
    }
    out.push_back((uchar)v);
}

uint64_t getVarint(const std::vector<uchar>& in, size_t& pos, const String& what)
{
    uint64_t v = 0;
    for (int shift = 0; shift < 64; shift += 7)
    {
        if (pos >= in.size())
            CV_Error(Error::StsParseError, what + ": truncated data");
        const uchar b = in[pos++];
        v |= (uint64_t)(b & 0x7f) << shift;
        if (!(b & 0x80))
            return v;
    }
    CV_Error(Error::StsParseError, what + ": corrupt data (varint too long)");
}

void writeBlob(FileStorage& fs, const String& key, const std::vector<uchar>& bytes)
{
    // Base64 without padding inside chunks: each chunk encodes a multiple of 3 bytes except the
    // last, which is padded with '='.
    const size_t bytesPerChunk = kChunkChars / 4 * 3;
    fs << key << "{" << "bytes" << (double)bytes.size() << "b64" << "[";
    std::string s;
    for (size_t off = 0; off < bytes.size() || off == 0; off += bytesPerChunk)
    {
        const size_t n = std::min(bytesPerChunk, bytes.size() - off);
        s.clear();
        for (size_t i = 0; i < n; i += 3)
        {
            const uint32_t a = bytes[off + i];
            const uint32_t b = i + 1 < n ? bytes[off + i + 1] : 0;
            const uint32_t c = i + 2 < n ? bytes[off + i + 2] : 0;
            const uint32_t w = (a << 16) | (b << 8) | c;
            s += kB64[(w >> 18) & 63];
            s += kB64[(w >> 12) & 63];
            s += i + 1 < n ? kB64[(w >> 6) & 63] : '=';
            s += i + 2 < n ? kB64[w & 63] : '=';
        }
        if (s.empty())
            break;
        fs << s;
    }
    fs << "]" << "}";
}

std::vector<uchar> readBlob(const FileNode& node, const String& what)
{
    if (node.empty() || !node.isMap())
        CV_Error(Error::StsParseError, what + ": missing");
    if (!node["bytes"].isInt() && !node["bytes"].isReal())
        CV_Error(Error::StsParseError, what + ": key 'bytes' must be a number");
    const double expected = (double)node["bytes"];
    FileNode seq = node["b64"];
    if (!seq.isSeq())
        CV_Error(Error::StsParseError, what + ": key 'b64' must be a sequence of strings");
    // The declared size is bounded by what the base64 text can hold (3 bytes per 4 characters)
    // before anything is reserved.
    double capacity = 0;
    for (FileNodeIterator it = seq.begin(); it != seq.end(); ++it)
    {
        if (!(*it).isString())
            CV_Error(Error::StsParseError, what + ": key 'b64' must be a sequence of strings");
        capacity += (double)((std::string)*it).size() * 3 / 4;
    }
    if (!(expected >= 0 && expected <= capacity && expected == std::floor(expected)))
        CV_Error(Error::StsParseError, what + cv::format(": key 'bytes' = %g but the data holds "
                 "at most %.0f bytes", expected, capacity));
    std::vector<uchar> out;
    out.reserve((size_t)expected);
    for (FileNodeIterator it = seq.begin(); it != seq.end(); ++it)
    {
        const std::string s = (std::string)*it;
        if (s.size() % 4 != 0)
            CV_Error(Error::StsParseError, what + ": corrupt base64 chunk");
        for (size_t i = 0; i < s.size(); i += 4)
        {
            int v[4];
            int pad = 0;
            for (int q = 0; q < 4; q++)
            {
                if (s[i + q] == '=')
                {
                    v[q] = 0;
                    pad++;
                    continue;
                }
                v[q] = b64Value(s[i + q]);
                if (v[q] < 0)
                    CV_Error(Error::StsParseError, what + ": corrupt base64 character");
            }
            const uint32_t w = (v[0] << 18) | (v[1] << 12) | (v[2] << 6) | v[3];
            out.push_back((uchar)(w >> 16));
            if (pad < 2) out.push_back((uchar)(w >> 8));
            if (pad < 1) out.push_back((uchar)w);
        }
    }
    if ((double)out.size() != expected)
        CV_Error(Error::StsParseError, what + cv::format(": %zu bytes decoded, %.0f expected",
                                                         out.size(), expected));
    return out;
}

std::vector<uchar> encodeGrid(const std::vector<uchar>& data, int nx, int rows)
{
    CV_Assert(data.size() == (size_t)nx * rows);
    std::vector<uchar> out;
    std::vector<int> prev, cur;
    for (int r = 0; r < rows; r++)
    {
        const uchar* p = &data[(size_t)r * nx];
        cur.clear();
        int v = 0, x = 0;
        while (x < nx)
        {
            const void* q = std::memchr(p + x, v ^ 1, (size_t)(nx - x));
            if (!q)
                break;
            x = (int)((const uchar*)q - p);
            cur.push_back(x);
            v ^= 1;
        }
        putVarint(out, cur.size());
        for (size_t b = 0; b < cur.size(); b++)
            putVarint(out, zigzag((int64_t)cur[b] - (b < prev.size() ? prev[b] : 0)));
        prev.swap(cur);
    }
    return out;
}

void decodeGrid(const std::vector<uchar>& bytes, int nx, int rows, std::vector<uchar>& data,
                const String& what)
{
    // Every row takes at least one byte (its run count): a grid the data cannot fill is corrupt,
    // found before the allocation.
    if (bytes.size() < (size_t)rows)
        CV_Error(Error::StsParseError, what + cv::format(": corrupt voxel data (%zu bytes for "
                 "%d rows)", bytes.size(), rows));
    data.assign((size_t)nx * rows, 0);
    std::vector<int> prev, cur;
    size_t pos = 0;
    for (int r = 0; r < rows; r++)
    {
        const uint64_t n = getVarint(bytes, pos, what);
        if (n > (uint64_t)nx)
            CV_Error(Error::StsParseError, what + ": corrupt voxel data (too many runs in a row)");
        cur.resize((size_t)n);
        int last = -1;
        for (size_t b = 0; b < n; b++)
        {
            const int64_t x = unzigzag(getVarint(bytes, pos, what)) + (b < prev.size() ? prev[b] : 0);
            if (x <= last || x > nx)
                CV_Error(Error::StsParseError, what + ": corrupt voxel data (bad run boundary)");
            cur[b] = (int)x;
            last = (int)x;
        }
        uchar* p = &data[(size_t)r * nx];
        for (size_t b = 0; b < n; b += 2)
        {
            const int e = b + 1 < n ? cur[b + 1] : nx;
            std::memset(p + cur[b], 1, (size_t)(e - cur[b]));
        }
        prev.swap(cur);
    }
    if (pos != bytes.size())
        CV_Error(Error::StsParseError, what + ": corrupt voxel data (trailing bytes)");
}

} // namespace detail
} // namespace augocc
} // namespace cv
