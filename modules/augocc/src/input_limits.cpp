// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

#include "precomp.hpp"
#include "input_limits.hpp"

#include <algorithm>
#include <cstring>
#include <strings.h>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <opencv2/imgcodecs.hpp>
#include <zlib.h>

namespace fs = std::filesystem;

namespace cv {
namespace augocc {
namespace detail {

namespace {

bool isPrint(char c)
{
    return (unsigned char)c >= ' ' && c != 127;
}

bool isDigit(char c)
{
    return c >= '0' && c <= '9';
}

bool isAlnum(char c)
{
    return isDigit(c) || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
}

// YAML as OpenCV 4.6's YAMLParser reads it (persistence_yml.cpp): block collections open at a
// column ('-' items, 'key:' maps) and close on a line indented less; flow collections nest with
// brackets; a quoted string starts only where a value starts; '#' is a comment only where the
// parser skips spaces (between tokens, not inside a plain scalar); map keys (block or flow) are
// read up to ':' whatever they hold. Counting more levels than the parser would is harmless (the
// limit is far above augocc's own files); counting fewer is what this code must not do.
int yamlDepth(const char* s, size_t n, int stopAt)
{
    struct Level
    {
        int col;
        bool map;
    };
    std::vector<Level> block;
    std::vector<bool> flow;  // true: a flow map
    enum State { VALUE, KEY, AFTER };
    State state = VALUE;
    int maxDepth = 0;
    size_t i = 0, lineStart = 0;
    bool atLineStart = true;
    auto note = [&]() {
        maxDepth = std::max(maxDepth, (int)(block.size() + flow.size()));
        return maxDepth > stopAt;
    };
    auto openBlock = [&](int col, bool map) {
        if (block.empty() || block.back().col < col)
            block.push_back({col, map});
        return note();
    };
    auto skipToEol = [&]() {
        while (i < n && s[i] != '\n' && s[i] != '\r')
            i++;
    };
    while (i < n)
    {
        const char c = s[i];
        if (c == '\n' || c == '\r')
        {
            i++;
            lineStart = i;
            atLineStart = true;
            continue;
        }
        if (c == ' ' || !isPrint(c))
        {
            // Spaces; tabs and control characters are parse errors for OpenCV: skipped here
            // (every step of the scan moves on).
            i++;
            continue;
        }
        const int col = (int)(i - lineStart);
        if (atLineStart)
        {
            atLineStart = false;
            if (c == '#')
            {
                skipToEol();
                continue;
            }
            if (flow.empty())
            {
                if (col == 0 && (c == '%' || (n - i >= 3 && (!std::strncmp(s + i, "---", 3) ||
                                                             !std::strncmp(s + i, "...", 3)))))
                {
                    // A directive or a document marker: the rest of the line after "---" may
                    // hold a value (a tag); skip the marker only.
                    if (c == '%')
                        skipToEol();
                    else
                        i += 3;
                    state = VALUE;
                    continue;
                }
                while (!block.empty() && block.back().col > col)
                    block.pop_back();
                state = (!block.empty() && block.back().col == col && block.back().map) ? KEY
                                                                                       : VALUE;
            }
        }
        if (state == KEY)
        {
            // parseKey: everything printable up to ':'.
            while (i < n && isPrint(s[i]) && s[i] != ':')
                i++;
            if (i < n && s[i] == ':')
                i++;
            state = VALUE;
            continue;
        }
        if (state == AFTER)
        {
            if (c == '#')
            {
                skipToEol();
                continue;
            }
            if (!flow.empty() && c == ',')
            {
                i++;
                state = flow.back() ? KEY : VALUE;
                continue;
            }
            if (!flow.empty() && (c == ']' || c == '}'))
            {
                flow.pop_back();
                i++;
                continue;
            }
            // Anything else after a value is a parse error for OpenCV; read on as a value (it
            // can only count more).
            state = VALUE;
        }
        // VALUE
        if (c == '#')
        {
            skipToEol();
            continue;
        }
        if (c == '!')
        {
            while (i < n && isPrint(s[i]) && s[i] != ' ')
                i++;
            continue;
        }
        if (c == '\'' || c == '"')
        {
            i++;
            while (i < n && s[i] != '\n' && s[i] != '\r')
            {
                if (c == '"' && s[i] == '\\')
                {
                    i += 2;
                    continue;
                }
                if (s[i] == c)
                {
                    if (c == '\'' && i + 1 < n && s[i + 1] == '\'')
                    {
                        i += 2;
                        continue;
                    }
                    i++;
                    break;
                }
                i++;
            }
            state = AFTER;
            continue;
        }
        const char d = i + 1 < n ? s[i + 1] : '\0';
        if (isDigit(c) || ((c == '-' || c == '+') && (isDigit(d) || d == '.')) ||
            (c == '.' && isAlnum(d)))
        {
            i++;
            while (i < n && (isAlnum(s[i]) || s[i] == '.' || s[i] == '+' || s[i] == '-'))
                i++;
            state = AFTER;
            continue;
        }
        if (c == '[' || c == '{')
        {
            flow.push_back(c == '{');
            i++;
            if (note())
                return maxDepth;
            state = c == '{' ? KEY : VALUE;
            continue;
        }
        if (!flow.empty())
        {
            if (c == ']' || c == '}')
            {
                flow.pop_back();
                i++;
                state = AFTER;
                continue;
            }
            if (c == ',')
            {
                i++;
                state = flow.back() ? KEY : VALUE;
                continue;
            }
            // A plain scalar in a flow: up to , ] } or the end of the line.
            while (i < n && isPrint(s[i]) && s[i] != ',' && s[i] != ']' && s[i] != '}')
                i++;
            state = AFTER;
            continue;
        }
        if (c == '-')
        {
            if (openBlock(col, false))
                return maxDepth;
            i++;
            state = VALUE;
            continue;
        }
        // A plain scalar in block context: a map key when a ':' ends it on this line.
        size_t j = i;
        while (j < n && isPrint(s[j]) && s[j] != ':')
            j++;
        if (j < n && s[j] == ':')
        {
            if (openBlock(col, true))
                return maxDepth;
            i = j + 1;
            state = VALUE;
            continue;
        }
        i = j;
        state = AFTER;
    }
    return maxDepth;
}

// JSON as OpenCV's JSONParser reads it: strings are double-quoted with backslash escapes,
// collections nest with brackets.
int jsonDepth(const char* s, size_t n, int stopAt)
{
    int depth = 0, maxDepth = 0;
    for (size_t i = 0; i < n; i++)
    {
        const char c = s[i];
        if (c == '"')
        {
            for (i++; i < n && s[i] != '"'; i++)
                if (s[i] == '\\')
                    i++;
        }
        else if (c == '[' || c == '{')
        {
            maxDepth = std::max(maxDepth, ++depth);
            if (maxDepth > stopAt)
                return maxDepth;
        }
        else if ((c == ']' || c == '}') && depth > 0)
            depth--;
    }
    return maxDepth;
}

// The '>' that ends the markup whose text starts at `i`, past quoted values; `n` when the text
// ends first (then *openQuote, when given, is the quote still open, or 0).
size_t xmlMarkupEnd(const char* s, size_t n, size_t i, char* openQuote)
{
    char quote = 0;
    for (; i < n; i++)
    {
        if (quote)
        {
            if (s[i] == quote)
                quote = 0;
        }
        else if (s[i] == '"' || s[i] == '\'')
            quote = s[i];
        else if (s[i] == '>')
            return i;
    }
    if (openQuote)
        *openQuote = quote;
    return n;
}

// XML: elements nest by tags; comments, processing instructions and declarations do not.
int xmlDepth(const char* s, size_t n, int stopAt)
{
    int depth = 0, maxDepth = 0;
    auto skipPast = [&](size_t& i, const char* end) {
        const size_t len = std::strlen(end);
        while (i + len <= n && std::strncmp(s + i, end, len) != 0)
            i++;
        i = std::min(n, i + len);
    };
    size_t i = 0;
    while (i < n)
    {
        if (s[i] != '<')
        {
            i++;
            continue;
        }
        if (i + 4 <= n && !std::strncmp(s + i, "<!--", 4))
            skipPast(i, "-->");
        else if (i + 1 < n && s[i + 1] == '?')
            skipPast(i, "?>");
        else if (i + 1 < n && s[i + 1] == '!')
            skipPast(i, ">");
        else if (i + 1 < n && s[i + 1] == '/')
        {
            depth = std::max(0, depth - 1);
            skipPast(i, ">");
        }
        else
        {
            maxDepth = std::max(maxDepth, ++depth);
            if (maxDepth > stopAt)
                return maxDepth;
            // To the tag's end, past quoted attribute values; "/>" closes it at once.
            i = xmlMarkupEnd(s, n, i + 1, nullptr);
            if (i < n && s[i - 1] == '/')
                depth--;
            i++;
        }
    }
    return maxDepth;
}

uint32_t be32(const uchar* p)
{
    return ((uint32_t)p[0] << 24) | ((uint32_t)p[1] << 16) | ((uint32_t)p[2] << 8) | p[3];
}

void checkDims(int64 w, int64 h, const String& where)
{
    if (w > kMaxImageSide || h > kMaxImageSide || w * h > kMaxImagePixels)
        CV_Error(Error::StsOutOfRange, where + cv::format(": the image header declares %lld x "
                 "%lld pixels; augocc reads images of at most %d pixels a side and %lld pixels",
                 (long long)w, (long long)h, kMaxImageSide, (long long)kMaxImagePixels));
}

bool isPng(const uchar* data, size_t size)
{
    static const uchar sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    return size >= 8 && std::memcmp(data, sig, 8) == 0;
}

String readWhole(const String& path, int64 limit, const String& what)
{
    std::ifstream in(path, std::ios::binary);
    if (!in)
        CV_Error(Error::StsObjectNotFound, path + ": cannot open " + what);
    std::string s;
    char buf[1 << 16];
    while (in)
    {
        in.read(buf, sizeof(buf));
        s.append(buf, (size_t)in.gcount());
        if ((int64)s.size() > limit)
            CV_Error(Error::StsOutOfRange, path + cv::format(": %s larger than augocc's limit "
                     "of %lld bytes", what.c_str(), (long long)limit));
    }
    return s;
}

// OpenCV 4.6's YAML parser never returned on a top level that is an indented sequence of maps
// followed by a line starting with '-' ("  - name: x" then "-x--": fuzz_scene,
// fuzz/open_findings). Every augocc file is a map at the top, written with its keys at the start
// of the line, as FileStorage writes it: the first line of content (after the "%YAML" directive,
// "---", comments and blank lines) must start with a key, not with a space or '-'.
void checkYamlTopLevel(const std::string& text, const String& path, const String& what)
{
    size_t i = 0;
    while (i < text.size() && (text[i] == ' ' || text[i] == '\t' || text[i] == '\r' ||
                               text[i] == '\n'))
        i++;
    if (i < text.size() && (text[i] == '{' || text[i] == '<'))
        return;  // JSON or XML
    size_t start = 0;
    int line = 0;
    // The first content line of every document (the file's start, after '---' or '...') must
    // start a key: after a "..." document end, a line starting with '-' hung the parser too
    // (fuzz_calibration).
    bool expectKey = true;
    while (start < text.size())
    {
        size_t end = text.find('\n', start);
        if (end == std::string::npos)
            end = text.size();
        line++;
        std::string l = text.substr(start, end - start);
        if (!l.empty() && l.back() == '\r')
            l.pop_back();
        start = end + 1;
        const size_t first = l.find_first_not_of(" \t");
        if (first == std::string::npos || l[0] == '%' || l[first] == '#')
            continue;
        if (l.compare(0, 3, "---") == 0 || l.compare(0, 3, "...") == 0)
        {
            // A document marker with text glued to it ("---Y:1", "...-x") hung the parser as
            // well when a sequence followed (fuzz_scene, fuzz_calibration).
            const size_t rest = l.find_first_not_of(" \t", 3);
            if (rest != std::string::npos && (l[rest] != '#' || rest == 3))
                CV_Error(Error::StsParseError, path + cv::format(": %s: line %d ('%s'): text "
                         "after the '%s' document marker", what.c_str(), line,
                         l.substr(0, 40).c_str(), l.substr(0, 3).c_str()));
            expectKey = true;
            continue;
        }
        if (expectKey && (first != 0 || l[0] == '-'))
            CV_Error(Error::StsParseError, path + cv::format(": %s: line %d ('%s') must start "
                     "a top-level key at the start of the line (the file's top level is a map)",
                     what.c_str(), line, l.substr(0, 40).c_str()));
        expectKey = false;
    }
}

// OpenCV 4.6's XML parser reads past the end of the text when the file ends inside markup
// ("<?xml version=": SEGV, found by fuzz_tracks). Every comment, processing instruction,
// declaration and tag must be closed, quoted attribute values included, before the end.
void checkXmlMarkup(const std::string& text, const String& path, const String& what)
{
    const size_t n = text.size();
    auto lineOf = [&](size_t at) {
        return 1 + (int)std::count(text.begin(), text.begin() + (std::ptrdiff_t)at, '\n');
    };
    auto fail = [&](size_t at, const char* problem) {
        CV_Error(Error::StsParseError, path + cv::format(": %s: line %d ('%s'): %s before the "
                 "end of the file (cut short?)", what.c_str(), lineOf(at),
                 text.substr(at, 40).c_str(), problem));
    };
    for (size_t i = text.find('<'); i != std::string::npos; i = text.find('<', i))
    {
        const size_t start = i;
        if (!text.compare(i, 4, "<!--"))
        {
            const size_t end = text.find("-->", i + 4);
            if (end == std::string::npos)
                fail(start, "a comment not closed by '-->'");
            i = end + 3;
            continue;
        }
        if (!text.compare(i, 2, "<?"))
        {
            const size_t end = text.find("?>", i + 2);
            if (end == std::string::npos)
                fail(start, "a processing instruction not closed by '?>'");
        }
        char quote = 0;
        i = xmlMarkupEnd(text.data(), n, i + 1, &quote);
        if (i >= n)
            fail(start, quote ? "a quoted value not closed" : "markup not closed by '>'");
        i++;
    }
}

} // namespace

int storageNestingDepth(const char* data, size_t size, int stopAt)
{
    size_t i = 0;
    while (i < size && (data[i] == ' ' || data[i] == '\t' || data[i] == '\r' || data[i] == '\n'))
        i++;
    if (i < size && data[i] == '{')
        return jsonDepth(data + i, size - i, stopAt);
    if (i < size && data[i] == '<')
        return xmlDepth(data + i, size - i, stopAt);
    return yamlDepth(data, size, stopAt);
}

void checkStorageFile(const String& path, const String& what)
{
    // gzopen reads plain files as they are (FileStorage opens "*.gz" the same way).
    gzFile gz = gzopen(path.c_str(), "rb");
    if (!gz)
        CV_Error(Error::StsObjectNotFound, path + ": cannot open " + what);
    std::string text;
    char buf[1 << 16];
    int got = 0;
    while ((got = gzread(gz, buf, sizeof(buf))) > 0)
    {
        text.append(buf, (size_t)got);
        if ((int64)text.size() > kMaxStorageBytes)
        {
            gzclose(gz);
            CV_Error(Error::StsOutOfRange, path + cv::format(": %s holds more than augocc's "
                     "limit of %lld bytes (uncompressed)", what.c_str(),
                     (long long)kMaxStorageBytes));
        }
    }
    const bool readError = got < 0;
    gzclose(gz);
    if (readError)
        CV_Error(Error::StsParseError, path + ": cannot read " + what + " (corrupt compressed "
                 "data)");
    // OpenCV 4.6's parsers read lines as C strings: a NUL byte made FileStorage::open loop for
    // ever (found by fuzz_tracks). No FileStorage text holds one.
    if (std::memchr(text.data(), 0, text.size()))
        CV_Error(Error::StsParseError, path + cv::format(": %s holds a NUL byte at offset %zu "
                 "(binary data, not a YAML, JSON or XML text)", what.c_str(),
                 (size_t)((const char*)std::memchr(text.data(), 0, text.size()) - text.data())));
    checkYamlTopLevel(text, path, what);
    const size_t first = text.find_first_not_of(" \t\r\n");
    if (first != std::string::npos && text[first] == '<')
        checkXmlMarkup(text, path, what);
    const int depth = storageNestingDepth(text.data(), text.size(), kMaxStorageDepth);
    if (depth > kMaxStorageDepth)
        CV_Error(Error::StsOutOfRange, path + cv::format(": %s nests deeper than augocc's limit "
                 "of %d levels", what.c_str(), kMaxStorageDepth));
}

void checkDuplicateKeys(const FileNode& node, const String& where)
{
    if (node.isMap())
    {
        std::set<String> seen;
        for (FileNodeIterator it = node.begin(); it != node.end(); ++it)
        {
            const FileNode child = *it;
            const String name = child.name();
            if (!seen.insert(name).second)
                CV_Error(Error::StsParseError, where + ": key '" + name + "' appears twice in "
                         "the same map");
            if (child.isMap() || child.isSeq())
                checkDuplicateKeys(child, where);
        }
    }
    else if (node.isSeq())
    {
        for (FileNodeIterator it = node.begin(); it != node.end(); ++it)
        {
            const FileNode child = *it;
            if (child.isMap() || child.isSeq())
                checkDuplicateKeys(child, where);
        }
    }
}

Mat readStorageMat(const FileNode& node, const String& where, const String& key)
{
    const String k = where + ": key '" + key + "'";
    if (node.empty() || node.isNone())
        CV_Error(Error::StsParseError, k + " is missing");
    if (!node.isMap())
        CV_Error(Error::StsParseError, k + " is not a matrix");
    const FileNode rows = node["rows"], cols = node["cols"], dt = node["dt"], data = node["data"];
    if (!node["sizes"].empty())
        CV_Error(Error::StsParseError, k + " must be a 2-D matrix (rows, cols), not n-D");
    if (!rows.isInt() || !cols.isInt() || !dt.isString())
        CV_Error(Error::StsParseError, k + " is not a matrix (needs integer rows and cols, a "
                 "dt string and data)");
    const int r = (int)rows, c = (int)cols;
    if (r < 0 || c < 0)
        CV_Error(Error::StsParseError, k + cv::format(" declares %d x %d: negative", r, c));
    const String dts = (String)dt;
    size_t q = 0;
    while (q < dts.size() && isDigit(dts[q]))
        q++;
    const int cn = q ? std::atoi(dts.substr(0, q).c_str()) : 1;
    if (q > 3 || cn < 1 || cn > CV_CN_MAX || dts.size() != q + 1 ||
        !std::strchr("ucwsifdh", dts[q]))
        CV_Error(Error::StsParseError, k + ": dt '" + dts + "' is not one OpenCV element type "
                 "(e.g. d, f, 2f, i, u)");
    const int64 declared = (int64)r * c * cn;
    if (declared == 0 && (data.empty() || data.isNone()))
        ;  // an empty matrix: FileStorage may write no data
    else if (data.isSeq())
    {
        if ((int64)data.size() != declared)
            CV_Error(Error::StsParseError, k + cv::format(" declares %d x %d x %d values but its "
                     "data holds %zu", r, c, cn, data.size()));
    }
    else
        CV_Error(Error::StsParseError, k + ": its data must be a sequence of numbers");
    Mat m;
    try
    {
        node >> m;
    }
    catch (const cv::Exception& e)
    {
        CV_Error(Error::StsParseError, k + " is not a valid matrix (" + e.err + ")");
    }
    if ((int64)m.total() * m.channels() != declared)
        CV_Error(Error::StsParseError, k + " is not a valid matrix");
    return m;
}

void checkImageHeader(const uchar* data, size_t size, const String& where)
{
    if (isPng(data, size))
    {
        if (size >= 24 && std::memcmp(data + 12, "IHDR", 4) == 0)
            checkDims(be32(data + 16), be32(data + 20), where);
        return;
    }
    if (size >= 4 && data[0] == 0xFF && data[1] == 0xD8)
    {
        // JPEG: walk the segments to the first start-of-frame (SOF0..SOF15 but DHT, JPG, DAC).
        size_t p = 2;
        while (p + 9 < size)
        {
            if (data[p] != 0xFF)
                return;
            const uchar m = data[p + 1];
            if (m == 0xFF)
            {
                p++;
                continue;
            }
            if (m == 0xD8 || m == 0x01 || (m >= 0xD0 && m <= 0xD7))
            {
                p += 2;
                continue;
            }
            const size_t len = ((size_t)data[p + 2] << 8) | data[p + 3];
            if (m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC)
            {
                const int64 h = ((int64)data[p + 5] << 8) | data[p + 6];
                const int64 w = ((int64)data[p + 7] << 8) | data[p + 8];
                checkDims(w, h, where);
                return;
            }
            if (len < 2)
                return;
            p += 2 + len;
        }
    }
}

Mat readImageChecked(const String& path, int flags, bool requirePng)
{
    const String bytes = readWhole(path, kMaxImagePixels * 8 + (1 << 20), "image file");
    const uchar* p = (const uchar*)bytes.data();
    if (requirePng && !isPng(p, bytes.size()))
        CV_Error(Error::StsParseError, path + ": cannot read image: not a PNG file");
    const std::vector<uchar> v(p, p + bytes.size());
    const Mat m = decodeImageChecked(v, flags, path);
    if (m.empty())
        CV_Error(Error::StsParseError, path + ": cannot read image (corrupt or not an image)");
    return m;
}

Mat decodeImageChecked(const std::vector<uchar>& bytes, int flags, const String& where)
{
    if (bytes.empty())
        return Mat();
    checkImageHeader(bytes.data(), bytes.size(), where);
    try
    {
        return cv::imdecode(bytes, flags);
    }
    catch (const cv::Exception& e)
    {
        CV_Error(Error::StsParseError, where + ": cannot decode image: " + e.err);
    }
}

namespace {

// PLY (http://paulbourke.net/dataformats/ply/): checks the header and that the body holds the
// declared elements exactly, so that Assimp's PLY loader never runs off the end of the data.
struct PlyProperty
{
    int size = 0;       // bytes of a scalar (binary)
    bool list = false;
    int countSize = 0;  // bytes of the list count (binary)
    bool countSigned = false;
    bool indexSigned = false;
    bool isIndex = false;
    bool isFloat = false;
    bool isCoordinate = false;  // vertex x, y or z
    String name;
};

struct PlyElement
{
    String name;
    int64 count = 0;
    std::vector<PlyProperty> props;
};

int plyTypeSize(const String& t)
{
    if (t == "char" || t == "uchar" || t == "int8" || t == "uint8")
        return 1;
    if (t == "short" || t == "ushort" || t == "int16" || t == "uint16")
        return 2;
    if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" ||
        t == "float32")
        return 4;
    if (t == "double" || t == "float64")
        return 8;
    return 0;
}

void checkPly(const char* data, size_t size, const String& where)
{
    const size_t headerLimit = std::min(size, (size_t)1 << 16);
    const char* endTag = nullptr;
    for (size_t i = 0; i + 10 <= headerLimit; i++)
        if (!std::strncmp(data + i, "end_header", 10) && (i == 0 || data[i - 1] == '\n') &&
            (i + 10 == size || data[i + 10] == '\n' || data[i + 10] == '\r'))
        {
            endTag = data + i;
            break;
        }
    if (!endTag)
        CV_Error(Error::StsParseError, where + ": PLY header has no 'end_header' line in its "
                 "first 64 KiB (file cut short?)");
    if (size < 4 || std::strncmp(data, "ply", 3) != 0 || (data[3] != '\n' && data[3] != '\r'))
        CV_Error(Error::StsParseError, where + ": PLY file does not start with a 'ply' line");
    const char* body = endTag + 10;
    while (body < data + size && *body != '\n')
        body++;
    if (body < data + size)
        body++;
    // The header is text of printable lines: a form feed inside "element face 3\fproperty ..."
    // split the line for Assimp but not for this check, which then disagreed on the body's layout
    // (fuzz_mesh: SIGSEGV in Assimp's post-processing).
    for (const char* c = data; c < endTag; c++)
        if ((uchar)*c < 0x20 && *c != '\n' && *c != '\r' && *c != '\t')
            CV_Error(Error::StsParseError, where + cv::format(": PLY header holds the control "
                     "byte 0x%02x at offset %lld", (uchar)*c, (long long)(c - data)));
    std::istringstream header(std::string(data, endTag));
    String line, format;
    std::vector<PlyElement> elems;
    while (std::getline(header, line))
    {
        if (!line.empty() && line.back() == '\r')
            line.pop_back();
        std::istringstream ls(line);
        String word;
        ls >> word;
        if (word == "format")
        {
            String version;
            ls >> format >> version;
            if (version != "1.0")
                CV_Error(Error::StsParseError, where + ": PLY header: bad line '" + line +
                         "' (format ascii|binary_little_endian|binary_big_endian 1.0)");
        }
        else if (word == "ply" || word == "comment" || word == "obj_info")
            continue;
        else if (word == "element")
        {
            PlyElement e;
            long long count = -1;
            String extra;
            ls >> e.name >> count;
            if (!ls || count < 0 || (ls >> extra))
                CV_Error(Error::StsParseError, where + ": PLY header: bad line '" + line + "'");
            if (count > kMaxMeshElements)
                CV_Error(Error::StsOutOfRange, where + cv::format(": PLY header declares %lld %s "
                         "elements; augocc reads at most %lld", count, e.name.c_str(),
                         (long long)kMaxMeshElements));
            e.count = count;
            elems.push_back(e);
        }
        else if (word == "property")
        {
            if (elems.empty())
                CV_Error(Error::StsParseError, where + ": PLY header: a property before any "
                         "element");
            PlyProperty p;
            String t;
            ls >> t;
            if (t == "list")
            {
                String ct, it, name;
                ls >> ct >> it >> name;
                p.name = name;
                p.list = true;
                p.countSize = plyTypeSize(ct);
                p.countSigned = ct == "char" || ct == "short" || ct == "int" || ct == "int8" ||
                                ct == "int16" || ct == "int32";
                p.size = plyTypeSize(it);
                p.indexSigned = it == "char" || it == "short" || it == "int" || it == "int8" ||
                                it == "int16" || it == "int32";
                p.isIndex = elems.back().name == "face" &&
                            (name == "vertex_indices" || name == "vertex_index");
                if (p.isIndex && (it == "float" || it == "float32" || it == "double" ||
                                  it == "float64"))
                    CV_Error(Error::StsParseError, where + ": PLY header: vertex indices of "
                             "floating-point type in '" + line + "'");
                if (!p.countSize || !p.size || p.countSize > 4)
                    CV_Error(Error::StsParseError, where + ": PLY header: bad line '" + line + "'");
            }
            else
            {
                String name;
                ls >> name;
                p.name = name;
                p.size = plyTypeSize(t);
                if (!p.size)
                    CV_Error(Error::StsParseError, where + ": PLY header: unknown type in '" +
                             line + "'");
                p.isFloat = t == "float" || t == "float32" || t == "double" || t == "float64";
                p.isCoordinate = elems.back().name == "vertex" &&
                                 (name == "x" || name == "y" || name == "z");
            }
            elems.back().props.push_back(p);
        }
        else
        {
            // A line Assimp's loader reads differently from the element layout (a misspelt
            // "property") made it read past its buffers and leak (fuzz_mesh): the PLY header
            // has no other keywords.
            CV_Error(Error::StsParseError, where + ": PLY header: unknown line '" + line +
                     "' (ply, format, comment, obj_info, element, property, end_header)");
        }
    }
    if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
        CV_Error(Error::StsParseError, where + ": PLY header: format must be ascii, "
                 "binary_little_endian or binary_big_endian");
    int64 vertices = -1;
    for (const PlyElement& e : elems)
    {
        if (e.name == "vertex")
        {
            vertices = e.count;
            // Assimp's post-processing dereferenced the missing axis of a vertex without y.
            for (const char* axis : {"x", "y", "z"})
                if (std::none_of(e.props.begin(), e.props.end(), [&](const PlyProperty& q) {
                        return !q.list && q.name == axis; }))
                    CV_Error(Error::StsParseError, where + ": PLY vertex element has no '" +
                             String(axis) + "' property");
        }
        for (const PlyProperty& q : e.props)
            if (q.name.empty())
                CV_Error(Error::StsParseError, where + ": PLY header: a property of element '" +
                         e.name + "' has no name");
    }
    // A header without its vertex element made Assimp's PLY loader loop for ever (fuzz_mesh).
    if (vertices < 0)
        CV_Error(Error::StsParseError, where + ": PLY header declares no 'element vertex'");
    const char* p = body;
    const char* end = data + size;
    const bool ascii = format == "ascii";
    const bool little = format == "binary_little_endian";
    auto truncated = [&](const PlyElement& e, int64 k) {
        CV_Error(Error::StsParseError, where + cv::format(": PLY body ends inside %s %lld of "
                 "%lld (file cut short or counts wrong)", e.name.c_str(), (long long)k,
                 (long long)e.count));
    };
    auto badIndex = [&](double v, int64 k) {
        CV_Error(Error::StsParseError, where + cv::format(": PLY face %lld refers to vertex %.0f "
                 "of %lld", (long long)k, v, (long long)vertices));
    };
    // A face of no corner crashed Assimp's post-processing (fuzz_mesh); one or two corners are
    // points and lines, not surfaces.
    auto tooFewCorners = [&](double n, int64 k) {
        if (n < 3)
            CV_Error(Error::StsParseError, where + cv::format(": PLY face %lld has %.0f "
                     "corners (at least 3)", (long long)k, n));
    };
    auto badVertex = [&](double v, int64 k) {
        if (!(std::abs(v) <= kMaxSceneCoordinate))
            CV_Error(Error::StsOutOfRange, where + cv::format(": PLY vertex %lld has coordinate "
                     "%g: not finite or beyond augocc's limit of %g", (long long)k, v,
                     kMaxSceneCoordinate));
    };
    // An ASCII body is text: a NUL inside a line made the pre-check read the line as cut there
    // while Assimp read on, to a crash in its post-processing (fuzz_mesh).
    if (ascii)
        for (const char* c = body; c < end; c++)
            if ((uchar)*c < 0x20 && *c != '\n' && *c != '\r' && *c != '\t')
                CV_Error(Error::StsParseError, where + cv::format(": PLY ASCII body holds the "
                         "control byte 0x%02x at offset %lld", (uchar)*c,
                         (long long)(c - data)));
    for (const PlyElement& e : elems)
        for (int64 k = 0; k < e.count; k++)
        {
            if (ascii)
            {
                // One element a line, numbers as strtod reads them ("nan", "inf" included).
                while (p < end && (*p == '\n' || *p == '\r' || *p == ' ' || *p == '\t'))
                    p++;
                const char* eol = p;
                while (eol < end && *eol != '\n')
                    eol++;
                const std::string text(p, eol);
                const char* t = text.c_str();
                auto next = [&](double& v) {
                    char* stop = nullptr;
                    v = std::strtod(t, &stop);
                    if (stop == t)
                        return false;
                    t = stop;
                    return true;
                };
                for (const PlyProperty& pr : e.props)
                {
                    double v;
                    if (pr.list)
                    {
                        if (!next(v) || v < 0 || v > 1024 || v != std::floor(v))
                            truncated(e, k);
                        if (pr.isIndex)
                            tooFewCorners(v, k);
                        for (int q = 0; q < (int)v; q++)
                        {
                            double idx;
                            if (!next(idx))
                                truncated(e, k);
                            if (pr.isIndex && !(idx >= 0 && idx < vertices))
                                badIndex(idx, k);
                        }
                    }
                    else if (!next(v))
                        truncated(e, k);
                    else if (pr.isCoordinate)
                        badVertex(v, k);
                }
                p = eol;
            }
            else
            {
                for (const PlyProperty& pr : e.props)
                {
                    if (!pr.list)
                    {
                        if (end - p < pr.size)
                            truncated(e, k);
                        if (pr.isCoordinate && pr.isFloat)
                        {
                            uchar b[8];
                            for (int q = 0; q < pr.size; q++)
                                b[q] = (uchar)p[little ? q : pr.size - 1 - q];
                            double v;
                            if (pr.size == 4)
                            {
                                float f;
                                std::memcpy(&f, b, 4);
                                v = f;
                            }
                            else
                                std::memcpy(&v, b, 8);
                            badVertex(v, k);
                        }
                        p += pr.size;
                        continue;
                    }
                    if (end - p < pr.countSize)
                        truncated(e, k);
                    uint64_t cnt = 0;
                    for (int b = 0; b < pr.countSize; b++)
                    {
                        const uchar byte = (uchar)p[little ? pr.countSize - 1 - b : b];
                        cnt = (cnt << 8) | byte;
                    }
                    if (pr.countSigned && (cnt >> (8 * pr.countSize - 1)) & 1)
                        truncated(e, k);
                    p += pr.countSize;
                    if ((uint64_t)(end - p) < cnt * (uint64_t)pr.size)
                        truncated(e, k);
                    if (pr.isIndex)
                    {
                        tooFewCorners((double)cnt, k);
                        // Indices of any integer type (1, 2 or 4 bytes; signed or not).
                        for (uint64_t q = 0; q < cnt && pr.size <= 4; q++)
                        {
                            uint64_t u = 0;
                            for (int b = 0; b < pr.size; b++)
                                u = (u << 8) |
                                    (uchar)p[q * pr.size + (little ? pr.size - 1 - b : b)];
                            int64 idx = (int64)u;
                            if (pr.indexSigned && (u >> (8 * pr.size - 1)) & 1)
                                idx -= (int64)1 << (8 * pr.size);
                            if (idx < 0 || idx >= vertices)
                                badIndex((double)idx, k);
                        }
                    }
                    p += cnt * pr.size;
                }
            }
        }
}

} // namespace

void checkMeshBytes(const char* data, size_t size, const String& ext, const String& where)
{
    if ((int64)size > kMaxMeshBytes)
        CV_Error(Error::StsOutOfRange, where + cv::format(": mesh file of %zu bytes; augocc "
                 "reads at most %lld", size, (long long)kMaxMeshBytes));
    if (size == 0)
        CV_Error(Error::StsParseError, where + ": mesh file is empty");
    // Assimp takes a ".ply" file, or one starting with "ply" in any case, for PLY: a "pLy" with
    // no end_header made it loop for ever (fuzz_mesh). Such a file is checked as PLY here.
    if (ext == ".ply" || (size >= 3 && !strncasecmp(data, "ply", 3)))
    {
        checkPly(data, size, where);
        return;
    }
    if (ext == ".stl" && size >= 84 && std::strncmp(data, "solid", 5) != 0)
    {
        const uint32_t n = (uint32_t)(uchar)data[80] | ((uint32_t)(uchar)data[81] << 8) |
                           ((uint32_t)(uchar)data[82] << 16) | ((uint32_t)(uchar)data[83] << 24);
        if (n > kMaxMeshElements || 84 + 50 * (uint64_t)n != size)
            CV_Error(Error::StsParseError, where + cv::format(": binary STL declares %u "
                     "triangles but holds %zu bytes (84 + 50 per triangle expected)", n, size));
    }
}

void checkMeshFile(const String& path)
{
    std::error_code ec;
    const uintmax_t size = fs::file_size(path, ec);
    if (ec)
        CV_Error(Error::StsObjectNotFound, path + ": cannot read mesh file: " + ec.message());
    if ((int64)size > kMaxMeshBytes)
        CV_Error(Error::StsOutOfRange, path + cv::format(": mesh file of %llu bytes; augocc "
                 "reads at most %lld", (unsigned long long)size, (long long)kMaxMeshBytes));
    String ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    const String bytes = readWhole(path, kMaxMeshBytes, "mesh file");
    checkMeshBytes(bytes.data(), bytes.size(), ext, path);
}

void checkMagnitude(double v, double limit, const String& where)
{
    if (!(std::abs(v) <= limit))
        CV_Error(Error::StsOutOfRange, where + cv::format(": %g is not finite or beyond augocc's "
                 "limit of %g", v, limit));
}

} // namespace detail
} // namespace augocc
} // namespace cv
