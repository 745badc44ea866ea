// This file is part of augocc. License: Apache-2.0.
// It is subject to the license terms in the LICENSE file found in the top-level directory.

// augocc farm's workflow without Slurm (samples/augocc/farm_workflow.hpp): the shots file, the
// chunks, the scripts, what resume submits. The real cluster: test/farm/slurm_test.sh.

#include "test_precomp.hpp"
#include "test_common.hpp"
#include "cli_common.hpp"
#include "farm_workflow.hpp"

#include <filesystem>
#include <fstream>
#include <iterator>

namespace opencv_test {
namespace {

namespace fs = std::filesystem;
using namespace augocc_cli::farm;
using augocc_cli::UsageError;

typedef std::vector<std::pair<int, int> > Chunks;

TEST(Augocc_Farm, split_frames)
{
    EXPECT_EQ(splitFrames(16, 0, 4), Chunks({{0, 4}, {4, 8}, {8, 12}, {12, 16}}));
    // Near-equal: the first ones one frame longer.
    EXPECT_EQ(splitFrames(10, 0, 4), Chunks({{0, 3}, {3, 6}, {6, 8}, {8, 10}}));
    EXPECT_EQ(splitFrames(12, 5, 0), Chunks({{0, 5}, {5, 10}, {10, 12}}));
    // Never an empty chunk.
    EXPECT_EQ(splitFrames(3, 0, 8), Chunks({{0, 1}, {1, 2}, {2, 3}}));
    EXPECT_EQ(splitFrames(7, 100, 0), Chunks({{0, 7}}));
    EXPECT_EQ(chunkDir({12, 16}), "chunks/0012-0016");
}

// readShotsFile's message for a shots file `file` holding `text` ("no error" when it reads).
std::string shotsError(const fs::path& file, const std::string& text)
{
    std::ofstream(file) << text;
    try
    {
        readShotsFile(file.string());
    }
    catch (const UsageError& e)
    {
        return std::string(e.what());
    }
    return std::string("no error");
}

TEST(Augocc_Farm, shots_file)
{
    const fs::path dir = tempDir("farm_shots");
    const fs::path file = dir / "shots.txt";
    {
        std::ofstream f(file);
        f << "# input masks scene out-dir\n"
          << "a/video.mp4  a/masks  a/scene.yml  out/shot_a   # the first\n"
          << "\n"
          << "/abs/b/%04d.png /abs/b/masks - /abs/out/shot\\ b\n";
    }
    EXPECT_THROW(readShotsFile(file.string()), UsageError);  // a blank in an out-dir
    {
        std::ofstream f(file);
        f << "a/video.mp4  a/masks  a/scene.yml  out/shot_a   # the first\n"
          << "/abs/b/%04d.png /abs/b/masks - /abs/out/shot.b\n";
    }
    const std::vector<Shot> s = readShotsFile(file.string());
    ASSERT_EQ(s.size(), 2u);
    EXPECT_EQ(s[0].input, (dir / "a/video.mp4").string());
    EXPECT_EQ(s[0].scene, (dir / "a/scene.yml").string());
    EXPECT_EQ(s[0].outDir, (dir / "out/shot_a").string());
    EXPECT_EQ(s[0].name, "shot_a");
    EXPECT_EQ(s[1].input, "/abs/b/%04d.png");
    EXPECT_EQ(s[1].scene, "");
    EXPECT_EQ(s[1].name, "shot.b");

    auto errorOf = [&](const std::string& text) { return shotsError(file, text); };
    const std::string where = file.string() + ":2: ";
    EXPECT_EQ(errorOf("# nothing\n"), "--shots " + file.string() +
              ": no shot (a line 'input masks scene out-dir')");
    EXPECT_EQ(errorOf("a b c d\na b c\n").rfind(where + "expected 4 fields", 0), 0u);
    EXPECT_EQ(errorOf("a b c x/shot\na b c y/shot\n").rfind(where + "out-dir", 0), 0u);
    EXPECT_EQ(errorOf("a b c x/sh%ot\n").rfind(file.string() + ":1: out-dir", 0), 0u);
    fs::remove_all(dir);
}

TEST(Augocc_Farm, shots_file_yaml)
{
    // The same shots as a YAML (or JSON) list of maps; scene optional.
    const fs::path dir = tempDir("farm_shots_yaml");
    const fs::path file = dir / "shots.yml";
    std::ofstream(file) << "%YAML:1.0\n---\nshots:\n"
                        << "  - { input: a/video.mp4, masks: a/masks, scene: a/scene.yml, "
                           "out_dir: out/shot_a }\n"
                        << "  - { input: \"/abs/b/%04d.png\", masks: /abs/b/masks, "
                           "out_dir: /abs/out/shot.b }\n";
    const std::vector<Shot> s = readShotsFile(file.string());
    ASSERT_EQ(s.size(), 2u);
    EXPECT_EQ(s[0].input, (dir / "a/video.mp4").string());
    EXPECT_EQ(s[0].scene, (dir / "a/scene.yml").string());
    EXPECT_EQ(s[0].name, "shot_a");
    EXPECT_EQ(s[1].input, "/abs/b/%04d.png");
    EXPECT_EQ(s[1].scene, "");
    EXPECT_EQ(s[1].name, "shot.b");
    const fs::path json = dir / "shots.json";
    std::ofstream(json) << "{ \"shots\": [ { \"input\": \"v.mp4\", \"masks\": \"m\", "
                           "\"out_dir\": \"o/x\" } ] }\n";
    ASSERT_EQ(readShotsFile(json.string()).size(), 1u);

    auto errorOf = [&](const std::string& text) { return shotsError(file, text); };
    const std::string f = file.string();
    EXPECT_EQ(errorOf("%YAML:1.0\n---\nshots: []\n").rfind("--shots " + f + ": no shot", 0), 0u);
    EXPECT_EQ(errorOf("%YAML:1.0\n---\nshots:\n  - { input: v, out_dir: o/x }\n"),
              f + ": shot 1: key 'masks' is missing");
    EXPECT_EQ(errorOf("%YAML:1.0\n---\nshots:\n  - { input: v, masks: m, out: o/x }\n"),
              f + ": shot 1: unknown key 'out' (input, masks, scene, out_dir)");
    EXPECT_EQ(errorOf("%YAML:1.0\n---\nshots:\n  - { input: v, masks: m, out_dir: x/s }\n"
                      "  - { input: w, masks: m, out_dir: y/s }\n")
                  .rfind(f + ": shot 2: out-dir", 0),
              0u);
    // A file the parsers would crash on is refused before them (the readers' limits).
    EXPECT_EQ(errorOf("<?xml version=").find("no shot"), std::string::npos);
    EXPECT_NE(errorOf("%YAML:1.0\nshots: [ { input: v\n").find("--shots " + f), std::string::npos);
    fs::remove_all(dir);
}

Plan demoPlan(const std::string& outDir, bool scene)
{
    Plan p;
    p.shot.name = "shot1";
    p.shot.input = "/data/shot1/video.mp4";
    p.shot.masks = "/data/shot1/masks";
    p.shot.scene = scene ? "/data/shot 1/scene.yml" : "";
    p.shot.outDir = outDir;
    p.frameCount = 16;
    p.fps = 29.97;
    p.chunks = splitFrames(16, 0, 4);
    p.objects = {"building", "l block", "tower"};
    return p;
}

TEST(Augocc_Farm, scripts)
{
    Options o;
    o.partition = "gpu";
    o.timeLimit = "01:30:00";
    o.augocc = "/opt/augocc/bin/augocc";
    o.setup = {"module load opencv/4.6"};
    const std::vector<Script> s = makeScripts(demoPlan("/farm/out/shot1", true), o);
    ASSERT_EQ(s.size(), 5u);
    EXPECT_EQ(s[0].file, "1-sfm.sh");
    EXPECT_EQ(s[1].file, "2-clone.sh");
    EXPECT_EQ(s[2].file, "3-merge.sh");
    EXPECT_EQ(s[3].file, "4-chunks.sh");
    EXPECT_EQ(s[4].file, "5-join.sh");
    for (const Script& x : s)
    {
        EXPECT_EQ(x.text.rfind("#!/bin/bash\n", 0), 0u);
        EXPECT_NE(x.text.find("#SBATCH --partition=gpu\n"), std::string::npos);
        EXPECT_NE(x.text.find("#SBATCH --time=01:30:00\n"), std::string::npos);
        EXPECT_EQ(x.text.find("--account"), std::string::npos);  // not given: not written
        EXPECT_NE(x.text.find("\nmodule load opencv/4.6\n"), std::string::npos);
        EXPECT_NE(x.text.find("AUGOCC=/opt/augocc/bin/augocc\n"), std::string::npos);
        EXPECT_NE(x.text.find("\ncd /farm/out/shot1\n"), std::string::npos);
        EXPECT_NE(x.text.find("#SBATCH --output=/farm/out/shot1/farm/logs/%x-"),
                  std::string::npos);
    }
    EXPECT_NE(s[0].text.find("#SBATCH --job-name=augocc-shot1-sfm\n"), std::string::npos);
    // The clones: an array over the objects, each task writing its part; then one merge.
    EXPECT_NE(s[1].text.find("#SBATCH --job-name=augocc-shot1-clone\n"), std::string::npos);
    EXPECT_NE(s[1].text.find("#SBATCH --array=0-2\n"), std::string::npos);
    EXPECT_NE(s[1].text.find("OBJECTS=(building 'l block' tower)\n"), std::string::npos);
    EXPECT_NE(s[1].text.find("--object \"${OBJECTS[i]}\" --out \"$part\""), std::string::npos);
    EXPECT_NE(s[1].text.find("if [ -f \"$part\" ]; then"), std::string::npos);
    EXPECT_EQ(s[1].text.find("--input"), std::string::npos);  // photo refine: at the merge
    EXPECT_NE(s[2].text.find("#SBATCH --job-name=augocc-shot1-merge\n"), std::string::npos);
    EXPECT_EQ(s[2].text.find("--array"), std::string::npos);
    EXPECT_NE(s[2].text.find("--merge \\\n        clones.parts/building.yml.gz \\\n        "
                             "'clones.parts/l block.yml.gz' \\\n        "
                             "clones.parts/tower.yml.gz\n"), std::string::npos) << s[2].text;
    EXPECT_NE(s[2].text.find("--input \"$INPUT\""), std::string::npos);  // photo refine
    EXPECT_NE(s[3].text.find("#SBATCH --array=0-3\n"), std::string::npos);
    EXPECT_NE(s[3].text.find("FIRST=(0 4 8 12)\nEND=(4 8 12 16)\n"), std::string::npos);
    EXPECT_NE(s[3].text.find("SCENE='/data/shot 1/scene.yml'\n"), std::string::npos);
    EXPECT_NE(s[3].text.find(" composite "), std::string::npos);
    EXPECT_NE(s[4].text.find("chunks/0012-0016/composite"), std::string::npos);
    EXPECT_NE(s[4].text.find("--fps 29.969999999999999 --out composite.mp4"),
              std::string::npos);

    // No scene: the chunks render mattes, the join has no video.
    o.photoRefine = false;
    const std::vector<Script> m = makeScripts(demoPlan("/farm/out/shot1", false), o);
    EXPECT_NE(m[3].text.find(" matte "), std::string::npos);
    EXPECT_EQ(m[3].text.find(" composite "), std::string::npos);
    EXPECT_EQ(m[4].text.find("composite.mp4"), std::string::npos);
    EXPECT_EQ(m[2].text.find("--input"), std::string::npos);
}

TEST(Augocc_Farm, shell_quote)
{
    EXPECT_EQ(shellQuote("/a/b-c_d.e"), "/a/b-c_d.e");
    EXPECT_EQ(shellQuote("a b"), "'a b'");
    EXPECT_EQ(shellQuote("it's"), "'it'\\''s'");
    EXPECT_EQ(shellQuote("$HOME"), "'$HOME'");
    EXPECT_EQ(shellQuote(""), "''");
}

TEST(Augocc_Farm, resume_submits_the_unfinished_only)
{
    const fs::path dir = tempDir("farm_resume");
    const Plan plan = demoPlan(dir.string(), true);
    EXPECT_EQ(arraySpec({0, 1, 2, 5, 7, 8}), "0-2,5,7-8");

    // Nothing done: the five stages, each waiting for the one before.
    std::vector<Submission> s = planSubmissions(plan, readStatus(plan));
    ASSERT_EQ(s.size(), 5u);
    EXPECT_EQ(s[0].stage, STAGE_SFM);
    EXPECT_EQ(s[0].dependsOn, -1);
    EXPECT_EQ(s[1].stage, STAGE_CLONE);
    EXPECT_EQ(s[1].arrayTasks, std::vector<int>({0, 1, 2}));
    EXPECT_EQ(s[1].dependsOn, 0);
    EXPECT_EQ(s[1].script, (dir / "farm" / "2-clone.sh").string());
    EXPECT_EQ(s[2].stage, STAGE_MERGE);
    EXPECT_TRUE(s[2].arrayTasks.empty());
    EXPECT_EQ(s[2].dependsOn, 1);
    EXPECT_EQ(s[2].script, (dir / "farm" / "3-merge.sh").string());
    EXPECT_EQ(s[3].arrayTasks, std::vector<int>({0, 1, 2, 3}));
    EXPECT_EQ(s[3].dependsOn, 2);
    EXPECT_EQ(s[4].dependsOn, 3);
    EXPECT_EQ(s[3].script, (dir / "farm" / "4-chunks.sh").string());
    EXPECT_EQ(sbatchArgs(s[3], "41"),
              std::vector<std::string>({"--parsable", "--array=0-3",
                                        "--dependency=afterok:41", "--kill-on-invalid-dep=yes",
                                        s[3].script}));
    EXPECT_EQ(sbatchArgs(s[0], ""), std::vector<std::string>({"--parsable", s[0].script}));

    // sfm done, the part of 'l block' written (its task finished, the others failed): the
    // clone array over objects 0 and 2, the merge, the chunks, the join.
    std::ofstream(dir / "tracks.yml") << "x";
    std::ofstream(dir / "reconstruction.yml") << "x";
    fs::create_directories(dir / "clones.parts");
    std::ofstream(dir / clonePartFile("l block")) << "x";
    Status p0 = readStatus(plan);
    EXPECT_EQ(p0.cloneParts, std::vector<bool>({false, true, false}));
    EXPECT_FALSE(p0.clone);
    s = planSubmissions(plan, p0);
    ASSERT_EQ(s.size(), 4u);
    EXPECT_EQ(s[0].stage, STAGE_CLONE);
    EXPECT_EQ(s[0].arrayTasks, std::vector<int>({0, 2}));
    EXPECT_EQ(s[0].dependsOn, -1);
    EXPECT_EQ(s[1].stage, STAGE_MERGE);
    EXPECT_EQ(s[1].dependsOn, 0);
    // Every part written, the merge failed: the merge alone before the chunks.
    std::ofstream(dir / clonePartFile("building")) << "x";
    std::ofstream(dir / clonePartFile("tower")) << "x";
    s = planSubmissions(plan, readStatus(plan));
    ASSERT_EQ(s.size(), 3u);
    EXPECT_EQ(s[0].stage, STAGE_MERGE);
    EXPECT_EQ(s[0].dependsOn, -1);
    EXPECT_EQ(s[1].stage, STAGE_CHUNKS);

    // sfm, clone and chunks 0 and 2 finished (chunk 3 has its composite but not its mattes:
    // killed between the two renames): chunks 1 and 3, then the join.
    fs::remove_all(dir / "clones.parts");  // the merged file alone says the clones are done
    std::ofstream(dir / "clones.yml.gz") << "x";
    for (const char* c : {"0000-0004", "0008-0012"})
    {
        fs::create_directories(dir / "chunks" / c / "composite");
        fs::create_directories(dir / "chunks" / c / "mattes");
    }
    fs::create_directories(dir / "chunks" / "0012-0016" / "composite");
    const Status p = readStatus(plan);
    EXPECT_TRUE(p.sfm);
    EXPECT_TRUE(p.clone);
    EXPECT_EQ(p.chunks, std::vector<bool>({true, false, true, false}));
    s = planSubmissions(plan, p);
    ASSERT_EQ(s.size(), 2u);
    EXPECT_EQ(s[0].stage, STAGE_CHUNKS);
    EXPECT_EQ(s[0].arrayTasks, std::vector<int>({1, 3}));
    EXPECT_EQ(s[0].dependsOn, -1);
    EXPECT_EQ(s[1].stage, STAGE_JOIN);
    EXPECT_EQ(s[1].dependsOn, 0);

    // Every chunk done, the video missing: the join alone.
    fs::create_directories(dir / "chunks" / "0004-0008" / "composite");
    fs::create_directories(dir / "chunks" / "0004-0008" / "mattes");
    fs::create_directories(dir / "chunks" / "0012-0016" / "mattes");
    fs::create_directories(dir / "mattes");
    fs::create_directories(dir / "composite");
    s = planSubmissions(plan, readStatus(plan));
    ASSERT_EQ(s.size(), 1u);
    EXPECT_EQ(s[0].stage, STAGE_JOIN);
    EXPECT_EQ(s[0].dependsOn, -1);
    std::ofstream(dir / "composite.mp4") << "x";
    EXPECT_TRUE(planSubmissions(plan, readStatus(plan)).empty());
    fs::remove_all(dir);
}

TEST(Augocc_Farm, plan_file_round_trip)
{
    const fs::path dir = tempDir("farm_plan");
    fs::create_directories(dir / "farm");
    Options o;
    o.account = "vfx";
    o.setup = {"module load a", "export OMP_NUM_THREADS=2"};
    o.photoRefine = false;
    const Plan plan = demoPlan(dir.string(), true);
    writePlan(plan, o);
    Plan back;
    Options ob;
    readPlan(dir.string(), back, ob);
    EXPECT_EQ(back.shot.name, plan.shot.name);
    EXPECT_EQ(back.shot.scene, plan.shot.scene);
    EXPECT_EQ(back.shot.outDir, plan.shot.outDir);
    EXPECT_EQ(back.frameCount, 16);
    EXPECT_EQ(back.fps, 29.97);
    EXPECT_EQ(back.chunks, plan.chunks);
    EXPECT_EQ(back.objects, plan.objects);
    EXPECT_EQ(ob.account, "vfx");
    EXPECT_EQ(ob.partition, "");
    EXPECT_EQ(ob.setup, o.setup);
    EXPECT_FALSE(ob.photoRefine);
    EXPECT_THROW(readPlan((dir / "nothing").string(), back, ob), UsageError);
    // A plan without its objects (an older augocc farm): resume cannot run the clone array.
    Plan old = plan;
    old.objects.clear();
    writePlan(old, o);
    EXPECT_THROW(readPlan(dir.string(), back, ob), UsageError);
    fs::remove_all(dir);
}

// Every file under `a` equals the one under `b` of the same relative path, and the file counts
// match.
void expectSameTree(const fs::path& a, const fs::path& b)
{
    int na = 0, nb = 0;
    for (const auto& e : fs::recursive_directory_iterator(a))
        if (e.is_regular_file())
        {
            na++;
            const fs::path other = b / fs::relative(e.path(), a);
            std::ifstream fa(e.path(), std::ios::binary), fb(other, std::ios::binary);
            const std::string x((std::istreambuf_iterator<char>(fa)), {}),
                y((std::istreambuf_iterator<char>(fb)), {});
            EXPECT_TRUE(!x.empty() && x == y) << e.path() << " differs from " << other;
        }
    for (const auto& e : fs::recursive_directory_iterator(b))
        nb += e.is_regular_file() ? 1 : 0;
    EXPECT_EQ(na, nb) << a << " and " << b;
}

// The chunks of composite and matte (--frames a:b), joined, are the single run's outputs byte
// for byte: what the farm's chunk array and join do, without Slurm.
TEST(Augocc_Farm, chunks_joined_equal_the_whole)
{
    const fs::path dir = tempDir("farm_chunks");
    const std::string a = augoccBinary() + " --quiet ";
    const std::string d = dir.string() + "/";
    std::ofstream(dir / "scene.yml")
        << "%YAML:1.0\n---\nobjects:\n"
        << "  - { name: tree, shape: tree, in_front_of: building, distance: 0.15, size: 0.6 }\n";
    std::string out;
    ASSERT_EQ(runCommand(a + "synth --out " + d + "src --frames 8 --size 96x72", &out), 0) << out;
    ASSERT_EQ(runCommand(a + "track --input " + d + "src/video.mp4 --out " + d + "t.yml", &out),
              0) << out;
    ASSERT_EQ(runCommand(a + "sfm --tracks " + d + "t.yml --out " + d + "r.yml", &out), 0) << out;
    ASSERT_EQ(runCommand(a + "clone --reconstruction " + d + "r.yml --masks " + d +
                         "src/input/masks --tracks " + d + "t.yml --out " + d + "c.yml.gz", &out),
              0) << out;
    const std::string comp = a + "composite --input " + d + "src/video.mp4 --reconstruction " + d +
                             "r.yml --clones " + d + "c.yml.gz --scene " + d + "scene.yml ";
    ASSERT_EQ(runCommand(comp + "--out " + d + "whole --mattes " + d + "whole_m", &out), 0) << out;
    ASSERT_EQ(runCommand(comp + "--frames 5: --out " + d + "c1 --mattes " + d + "c1_m", &out), 0)
        << out;
    ASSERT_EQ(runCommand(comp + "--frames 0:5 --out " + d + "c0 --mattes " + d + "c0_m", &out), 0)
        << out;
    ASSERT_EQ(runCommand(a + "join --kind frames --out " + d + "joined " + d + "c1 " + d + "c0",
                         &out), 0) << out;
    ASSERT_EQ(runCommand(a + "join --kind masks --out " + d + "joined_m " + d + "c0_m " + d +
                         "c1_m", &out), 0) << out;
    expectSameTree(dir / "whole", dir / "joined");
    expectSameTree(dir / "whole_m", dir / "joined_m");
    EXPECT_EQ(std::distance(fs::directory_iterator(dir / "joined"), fs::directory_iterator()), 8);

    // matte --frames: chunks of the mattes alone, joined, = augocc matte of every frame.
    const std::string matte = a + "matte --reconstruction " + d + "r.yml --clones " + d +
                              "c.yml.gz --out " + d;
    ASSERT_EQ(runCommand(matte + "m_all", &out), 0) << out;
    ASSERT_EQ(runCommand(matte + "m0 --frames 0:3", &out), 0) << out;
    ASSERT_EQ(runCommand(matte + "m1 --frames 3:", &out), 0) << out;
    ASSERT_EQ(runCommand(a + "join --kind masks --out " + d + "m_joined " + d + "m0 " + d + "m1",
                         &out), 0) << out;
    expectSameTree(dir / "m_all", dir / "m_joined");
    expectSameTree(dir / "whole_m", dir / "m_all");  // composite's mattes are matte's
    // A frame past the reconstruction's cameras: exit 2, nothing written.
    EXPECT_EQ(runCommand(matte + "m_bad --frames 5:20", &out), 2);
    EXPECT_NE(out.find("--frames 5:20: frame 19 is beyond the last frame 7"), std::string::npos)
        << out;
    EXPECT_FALSE(fs::exists(dir / "m_bad"));
    // Overlapping chunks: exit 2 naming the frame.
    EXPECT_EQ(runCommand(a + "join --kind frames --out " + d + "j2 " + d + "c0 " + d + "whole",
                         &out), 2);
    EXPECT_NE(out.find("frame 0 is also in"), std::string::npos) << out;
    fs::remove_all(dir);
}

} // namespace
} // namespace opencv_test
