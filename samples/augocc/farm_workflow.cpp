// augocc farm: the Slurm workflow of a shot as data and script text (doc/farm.md).

#include "farm_workflow.hpp"

#include "cli_common.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>
#include <opencv2/augocc.hpp>

namespace fs = std::filesystem;

namespace augocc_cli {
namespace farm {

namespace {

// Blanks in a path would break the #SBATCH lines (they cannot be quoted) and '%' is Slurm's
// file-name pattern character.
void checkFarmPath(const std::string& where, const std::string& path)
{
    if (path.find_first_of(" \t\n%") != std::string::npos)
        throw UsageError(where + " " + path + ": an out-dir for the farm may not hold blanks or "
                         "'%' (Slurm's #SBATCH lines cannot quote them)");
}

std::string absoluteFrom(const fs::path& base, const std::string& p)
{
    fs::path q(p);
    if (q.is_relative())
        q = base / q;
    return q.lexically_normal().string();
}

// The shot's paths a stage's commands use (each variable set only where used: shellcheck).
enum Uses { USES_INPUT = 1, USES_MASKS = 2, USES_SCENE = 4 };

// #SBATCH header, strict mode, the user's environment lines, and the shot's variables.
std::string header(const Plan& plan, const Options& o, Stage stage, const std::string& what,
                   int arrayTasks, int uses)
{
    const bool array = arrayTasks > 0;
    const Shot& s = plan.shot;
    std::ostringstream t;
    t << "#!/bin/bash\n"
      << "# augocc farm: shot " << s.name << ", " << what << "\n"
      << "# Written by augocc farm (doc/farm.md); edit freely, then\n"
      << "#   augocc farm resume --out-dir " << s.outDir << "\n"
      << "#SBATCH --job-name=augocc-" << s.name << "-" << stageName(stage) << "\n"
      << "#SBATCH --output=" << s.outDir << "/farm/logs/%x-" << (array ? "%A_%a" : "%j")
      << ".out\n";
    if (!o.partition.empty())
        t << "#SBATCH --partition=" << o.partition << "\n";
    if (!o.account.empty())
        t << "#SBATCH --account=" << o.account << "\n";
    if (!o.timeLimit.empty())
        t << "#SBATCH --time=" << o.timeLimit << "\n";
    if (array)
        t << "#SBATCH --array=0-" << arrayTasks - 1 << "\n";
    t << "set -euo pipefail\n";
    if (!o.setup.empty())
    {
        t << "# The environment the jobs need (--setup):\n";
        for (const std::string& line : o.setup)
            t << line << "\n";
    }
    t << "AUGOCC=" << shellQuote(o.augocc) << "\n";
    if (uses & USES_INPUT)
        t << "INPUT=" << shellQuote(s.input) << "\n";
    if (uses & USES_MASKS)
        t << "MASKS=" << shellQuote(s.masks) << "\n";
    if (uses & USES_SCENE)
        t << "SCENE=" << shellQuote(s.scene) << "\n";
    t << "cd " << shellQuote(s.outDir) << "\n";
    return t.str();
}

} // namespace

const char* stageName(Stage s)
{
    static const char* names[] = {"sfm", "clone", "merge", "chunks", "join"};
    return names[s];
}

std::string clonePartFile(const std::string& object)
{
    return "clones.parts/" + object + ".yml.gz";
}

std::string shellQuote(const std::string& s)
{
    const bool safe = !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) {
        return std::isalnum(c) || std::strchr("/._-+:,=@", c) != nullptr;
    });
    if (safe)
        return s;
    std::string q = "'";
    for (char c : s)
        q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

std::string shotName(const std::string& outDir)
{
    fs::path p = fs::path(outDir).lexically_normal();
    std::string name = p.filename().string();
    if (name.empty())
        name = p.parent_path().filename().string();
    for (char& c : name)
        if (!std::isalnum((unsigned char)c) && c != '.' && c != '_' && c != '-')
            c = '_';
    return name.empty() ? std::string("shot") : name;
}

namespace {

// One shot from its four fields (relative paths against `base`), checked against those before.
void addShot(std::vector<Shot>& shots, const fs::path& base, const std::string& where,
             const std::string& input, const std::string& masks, const std::string& scene,
             const std::string& outDir)
{
    Shot s;
    s.input = absoluteFrom(base, input);
    s.masks = absoluteFrom(base, masks);
    s.scene = scene.empty() || scene == "-" ? std::string() : absoluteFrom(base, scene);
    s.outDir = absoluteFrom(base, outDir);
    checkFarmPath(where + ": out-dir", s.outDir);
    s.name = shotName(s.outDir);
    for (const Shot& other : shots)
        if (other.name == s.name)
            throw UsageError(where + ": out-dir " + s.outDir + " has the folder name of " +
                             other.outDir + " (job names come from it: make them differ)");
    shots.push_back(s);
}

bool isStorageName(const std::string& path)
{
    std::string p = path;
    if (p.size() > 3 && p.compare(p.size() - 3, 3, ".gz") == 0)
        p.resize(p.size() - 3);
    const std::string ext = fs::path(p).extension().string();
    return ext == ".yml" || ext == ".yaml" || ext == ".json";
}

// shots: [{input, masks, scene (optional), out_dir}, ...] in YAML or JSON.
std::vector<Shot> readShotsStorage(const std::string& path, const fs::path& base)
{
    std::vector<Shot> shots;
    try
    {
        cv::FileStorage fsr = cv::augocc::openStorageForRead(path, "shots file");
        const cv::FileNode list = fsr["shots"];
        if (!list.isSeq() || list.size() == 0)
            throw UsageError("--shots " + path + ": no shot (a sequence 'shots' of maps with "
                             "input, masks, scene and out_dir)");
        for (int i = 0; i < (int)list.size(); i++)
        {
            const cv::FileNode n = list[i];
            const std::string where = path + cv::format(": shot %d", i + 1);
            if (!n.isMap())
                throw UsageError(where + ": expected a map with input, masks, scene, out_dir");
            for (const cv::FileNode& k : n)
                if (k.name() != "input" && k.name() != "masks" && k.name() != "scene" &&
                    k.name() != "out_dir")
                    throw UsageError(where + ": unknown key '" + k.name() +
                                     "' (input, masks, scene, out_dir)");
            auto text = [&](const char* key, bool required) {
                const cv::FileNode v = n[key];
                if (v.empty() || v.isNone())
                {
                    if (required)
                        throw UsageError(where + ": key '" + key + "' is missing");
                    return std::string();
                }
                if (!v.isString() || v.string().empty())
                    throw UsageError(where + ": key '" + key + "' must be a non-empty path");
                return v.string();
            };
            addShot(shots, base, where, text("input", true), text("masks", true),
                    text("scene", false), text("out_dir", true));
        }
    }
    catch (const cv::Exception& e)
    {
        throw UsageError("--shots " + e.err);
    }
    return shots;
}

} // namespace

std::vector<Shot> readShotsFile(const std::string& path)
{
    const fs::path base = fs::absolute(fs::path(path)).parent_path();
    if (isStorageName(path))
        return readShotsStorage(path, base);
    std::ifstream in(path);
    if (!in)
        throw UsageError("--shots " + path + ": cannot be read");
    std::vector<Shot> shots;
    std::string line;
    for (int number = 1; std::getline(in, line); number++)
    {
        const size_t hash = line.find('#');
        if (hash != std::string::npos)
            line.resize(hash);
        std::istringstream words(line);
        std::vector<std::string> w;
        for (std::string x; words >> x;)
            w.push_back(x);
        if (w.empty())
            continue;
        const std::string where = path + ":" + std::to_string(number);
        if (w.size() != 4)
            throw UsageError(where + ": expected 4 fields, input masks scene out-dir ('-' for no "
                             "scene), found " + std::to_string(w.size()));
        addShot(shots, base, where, w[0], w[1], w[2], w[3]);
    }
    if (shots.empty())
        throw UsageError("--shots " + path + ": no shot (a line 'input masks scene out-dir')");
    return shots;
}

std::vector<std::pair<int, int> > splitFrames(int frameCount, int chunkFrames, int chunks)
{
    CV_Assert(frameCount > 0 && ((chunkFrames > 0) != (chunks > 0)));
    std::vector<std::pair<int, int> > out;
    if (chunkFrames > 0)
    {
        for (int a = 0; a < frameCount; a += chunkFrames)
            out.push_back({a, std::min(frameCount, a + chunkFrames)});
        return out;
    }
    const int n = std::min(chunks, frameCount);
    for (int i = 0, a = 0; i < n; i++)
    {
        const int len = frameCount / n + (i < frameCount % n ? 1 : 0);
        out.push_back({a, a + len});
        a += len;
    }
    return out;
}

std::string chunkDir(const std::pair<int, int>& chunk)
{
    return cv::format("chunks/%04d-%04d", chunk.first, chunk.second);
}

std::vector<Script> makeScripts(const Plan& plan, const Options& o)
{
    const Shot& s = plan.shot;
    const bool scene = !s.scene.empty();
    std::vector<Script> scripts;

    // 1. Tracking and camera recovery: one job (every frame's tracks feed one bundle adjustment).
    std::ostringstream sfm;
    sfm << header(plan, o, STAGE_SFM, "tracking and camera recovery (one job: the whole shot)",
                  0, USES_INPUT)
        << "# Each output is written all or nothing: a file present is finished.\n"
        << "if [ ! -f tracks.yml ]; then\n"
        << "    \"$AUGOCC\" --quiet track --input \"$INPUT\" --out tracks.yml\n"
        << "fi\n"
        << "if [ ! -f reconstruction.yml ]; then\n"
        << "    \"$AUGOCC\" --quiet sfm --tracks tracks.yml --out reconstruction.yml\n"
        << "fi\n";
    scripts.push_back({STAGE_SFM, "1-sfm.sh", sfm.str()});

    // 2. The clones, per object: a job array, task i = object i (passes 1-4 of doc/clones.md
    // need no other object's clone). The object list is the masks folder's at submission.
    CV_Assert(!plan.objects.empty());
    std::ostringstream names;
    for (size_t i = 0; i < plan.objects.size(); i++)
        names << (i ? " " : "") << shellQuote(plan.objects[i]);
    std::ostringstream clone;
    clone << header(plan, o, STAGE_CLONE, "the clones per object (" +
                    std::to_string(plan.objects.size()) + " objects, a job array, task i = "
                    "object i)", (int)plan.objects.size(), USES_MASKS)
          << "# The objects of the masks folder when the shot was submitted (doc/farm.md).\n"
          << "OBJECTS=(" << names.str() << ")\n"
          << "i=${SLURM_ARRAY_TASK_ID:?run as a Slurm array task (sbatch), or set "
             "SLURM_ARRAY_TASK_ID}\n"
          << "part=\"clones.parts/${OBJECTS[i]}.yml.gz\"\n"
          << "# The part is written all or nothing: a part present is finished.\n"
          << "if [ -f \"$part\" ]; then\n"
          << "    echo \"$part: finished before, not redone\"\n"
          << "    exit 0\n"
          << "fi\n"
          << "mkdir -p clones.parts\n"
          << "\"$AUGOCC\" --quiet clone --reconstruction reconstruction.yml --masks \"$MASKS\" "
             "\\\n    --tracks tracks.yml --object \"${OBJECTS[i]}\" --out \"$part\"\n";
    scripts.push_back({STAGE_CLONE, "2-clone.sh", clone.str()});

    // 3. The merge: the parts into one clones file, and the passes that see every object
    // (unobserved volume, patch voxels, photo-consistency): one job.
    std::string parts;
    for (const std::string& obj : plan.objects)
        parts += " \\\n        " + shellQuote(clonePartFile(obj));
    std::ostringstream merge;
    merge << header(plan, o, STAGE_MERGE, "the clone parts merged (one job: the passes that "
                    "look at every object)", 0, USES_MASKS | (o.photoRefine ? USES_INPUT : 0))
          << "if [ ! -f clones.yml.gz ]; then\n"
          << "    \"$AUGOCC\" --quiet clone --reconstruction reconstruction.yml --masks \"$MASKS\" "
             "\\\n        --tracks tracks.yml"
          << (o.photoRefine ? " --input \"$INPUT\"" : "") << " --out clones.yml.gz \\\n"
          << "        --merge" << parts << "\n"
          << "fi\n";
    scripts.push_back({STAGE_MERGE, "3-merge.sh", merge.str()});

    // 4. The chunks: a job array, one task per frame range.
    std::ostringstream first, end;
    for (size_t i = 0; i < plan.chunks.size(); i++)
    {
        first << (i ? " " : "") << plan.chunks[i].first;
        end << (i ? " " : "") << plan.chunks[i].second;
    }
    std::ostringstream chunks;
    chunks << header(plan, o, STAGE_CHUNKS, std::string(scene ? "composite" : "mattes") +
                     " of " + std::to_string(plan.chunks.size()) + " frame chunks (a job "
                     "array, task i = chunk i)", (int)plan.chunks.size(),
                     scene ? USES_INPUT | USES_SCENE : 0)
           << "# Chunk i is frames FIRST[i] .. END[i]-1.\n"
           << "FIRST=(" << first.str() << ")\n"
           << "END=(" << end.str() << ")\n"
           << "i=${SLURM_ARRAY_TASK_ID:?run as a Slurm array task (sbatch), or set "
              "SLURM_ARRAY_TASK_ID}\n"
           << "dir=$(printf 'chunks/%04d-%04d' \"${FIRST[i]}\" \"${END[i]}\")\n"
           << "# The outputs are written all or nothing: a chunk with them is finished.\n";
    if (scene)
        chunks << "if [ -d \"$dir/composite\" ] && [ -d \"$dir/mattes\" ]; then\n";
    else
        chunks << "if [ -d \"$dir/mattes\" ]; then\n";
    chunks << "    echo \"$dir: finished before, not redone\"\n"
           << "    exit 0\n"
           << "fi\n"
           << "mkdir -p \"$dir\"\n";
    if (scene)
        chunks << "\"$AUGOCC\" --quiet composite --input \"$INPUT\" --reconstruction "
                  "reconstruction.yml \\\n    --clones clones.yml.gz --scene \"$SCENE\" "
                  "--frames \"${FIRST[i]}:${END[i]}\" \\\n    --out \"$dir/composite\" "
                  "--mattes \"$dir/mattes\"\n";
    else
        chunks << "\"$AUGOCC\" --quiet matte --reconstruction reconstruction.yml --clones "
                  "clones.yml.gz \\\n    --frames \"${FIRST[i]}:${END[i]}\" --out "
                  "\"$dir/mattes\"\n";
    scripts.push_back({STAGE_CHUNKS, "4-chunks.sh", chunks.str()});

    // 5. The join: PNG files copied, the video encoded once from the joined frames.
    std::ostringstream join;
    join << header(plan, o, STAGE_JOIN, "join of the chunks (PNG copied, the video encoded "
                   "once)", 0, 0);
    auto list = [&](const char* sub) {
        std::string l;
        for (const auto& c : plan.chunks)
            l += " \\\n        " + chunkDir(c) + "/" + sub;
        return l;
    };
    join << "if [ ! -d mattes ]; then\n"
         << "    \"$AUGOCC\" --quiet join --kind masks --out mattes" << list("mattes") << "\n"
         << "fi\n";
    if (scene)
        join << "if [ ! -d composite ]; then\n"
             << "    \"$AUGOCC\" --quiet join --kind frames --out composite" << list("composite")
             << "\n"
             << "fi\n"
             << "if [ ! -f composite.mp4 ]; then\n"
             << "    \"$AUGOCC\" --quiet join --kind frames --fps " << cv::format("%.17g", plan.fps)
             << " --out composite.mp4 composite\n"
             << "fi\n";
    scripts.push_back({STAGE_JOIN, "5-join.sh", join.str()});
    return scripts;
}

Status readStatus(const Plan& plan)
{
    const fs::path d(plan.shot.outDir);
    const bool scene = !plan.shot.scene.empty();
    auto isFile = [&](const fs::path& p) { return fs::is_regular_file(d / p); };
    auto isDir = [&](const fs::path& p) { return fs::is_directory(d / p); };
    Status p;
    p.sfm = isFile("tracks.yml") && isFile("reconstruction.yml");
    for (const std::string& obj : plan.objects)
        p.cloneParts.push_back(isFile(clonePartFile(obj)));
    p.clone = isFile("clones.yml.gz");
    for (const auto& c : plan.chunks)
    {
        const fs::path cd(chunkDir(c));
        p.chunks.push_back(isDir(cd / "mattes") && (!scene || isDir(cd / "composite")));
    }
    p.join = isDir("mattes") && (!scene || (isDir("composite") && isFile("composite.mp4")));
    return p;
}

std::vector<Submission> planSubmissions(const Plan& plan, const Status& p)
{
    std::vector<Submission> subs;
    const std::string dir = (fs::path(plan.shot.outDir) / "farm").string();
    const std::vector<Script> scripts = makeScripts(plan, Options());
    auto add = [&](Stage st, std::vector<int> tasks) {
        Submission s;
        s.stage = st;
        s.script = (fs::path(dir) / scripts[st].file).string();
        s.arrayTasks = tasks;
        s.dependsOn = subs.empty() ? -1 : (int)subs.size() - 1;
        subs.push_back(s);
    };
    if (p.join)
        return subs;
    if (!p.sfm)
        add(STAGE_SFM, {});
    if (!p.clone)
    {
        std::vector<int> objects;
        for (size_t i = 0; i < plan.objects.size(); i++)
            if (i >= p.cloneParts.size() || !p.cloneParts[i])
                objects.push_back((int)i);
        if (!objects.empty())
            add(STAGE_CLONE, objects);
        add(STAGE_MERGE, {});
    }
    std::vector<int> tasks;
    for (size_t i = 0; i < plan.chunks.size(); i++)
        if (i >= p.chunks.size() || !p.chunks[i])
            tasks.push_back((int)i);
    if (!tasks.empty())
        add(STAGE_CHUNKS, tasks);
    add(STAGE_JOIN, {});
    return subs;
}

std::string arraySpec(const std::vector<int>& tasks)
{
    std::string s;
    for (size_t i = 0; i < tasks.size();)
    {
        size_t j = i;
        while (j + 1 < tasks.size() && tasks[j + 1] == tasks[j] + 1)
            j++;
        s += (s.empty() ? "" : ",") + std::to_string(tasks[i]) +
             (j > i ? "-" + std::to_string(tasks[j]) : std::string());
        i = j + 1;
    }
    return s;
}

std::vector<std::string> sbatchArgs(const Submission& s, const std::string& dependency)
{
    std::vector<std::string> a = {"--parsable"};
    if (!s.arrayTasks.empty())
        a.push_back("--array=" + arraySpec(s.arrayTasks));
    if (!dependency.empty())
    {
        a.push_back("--dependency=afterok:" + dependency);
        // A failed stage cancels the ones waiting for it (else they pend for ever).
        a.push_back("--kill-on-invalid-dep=yes");
    }
    a.push_back(s.script);
    return a;
}

namespace {

// `name` of farm/ written completely into `staging` (errors name its place in farmDir).
void writeStaged(const fs::path& staging, const fs::path& farmDir, const std::string& name,
                 const std::string& text, bool executable)
{
    const std::string shown = (farmDir / name).string();
    try
    {
        cv::augocc::writeFileAtomically((staging / name).string(), text, executable);
    }
    catch (const cv::Exception& e)
    {
        // The staging folder is an implementation detail: name the file the user will see.
        std::string msg = e.err;
        const std::string tmp = (staging / name).string();
        for (size_t at; (at = msg.find(tmp)) != std::string::npos;)
            msg.replace(at, tmp.size(), shown);
        CV_Error(cv::Error::StsError, msg);
    }
}

void commitStaged(const fs::path& staging, const fs::path& farmDir, const std::string& name)
{
    std::error_code ec;
    fs::rename(staging / name, farmDir / name, ec);
    if (ec)
        CV_Error(cv::Error::StsError,
                 (farmDir / name).string() + ": cannot be written: " + ec.message());
}

} // namespace

std::string planText(const Plan& plan, const Options& o)
{
    cv::FileStorage fsw(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
    fsw << "description" << "augocc farm: the shot's workflow (augocc farm resume reads it)";
    fsw << "name" << plan.shot.name << "input" << plan.shot.input << "masks" << plan.shot.masks
        << "scene" << plan.shot.scene << "out_dir" << plan.shot.outDir;
    fsw << "frame_count" << plan.frameCount << "fps" << plan.fps;
    fsw << "chunks" << "[";
    for (const auto& c : plan.chunks)
        fsw << "[:" << c.first << c.second << "]";
    fsw << "]";
    fsw << "objects" << "[";
    for (const std::string& obj : plan.objects)
        fsw << obj;
    fsw << "]";
    fsw << "partition" << o.partition << "account" << o.account << "time" << o.timeLimit
        << "augocc" << o.augocc << "photo_refine" << (int)o.photoRefine;
    fsw << "setup" << "[";
    for (const std::string& l : o.setup)
        fsw << l;
    fsw << "]";
    return fsw.releaseAndGetString();
}

void writePlan(const Plan& plan, const Options& o)
{
    writeWorkflow(plan, {}, o);
}

void writeWorkflow(const Plan& plan, const std::vector<Script>& scripts, const Options& o)
{
    const fs::path outDir(plan.shot.outDir), farmDir = outDir / "farm";
    // Folders made here go again on failure: the outermost one that did not exist.
    fs::path made;
    for (fs::path d = farmDir / "logs"; !d.empty() && !fs::exists(d); d = d.parent_path())
        made = d;
    // Every file is written into a staging folder first; only when all are complete are they
    // renamed into farm/ (renames need no space): a full disk leaves the workflow as it was.
    const fs::path staging = outDir / cv::format(".farm.tmp%d", (int)getpid());
    std::error_code ec;
    try
    {
        fs::create_directories(farmDir / "logs", ec);
        if (ec)
            CV_Error(cv::Error::StsError,
                     (farmDir / "logs").string() + ": cannot create folder: " + ec.message());
        fs::remove_all(staging, ec);
        fs::create_directory(staging, ec);
        if (ec)
            CV_Error(cv::Error::StsError,
                     farmDir.string() + ": cannot create its staging folder: " + ec.message());
        for (const Script& s : scripts)
            writeStaged(staging, farmDir, s.file, s.text, true);
        writeStaged(staging, farmDir, "plan.yml", planText(plan, o), false);
        for (const Script& s : scripts)
            commitStaged(staging, farmDir, s.file);
        commitStaged(staging, farmDir, "plan.yml");
        fs::remove_all(staging, ec);
    }
    catch (...)
    {
        fs::remove_all(staging, ec);
        if (!made.empty())
            fs::remove_all(made, ec);
        throw;
    }
}

void readPlan(const std::string& outDir, Plan& plan, Options& o)
{
    const std::string path = (fs::path(outDir) / "farm" / "plan.yml").string();
    if (!fs::is_regular_file(path))
        throw UsageError("--out-dir " + outDir + ": no farm/plan.yml (submit it with augocc "
                         "farm first)");
    cv::FileStorage f(path, cv::FileStorage::READ);
    auto str = [&](const char* key) {
        const cv::FileNode n = f[key];
        if (!n.isString())
            throw UsageError(path + ": key '" + key + "' missing or not a string");
        return n.string();
    };
    plan.shot.name = str("name");
    plan.shot.input = str("input");
    plan.shot.masks = str("masks");
    plan.shot.scene = str("scene");
    plan.shot.outDir = str("out_dir");
    if (!f["frame_count"].isInt() || !f["fps"].isReal() || !f["chunks"].isSeq())
        throw UsageError(path + ": frame_count, fps or chunks missing");
    plan.frameCount = (int)f["frame_count"];
    plan.fps = (double)f["fps"];
    plan.chunks.clear();
    for (const cv::FileNode& c : f["chunks"])
    {
        if (!c.isSeq() || c.size() != 2)
            throw UsageError(path + ": chunks: each entry must be [first, end]");
        plan.chunks.push_back({(int)c[0], (int)c[1]});
    }
    if (plan.chunks.empty())
        throw UsageError(path + ": chunks is empty");
    if (!f["objects"].isSeq() || f["objects"].size() == 0)
        throw UsageError(path + ": key 'objects' missing or empty (a plan of an augocc farm "
                         "before the per-object clone jobs: run augocc farm on the shot again)");
    plan.objects.clear();
    for (const cv::FileNode& n : f["objects"])
    {
        if (!n.isString() || n.string().empty())
            throw UsageError(path + ": objects: each entry must be an object name");
        plan.objects.push_back(n.string());
    }
    o.partition = str("partition");
    o.account = str("account");
    o.timeLimit = str("time");
    o.augocc = str("augocc");
    o.photoRefine = (int)f["photo_refine"] != 0;
    o.setup.clear();
    for (const cv::FileNode& l : f["setup"])
        o.setup.push_back(l.string());
}

} // namespace farm
} // namespace augocc_cli
