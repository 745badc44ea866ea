// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// Hostile and broken input (issue 17): every reader bounds what a file can make FileStorage,
// Assimp or an image decoder do, and absurd values are errors naming the file. Each test here
// crashed, hung, aborted or passed a wrong value before src/input_limits.* (the reproducers of
// ../shared/repro, made small).

#include "test_clone_scenes.hpp"

#include "clone/clone_set.hpp"
#include "input_limits.hpp"

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

namespace opencv_test {
namespace {

namespace fs = std::filesystem;
using cv::augocc::detail::storageNestingDepth;

std::string dataFile(const std::string& name)
{
    return std::string(AUGOCC_SOURCE_DIR) + "/test/data/" + name;
}

void writeText(const std::string& path, const std::string& text)
{
    std::ofstream(path, std::ios::binary) << text;
}

std::string readText(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The reader throws a cv::Exception whose message holds every needle.
template <typename F>
testing::AssertionResult throwsWith(F f, const std::vector<std::string>& needles)
{
    try
    {
        f();
    }
    catch (const cv::Exception& e)
    {
        for (const std::string& n : needles)
            if (e.err.find(n) == std::string::npos)
                return testing::AssertionFailure() << "message '" << e.err << "' lacks '" << n
                                                   << "'";
        if (e.code == Error::StsAssert || e.code == Error::StsInternal)
            return testing::AssertionFailure() << "an internal error: " << e.err;
        return testing::AssertionSuccess();
    }
    return testing::AssertionFailure() << "no exception";
}

int depthOf(const std::string& s)
{
    return storageNestingDepth(s.data(), s.size());
}

TEST(Augocc_InputLimits, nesting_depth_scan)
{
    // Depths as OpenCV's parsers recurse (root map = 1).
    EXPECT_EQ(depthOf("%YAML:1.0\n---\na: 1\nb: [1, 2]\n"), 2);
    EXPECT_EQ(depthOf("%YAML:1.0\n---\na:\n  b:\n    c: [[1]]\n"), 5);
    EXPECT_EQ(depthOf("%YAML:1.0\n---\nl:\n  - { x: [1, 2] }\n  - 3\n"), 4);
    // Brackets inside quoted strings and comments do not nest; keys hold anything up to ':'.
    EXPECT_EQ(depthOf("%YAML:1.0\n---\na: \"[[[[\"\nb: '{{{{'  # [[[[\nc: x [[[[\n"), 1);
    // ... but a quote inside a plain scalar does not start a string: the brackets after it
    // count (OpenCV reads [a 'b, [[ as the scalar "a 'b" and two levels).
    EXPECT_EQ(depthOf("%YAML:1.0\n---\nk: [a 'b, [[1]]]\n"), 4);
    EXPECT_EQ(depthOf("%YAML:1.0\n---\nk: [a #b, [[1]]]\n"), 4);
    EXPECT_EQ(depthOf("%YAML:1.0\n---\na: 1\n'k: [[1]]\n"), 3);
    // Block nesting on one line ("- - -", "a: b: c:") and by indentation.
    EXPECT_EQ(depthOf("%YAML:1.0\n---\nk: - - - 1\n"), 4);
    EXPECT_EQ(depthOf("%YAML:1.0\n---\na: b: c: d: 1\n"), 4);
    EXPECT_EQ(depthOf("{ \"a\": [ { \"b\": \"]]]}}}\" } ] }"), 3);
    // Control characters and tabs end the scan of nothing (every byte moves it on).
    EXPECT_EQ(depthOf(std::string("%YAML:1.0\n---\na: [\t\x01, \x7f]\n\tb:\x02\n", 30)), 2);
    EXPECT_EQ(depthOf("<?xml version=\"1.0\"?>\n<opencv_storage><a><b/><c>1</c></a>"
                      "<!-- <x><y><z> --></opencv_storage>\n"), 3);
}

TEST(Augocc_InputLimits, own_files_are_far_below_the_depth_limit)
{
    // What augocc writes must nest well below the limit (the limit's margin).
    const AnalyticScene s = makeScene(PERSPECTIVE, towerAndEll(), 6, 2);
    const std::string dir = tempDir("limits_own");
    writeReconstruction(dir + "/rec.yml", s.rec);
    Ptr<CloneSet> clones = CloneBuilder::create()->build(s.rec, s.keyMasks);
    clones->save(dir + "/clones.yml");
    for (const char* f : {"/rec.yml", "/clones.yml"})
        EXPECT_LE(depthOf(readText(dir + f)), 8) << f;
    fs::remove_all(dir);
}

TEST(Augocc_InputLimits, regression_deep_nesting)
{
    // 100,000 levels overflowed the stack in OpenCV 4.6's parsers (SEGV) in all four readers.
    const std::string dir = tempDir("limits_nest");
    const std::string yaml = dir + "/nest.yml", json = dir + "/nest.json",
                      block = dir + "/block.yml", xml = dir + "/nest.xml";
    writeText(yaml, "%YAML:1.0\n---\nobjects: " + std::string(100000, '['));
    writeText(json, "{ \"objects\": " + std::string(100000, '['));
    std::string b = "%YAML:1.0\n---\nobjects: ";
    for (int i = 0; i < 50000; i++)
        b += "- ";
    writeText(block, b + "1\n");
    std::string x = "<?xml version=\"1.0\"?>\n<opencv_storage>";
    for (int i = 0; i < 100000; i++)
        x += "<a>";
    writeText(xml, x);
    for (const std::string& f : {yaml, json, block, xml})
    {
        const std::vector<std::string> needles = {f, "nests deeper"};
        EXPECT_TRUE(throwsWith([&] { readTracks(f); }, needles));
        EXPECT_TRUE(throwsWith([&] { readReconstruction(f); }, needles));
        EXPECT_TRUE(throwsWith([&] { readScene(f); }, needles));
        EXPECT_TRUE(throwsWith([&] { CloneSet::load(f); }, needles));
        EXPECT_TRUE(throwsWith([&] { readCalibration(f); }, needles));
    }
    fs::remove_all(dir);
}

TEST(Augocc_InputLimits, regression_fuzz_reconstruction_length_error)
{
    // Found by fuzz_reconstruction: OpenCV's YAML parser threw std::length_error out of
    // FileStorage::open (exit 1, "internal error: basic_string::_M_create").
    const std::string f = dataFile("fuzz_reconstruction_length_error.yml");
    EXPECT_TRUE(throwsWith([&] { readReconstruction(f); }, {f, "cannot parse file"}));
}

// Every FileStorage reader of augocc, reading `path`.
std::vector<std::function<void()> > storageReaders(const std::string& path)
{
    return {[=] { readTracks(path); }, [=] { readReconstruction(path); },
            [=] { readCalibration(path); }, [=] { CloneSet::load(path); },
            [=] { readScene(path); }};
}

TEST(Augocc_InputLimits, regression_fuzz_nul_byte_and_top_level)
{
    // Found by fuzz_tracks: NUL bytes in a tracks file made FileStorage::open loop for ever.
    const std::string nul = dataFile("fuzz_tracks_nul_hang.yml");
    EXPECT_TRUE(throwsWith([&] { readTracks(nul); }, {nul, "NUL byte"}));
    // Found by fuzz_reconstruction, fuzz_calibration, fuzz_clones: a top level that is not a map
    // gave OpenCV's "isMap()" assertion (exit 1) from FileNode::operator[].
    const std::string dir = tempDir("limits_top");
    const std::string f = dir + "/seq.yml";
    writeText(f, "%YAML:1.0\n---\n- 1\n- 2\n");
    for (const auto& read : storageReaders(f))
        EXPECT_TRUE(throwsWith(read, {f}));
    // Found by fuzz_scene: an indented sequence at the top, then a line starting with '-', made
    // FileStorage::open loop for ever (the whole finding, and the 3-line core of it).
    const std::string hang = dataFile("fuzz_scene_filestorage_hang.yml");
    EXPECT_TRUE(throwsWith([&] { readScene(hang); }, {hang, "line 2", "top-level key"}));
    // And a document marker with text glued to it, then a sequence ("---Y:1", "ts:", "  -").
    const std::string marker = dataFile("fuzz_scene_marker_hang.yml");
    EXPECT_TRUE(throwsWith([&] { readScene(marker); },
                           {marker, "line 2", "'---' document marker"}));
    // Found by fuzz_calibration: a "..." document end with text glued to it, or followed by a
    // line starting with '-', made FileStorage::open loop for ever (the finding, and its cores).
    const std::string end = dataFile("fuzz_calibration_document_end_hang.yml");
    EXPECT_TRUE(throwsWith([&] { readCalibration(end); },
                           {end, "line 5", "'...' document marker"}));
    // The same in a clones file (fuzz_clones, the million-execution campaign: "...-bjects:").
    const std::string clonesEnd = dataFile("fuzz_clones_document_end_hang.yml");
    EXPECT_TRUE(throwsWith([&] { CloneSet::load(clonesEnd); },
                           {clonesEnd, "line 6", "'...' document marker"}));
    const std::string afterEnd = dir + "/after_end.yml";
    writeText(afterEnd, "%YAML:1.0\n---\na: 6\n...\n-x\n");
    for (const auto& read : storageReaders(afterEnd))
        EXPECT_TRUE(throwsWith(read, {afterEnd, "line 5", "top-level key"}));
    const std::string core = dir + "/core.yml";
    writeText(core, "%YAML:1.0\n  - name: x\n-x--\n");
    for (const auto& read : storageReaders(core))
        EXPECT_TRUE(throwsWith(read, {core, "top-level key"}));
    fs::remove_all(dir);
}

TEST(Augocc_InputLimits, regression_fuzz_xml_cut_short)
{
    // Found by fuzz_tracks: a file ending inside XML markup ("<?xml version=", the whole finding)
    // made OpenCV 4.6's XML parser read past the text's end (SEGV in FileStorage::open).
    const std::string f = dataFile("fuzz_tracks_xml_cut_segv.yml");
    for (const auto& read : storageReaders(f))
        EXPECT_TRUE(throwsWith(read, {f, "line 1", "processing instruction not closed"}));
    // Each construct cut short, every reader: a clear error naming the line, no parse attempt.
    const std::string dir = tempDir("limits_xml");
    const std::pair<const char*, const char*> cuts[] = {
        {"<?xml version=\"1.0\"?>\n<opencv_storage>\n<!-- a comment", "comment not closed"},
        {"<?xml version=\"1.0\"?>\n<opencv_storage>\n<frames type_id=\"opencv", "quoted value"},
        {"<?xml version=\"1.0\"?>\n<opencv_storage>\n<frames", "markup not closed"}};
    for (const auto& c : cuts)
    {
        const std::string p = dir + "/cut.xml";
        writeText(p, c.first);
        for (const auto& read : storageReaders(p))
            EXPECT_TRUE(throwsWith(read, {p, "line 3", c.second}));
    }
    // A complete XML file still reads (calibrateCamera users write XML calibration files).
    const std::string ok = dir + "/calibration.xml";
    writeText(ok, "<?xml version=\"1.0\"?>\n<opencv_storage>\n<camera_matrix type_id=\"opencv-matrix\">"
                  "<rows>3</rows><cols>3</cols><dt>d</dt><data>500. 0. 320. 0. 500. 240. 0. 0. "
                  "1.</data></camera_matrix>\n<distortion_coefficients type_id=\"opencv-matrix\">"
                  "<rows>1</rows><cols>5</cols><dt>d</dt><data>0. 0. 0. 0. 0.</data>"
                  "</distortion_coefficients>\n</opencv_storage>\n");
    EXPECT_NO_THROW(readCalibration(ok));
    fs::remove_all(dir);
}

TEST(Augocc_InputLimits, regression_duplicate_keys)
{
    // FileStorage silently kept the first of two 'frames' keys.
    const std::string dir = tempDir("limits_dup");
    const std::string f = dir + "/t.yml";
    writeText(f, "%YAML:1.0\n---\nimage_size: !!opencv-matrix\n  rows: 1\n  cols: 2\n  dt: i\n"
                 "  data: [ 64, 48 ]\nframes: 1\npoints: 1\nframes: 2\n"
                 "tracks: !!opencv-matrix\n  rows: 1\n  cols: 1\n  dt: \"2f\"\n  data: [ 1., 2. ]\n");
    EXPECT_TRUE(throwsWith([&] { readTracks(f); }, {f, "'frames' appears twice"}));
    fs::remove_all(dir);
}

TEST(Augocc_InputLimits, declared_matrix_size_against_its_data)
{
    // 100000 x 100000 x 2 floats declared, two given: OpenCV allocated 80 GB before its check.
    const std::string dir = tempDir("limits_mat");
    const std::string f = dir + "/t.yml";
    writeText(f, "%YAML:1.0\n---\nimage_size: !!opencv-matrix\n  rows: 1\n  cols: 2\n  dt: i\n"
                 "  data: [ 64, 48 ]\nframes: 100000\npoints: 100000\n"
                 "tracks: !!opencv-matrix\n  rows: 100000\n  cols: 100000\n  dt: \"2f\"\n"
                 "  data: [ 1., 2. ]\n");
    EXPECT_TRUE(throwsWith([&] { readTracks(f); }, {f, "'tracks'", "data holds 2"}));
    writeText(f, "%YAML:1.0\n---\nimage_size: !!opencv-matrix\n  rows: 1\n  cols: 2\n  dt: xyz\n"
                 "  data: [ 64, 48 ]\n");
    EXPECT_TRUE(throwsWith([&] { readTracks(f); }, {f, "'image_size'", "dt 'xyz'"}));
    fs::remove_all(dir);
}

TEST(Augocc_InputLimits, regression_absurd_values)
{
    const std::string dir = tempDir("limits_absurd");
    const AnalyticScene s = makeScene(PERSPECTIVE, towerAndEll(), 4, 2);
    // A camera at t = 1e308 gave a UBSan signed overflow in VoxelGrid::imageBounds and exit 0.
    {
        Reconstruction rec = s.rec;
        writeReconstruction(dir + "/rec.yml", rec);
        std::string text = readText(dir + "/rec.yml");
        const size_t t = text.find("t: !!opencv-matrix");
        ASSERT_NE(t, std::string::npos);
        const size_t data = text.find("data: [", t);
        text.replace(data, 7, "data: [ 1e308,");
        // The matrix now holds 4 values: put the count right by dropping the last.
        const size_t close = text.find(']', data);
        const size_t lastComma = text.rfind(',', close);
        text.erase(lastComma, close - lastComma);
        writeText(dir + "/rec_far.yml", text);
        EXPECT_TRUE(throwsWith([&] { readReconstruction(dir + "/rec_far.yml"); },
                               {dir + "/rec_far.yml", "cameras[0]", "t[0]", "limit"}));
    }
    // A reconstructed point at 1e300.
    {
        Reconstruction rec = s.rec;
        rec.points = (Mat_<double>(1, 3) << 1e300, 0, 0);
        EXPECT_TRUE(throwsWith([&] { writeReconstruction(dir + "/r2.yml", rec); },
                               {"'points' (0, 0)", "limit"}));
    }
    // Track coordinates of 2^31 px.
    {
        const Tracks t = Tracks::fromDense(Size(64, 48),
                                           Mat(1, 1, CV_32FC2, Scalar(2147483648.f, 3.f)));
        EXPECT_TRUE(throwsWith([&] { writeTracks(dir + "/t.yml", t); },
                               {"track 0 in frame 0", "limit"}));
    }
    // A scene position of 3.4e39 (beyond float) was accepted.
    {
        const std::string f = dir + "/scene.yml";
        writeText(f, "%YAML:1.0\n---\nobjects:\n  - { shape: box, position: [3.4e39, 0, 0] }\n");
        EXPECT_TRUE(throwsWith([&] { readScene(f); }, {f, "position", "limit"}));
    }
    // Mesh vertices: NaN and 1e308.
    for (const char* v : {"nan", "1e308"})
    {
        const std::string f = dir + "/far.ply";
        writeText(f, std::string("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                 "property float y\nproperty float z\nelement face 1\n"
                                 "property list uchar int vertex_indices\nend_header\n") +
                         v + " 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
        EXPECT_TRUE(throwsWith([&] { loadMeshes(f); }, {f, "vertex"})) << v;
    }
    fs::remove_all(dir);
}

TEST(Augocc_InputLimits, voxel_footprint_far_off_the_image_is_defined)
{
    // The projector itself (for callers that bypass the readers): no int overflow.
    const AnalyticScene s = makeScene(SCALED_ORTHOGRAPHIC, towerAndEll(), 4, 2);
    Camera cam = s.rec.cameras[0];
    cam.t = Vec3d(1e15, 0, 0);
    cv::augocc::detail::VoxelGrid g;
    g.dims = Vec3i(4, 4, 4);
    g.h = 1;
    g.data.assign(64, 1);
    const cv::augocc::detail::VoxelProjector p = g.projector(cam, s.rec.imageSize);
    EXPECT_EQ(g.imageBounds(p), Rect(Point(0, 0), s.rec.imageSize));
}

TEST(Augocc_InputLimits, regression_mesh_cut_in_header_and_body)
{
    // Cut before end_header: Assimp never returned. Cut in the body: ai_assert, SIGABRT.
    EXPECT_TRUE(throwsWith([] { loadMeshes(dataFile("cut_header.ply")); },
                           {"cut_header.ply", "end_header"}));
    EXPECT_TRUE(throwsWith([] { loadMeshes(dataFile("cut_body.ply")); },
                           {"cut_body.ply", "PLY body ends inside vertex 3 of 4"}));
    // Found by fuzz_mesh: a header with no vertex element made Assimp loop for ever.
    EXPECT_TRUE(throwsWith([] { loadMeshes(dataFile("fuzz_mesh_no_vertex.ply")); },
                           {"fuzz_mesh_no_vertex.ply", "no 'element vertex'"}));
    // Found by fuzz_mesh (2026-12-02): misspelt header keywords that the pre-check skipped and
    // Assimp read otherwise: a vertex without y crashed its post-processing (SIGSEGV), a garbled
    // "property" leaked.
    EXPECT_TRUE(throwsWith([] { loadMeshes(dataFile("fuzz_mesh_misspelt_property.ply")); },
                           {"fuzz_mesh_misspelt_property.ply", "bad line 'format ascii 1.`0'"}));
    EXPECT_TRUE(throwsWith([] { loadMeshes(dataFile("fuzz_mesh_garbled_keyword.ply")); },
                           {"fuzz_mesh_garbled_keyword.ply", "unknown line"}));
    // "pLy" and no end_header: Assimp's detection ignores case, and it looped for ever.
    EXPECT_TRUE(throwsWith([] { loadMeshes(dataFile("fuzz_mesh_mixed_case_magic.ply")); },
                           {"fuzz_mesh_mixed_case_magic.ply", "end_header"}));
    // A NUL inside an ASCII body's line: SIGSEGV in Assimp's post-processing.
    EXPECT_TRUE(throwsWith([] { loadMeshes(dataFile("fuzz_mesh_nul_in_ascii_body.ply")); },
                           {"fuzz_mesh_nul_in_ascii_body.ply", "control byte 0x00"}));
    // A form feed in a header line ("element face 03\fproperty list ..."): SIGSEGV likewise.
    EXPECT_TRUE(throwsWith([] { loadMeshes(dataFile("fuzz_mesh_form_feed_in_header.ply")); },
                           {"fuzz_mesh_form_feed_in_header.ply", "control byte 0x0c"}));
    // A binary face of no corner: SIGSEGV in Assimp's post-processing.
    EXPECT_TRUE(throwsWith([] { loadMeshes(dataFile("fuzz_mesh_face_without_corners.ply")); },
                           {"fuzz_mesh_face_without_corners.ply", "face 0 has 0 corners"}));
    // The whole file still loads.
    EXPECT_NO_THROW(loadMeshes(dataFile("tetra.ply")));
}

TEST(Augocc_InputLimits, regression_mesh_huge_counts)
{
    // Huge declared counts exhausted memory in Assimp.
    const std::string dir = tempDir("limits_ply");
    const std::string f = dir + "/huge.ply";
    writeText(f, "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n"
                 "property float x\nproperty float y\nproperty float z\nend_header\n");
    EXPECT_TRUE(throwsWith([&] { loadMeshes(f); }, {f, "4000000000 vertex", "at most"}));
    writeText(f, "ply\nformat binary_little_endian 1.0\nelement vertex 3000000\n"
                 "property float x\nproperty float y\nproperty float z\nend_header\n" +
                     std::string(36, '\0'));
    EXPECT_TRUE(throwsWith([&] { loadMeshes(f); }, {f, "PLY body ends inside vertex 3 "}));
    // A face index beyond the vertices.
    writeText(f, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                 "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                 "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
    EXPECT_TRUE(throwsWith([&] { loadMeshes(f); }, {f, "refers to vertex 7 of 3"}));
    fs::remove_all(dir);
}

TEST(Augocc_InputLimits, regression_mask_names_and_image_limits)
{
    const std::string dir = tempDir("limits_masks");
    const Mat m(48, 64, CV_8U, Scalar(255));
    fs::create_directories(dir + "/a/obj");
    // " 5.png" was read as frame 5.
    imwrite(dir + "/a/obj/ 5.png", m);
    EXPECT_TRUE(throwsWith([&] { readMasks(dir + "/a"); }, {" 5.png", "decimal digits"}));
    fs::remove_all(dir + "/a");
    // "0005.PNG" was silently ignored: the contract's name is <frame>.png.
    fs::create_directories(dir + "/b/obj");
    imwrite(dir + "/b/obj/0004.png", m);
    imwrite(dir + "/b/obj/0005.png.tmp.png", m);
    fs::rename(dir + "/b/obj/0005.png.tmp.png", dir + "/b/obj/0005.PNG");
    EXPECT_TRUE(throwsWith([&] { readMasks(dir + "/b"); }, {"0005.PNG", "lower-case"}));
    fs::remove(dir + "/b/obj/0005.PNG");
    EXPECT_EQ(readMasks(dir + "/b").at("obj").count(4), 1u);
    // A PNG header declaring 60000 x 60000: exit 1 "pixels <= CV_IO_MAX_IMAGE_PIXELS" before.
    std::vector<uchar> png;
    imencode(".png", m, png);
    png[16] = 0; png[17] = 0; png[18] = 0xEA; png[19] = 0x60;  // width 60000 (IHDR, big endian)
    png[20] = 0; png[21] = 0; png[22] = 0xEA; png[23] = 0x60;
    {
        std::ofstream out(dir + "/b/obj/0006.png", std::ios::binary);
        out.write((const char*)png.data(), (std::streamsize)png.size());
    }
    EXPECT_TRUE(throwsWith([&] { readMasks(dir + "/b"); },
                           {"0006.png", "60000 x 60000", "at most 16384"}));
    // A mask that is not a PNG.
    writeText(dir + "/b/obj/0006.png", "GIF89a not a png");
    EXPECT_TRUE(throwsWith([&] { readMasks(dir + "/b"); }, {"0006.png", "not a PNG"}));
    fs::remove_all(dir);
}

struct ClonesFile
{
    AnalyticScene s;
    std::string dir, text;
};

const ClonesFile& clonesFile()
{
    static ClonesFile c;
    if (!c.text.empty())
        return c;
    c.s = makeScene(PERSPECTIVE, towerAndEll(), 6, 2);
    c.dir = tempDir("limits_clones");
    CloneBuilder::create()->build(c.s.rec, c.s.keyMasks)->save(c.dir + "/clones.yml");
    c.text = readText(c.dir + "/clones.yml");
    return c;
}

// The clones file with the first `from` after `anchor` replaced by `to`.
std::string mutated(const std::string& anchor, const std::string& from, const std::string& to)
{
    std::string t = clonesFile().text;
    const size_t a = t.find(anchor);
    const size_t p = a == std::string::npos ? a : t.find(from, a);
    if (p == std::string::npos)
        return std::string();
    return t.replace(p, from.size(), to);
}

TEST(Augocc_InputLimits, regression_clones_reader)
{
    const ClonesFile& c = clonesFile();
    const std::string f = c.dir + "/bad.yml";
    ASSERT_NO_THROW(CloneSet::load(c.dir + "/clones.yml"));
    struct Case
    {
        std::string anchor, from, to, needle;
    };
    // bytes: 1e18 made reserve throw bad_alloc (exit 1); a matrix whose cols disagree with its
    // data was a raw "nelems == m.total()*m.channels()" with no file named.
    const Case cases[] = {
        {"voxels:", "bytes: ", "bytes: 1000000000000000000. #", "voxels: key 'bytes' = 1e+18"},
        {"dims:", "cols: 3", "cols: 4", "key 'dims' declares 1 x 4 x 1 values but its data holds 3"},
        {"R_box:", "rows: 3", "rows: 2", "key 'R_box' declares 2 x 3"},
        {"version:", "version: 1", "version: 7", "key 'version' must be 1"},
        {"patch_rule:", "patch_rule:", "patch_rule: sideways\nx_rule:", "key 'patch_rule'"},
        {"origin:", "data: [", "data: [ 1e300,", ": origin: 1e+300"},
    };
    for (const Case& k : cases)
    {
        std::string t = mutated(k.anchor, k.from, k.to);
        ASSERT_FALSE(t.empty()) << k.anchor;
        if (k.anchor == "origin:")
        {
            // Keep the count right: 4 values -> drop the last.
            const size_t o = t.find("origin:");
            const size_t close = t.find(']', o);
            const size_t comma = t.rfind(',', close);
            t.erase(comma, close - comma);
        }
        writeText(f, t);
        EXPECT_TRUE(throwsWith([&] { CloneSet::load(f); }, {f, k.needle})) << k.anchor;
    }
}

TEST(Augocc_InputLimits, regression_clones_of_other_frames)
{
    // Key-frame masks of another size than the reconstruction's frames were accepted.
    const ClonesFile& c = clonesFile();
    Ptr<CloneSet> clones = CloneSet::load(c.dir + "/clones.yml");
    Reconstruction rec = c.s.rec;
    rec.imageSize = Size(rec.imageSize.width * 2, rec.imageSize.height * 2);
    ObjectMasks mattes;
    EXPECT_TRUE(throwsWith([&] { renderMattes(*clones, rec, mattes); },
                           {"silhouette is", "clones file of another video"}));
}

} // namespace
} // namespace opencv_test
