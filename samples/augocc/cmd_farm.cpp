// augocc farm: writes a shot's (or a shots file's) Slurm workflow and submits it with sbatch:
// track+sfm -> a clone job array over objects -> merge -> a job array over frame chunks -> join,
// chained with afterok;
// `augocc farm resume` submits what is not finished (doc/farm.md). The scripts and the plan
// come from farm_workflow.cpp; this file reads the inputs, writes the files and runs sbatch.

#include "cli_common.hpp"
#include "farm_workflow.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sys/stat.h>
#include <sys/wait.h>

#include <opencv2/augocc.hpp>

namespace fs = std::filesystem;

namespace augocc_cli {

namespace {

using namespace farm;

struct FarmCliOptions
{
    std::string shots, input, masks, scene, outDir, sbatch = "sbatch";
    Options workflow;
    bool noPhotoRefine = false;
    bool dryRun = false;
    std::vector<std::string> resumeDirs;
    std::string resumeShots;
};

// The shots of the command line: a shots file or the one shot of --input ... --out-dir.
std::vector<Shot> shotsOf(const FarmCliOptions& o)
{
    if (!o.shots.empty())
    {
        if (!o.input.empty() || !o.masks.empty() || !o.scene.empty() || !o.outDir.empty())
            throw UsageError("--shots: give a shots file or --input/--masks/--out-dir, not both");
        requireFile("--shots", o.shots);
        return readShotsFile(o.shots);
    }
    if (o.input.empty() || o.masks.empty() || o.outDir.empty())
        throw UsageError("give --shots FILE, or --input, --masks and --out-dir (and --scene) for "
                         "one shot");
    Shot s;
    s.input = fs::absolute(o.input).lexically_normal().string();
    s.masks = fs::absolute(o.masks).lexically_normal().string();
    s.scene = o.scene.empty() ? std::string() : fs::absolute(o.scene).lexically_normal().string();
    s.outDir = fs::absolute(o.outDir).lexically_normal().string();
    if (s.outDir.find_first_of(" \t\n%") != std::string::npos)
        throw UsageError("--out-dir " + s.outDir + ": an out-dir for the farm may not hold "
                         "blanks or '%' (Slurm's #SBATCH lines cannot quote them)");
    s.name = shotName(s.outDir);
    return {s};
}

// Everything the jobs will read is checked here, before anything is submitted: the frames
// (count and rate for the chunks and the video), the masks, the scene file.
Plan planShot(const Shot& s, const Options& w)
{
    if (s.input.find('%') == std::string::npos)
        requireFile("input", s.input);
    requireFile("masks", s.masks);
    cv::Ptr<cv::augocc::FrameSource> src = cv::augocc::FrameSource::open(s.input);
    const cv::augocc::ObjectMasks masks = cv::augocc::readMasks(s.masks, src->size());
    if (masks.empty())
        throw UsageError("masks " + s.masks + ": no object folder with masks");
    for (const auto& obj : masks)
        for (const auto& fm : obj.second)
            if (fm.first >= src->count())
                throw UsageError(cv::format("masks %s: object %s has a mask for frame %d but %s "
                                            "has %d frames", s.masks.c_str(), obj.first.c_str(),
                                            fm.first, s.input.c_str(), src->count()));
    if (!s.scene.empty())
    {
        requireFile("scene", s.scene);
        cv::augocc::readScene(s.scene);
    }
    Plan p;
    p.shot = s;
    // Read here, at submission: the clone array needs its size (doc/farm.md).
    for (const auto& obj : masks)
        p.objects.push_back(obj.first);
    p.frameCount = src->count();
    p.fps = src->fps();
    p.chunks = splitFrames(p.frameCount, w.chunkFrames, w.chunks);
    return p;
}

// argv run without a shell; its standard output, or UsageError with its exit status.
std::string runCapture(const std::vector<std::string>& argv)
{
    std::string cmd;
    for (const std::string& a : argv)
        cmd += (cmd.empty() ? "" : " ") + shellQuote(a);
    FILE* p = popen(cmd.c_str(), "r");
    if (!p)
        throw UsageError(argv[0] + ": cannot be run");
    std::string out;
    char buf[256];
    for (size_t n; (n = fread(buf, 1, sizeof buf, p)) > 0;)
        out.append(buf, n);
    const int status = pclose(p);
    if (status != 0)
        throw UsageError(cmd + ": failed (exit status " +
                         std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")");
    return out;
}

std::string siblingTool(const std::string& sbatch, const std::string& tool)
{
    const fs::path p(sbatch);
    return p.has_parent_path() ? (p.parent_path() / tool).string() : tool;
}

// Jobs of the shot still queued or running (a resume must not run a chunk twice at once).
void checkNothingQueued(const Plan& plan, const std::string& sbatch)
{
    std::string names;
    for (Stage st : {STAGE_SFM, STAGE_CLONE, STAGE_MERGE, STAGE_CHUNKS, STAGE_JOIN})
        names += (names.empty() ? "" : ",") + ("augocc-" + plan.shot.name + "-") + stageName(st);
    const std::string q = runCapture({siblingTool(sbatch, "squeue"), "--noheader",
                                      "--format=%i", "--name=" + names});
    if (q.find_first_not_of(" \n") != std::string::npos)
        throw UsageError("shot " + plan.shot.outDir + ": jobs of it are still queued or running ("
                         + q.substr(0, q.find_last_not_of(" \n") + 1) + "): wait for them or "
                         "scancel them, then resume");
}

// Submits (or, dry, prints) what is not finished of `plan`, the scripts in its farm/ folder.
void submit(const Globals& g, const Plan& plan, const std::string& sbatch, bool dryRun)
{
    const Status progress = readStatus(plan);
    const std::vector<Submission> subs = planSubmissions(plan, progress);
    if (subs.empty())
    {
        info(g, "shot " + plan.shot.outDir + ": finished, nothing to submit");
        return;
    }
    for (const Submission& s : subs)
        requireFile("script", s.script);
    if (dryRun)
    {
        // A shell snippet a user can run instead (each job id kept when a later one needs it).
        std::cout << "# submission of shot " << plan.shot.name << " (--dry-run: not submitted)\n";
        for (size_t i = 0; i < subs.size(); i++)
        {
            bool needed = false;
            for (const Submission& later : subs)
                needed = needed || later.dependsOn == (int)i;
            const std::string dep =
                subs[i].dependsOn < 0 ? std::string()
                                      : "\"$" + plan.shot.name + "_" + std::to_string(
                                            subs[i].dependsOn) + "\"";
            std::string line = shellQuote(sbatch);
            for (const std::string& a : sbatchArgs(subs[i], dep.empty() ? "" : "@DEP@"))
                line += " " + (a.find("@DEP@") != std::string::npos
                                   ? a.substr(0, a.find("@DEP@")) + dep
                                   : shellQuote(a));
            std::string var = plan.shot.name + "_" + std::to_string(i);
            for (char& c : var)
                if (!std::isalnum((unsigned char)c))
                    c = '_';
            std::cout << (needed ? var + "=$(" + line + ")" : line) << "\n";
        }
        return;
    }
    checkNothingQueued(plan, sbatch);
    std::vector<std::string> ids;
    std::string summary;
    for (const Submission& s : subs)
    {
        const std::string dep = s.dependsOn < 0 ? std::string() : ids[s.dependsOn];
        std::vector<std::string> argv = {sbatch};
        for (const std::string& a : sbatchArgs(s, dep))
            argv.push_back(a);
        const std::string out = runCapture(argv);
        const size_t end = out.find_first_not_of("0123456789");
        const std::string id = out.substr(0, end);
        if (id.empty())
            throw UsageError(sbatch + ": printed no job id for " + s.script + " ('" + out + "')");
        ids.push_back(id);
        summary += cv::format("%s%s job %s", summary.empty() ? "" : ", ",
                              fs::path(s.script).stem().string().c_str(), id.c_str());
        if (!s.arrayTasks.empty())
            summary += std::string(s.stage == STAGE_CLONE ? " (objects " : " (chunks ") +
                       arraySpec(s.arrayTasks) + ")";
    }
    info(g, "shot " + plan.shot.outDir + ": submitted " + summary);
}

void runFarm(const Globals& g, const FarmCliOptions& o)
{
    Options w = o.workflow;
    w.photoRefine = !o.noPhotoRefine;
    if ((w.chunkFrames > 0) == (w.chunks > 0))
    {
        if (w.chunkFrames > 0)
            throw UsageError("--chunk-frames, --chunks: give one of them");
        w.chunks = 4;
    }
    const std::vector<Shot> shots = shotsOf(o);
    std::vector<Plan> plans;
    for (const Shot& s : shots)
        plans.push_back(planShot(s, w));
    for (const Plan& p : plans)
    {
        const fs::path farmDir = fs::path(p.shot.outDir) / "farm";
        const std::vector<Script> scripts = makeScripts(p, w);
        writeWorkflow(p, scripts, w);  // all or nothing
        if (o.dryRun)
            for (const Script& s : scripts)
                std::cout << "# ==> " << (farmDir / s.file).string() << " <==\n" << s.text << "\n";
        submit(g, p, o.sbatch, o.dryRun);
    }
}

void runResume(const Globals& g, const FarmCliOptions& o)
{
    std::vector<std::string> dirs = o.resumeDirs;
    if (!o.resumeShots.empty())
    {
        requireFile("--shots", o.resumeShots);
        for (const Shot& s : readShotsFile(o.resumeShots))
            dirs.push_back(s.outDir);
    }
    if (dirs.empty())
        throw UsageError("resume: give --out-dir DIR (repeatable) or --shots FILE");
    for (const std::string& d : dirs)
    {
        Plan p;
        Options w;
        readPlan(d, p, w);
        submit(g, p, o.sbatch, o.dryRun);
    }
}

} // namespace

void registerFarm(CLI::App& app, Globals& g)
{
    auto o = std::make_shared<FarmCliOptions>();
    CLI::App* sub = app.add_subcommand("farm", "write and submit (sbatch) the Slurm workflow of "
                                       "one shot or a shots file: track+sfm, clone per "
                                       "object, merge, frame chunks, join (doc/farm.md)");
    sub->add_option("--shots", o->shots, "shots file: a line 'input masks scene out-dir' per "
                    "shot ('-' for no scene, paths relative to the file)");
    sub->add_option("--input", o->input, "one shot: video, image folder or printf pattern");
    sub->add_option("--masks", o->masks, "one shot: key-frame masks MASKS/<object>/%04d.png");
    sub->add_option("--scene", o->scene, "one shot: scene.yml (without it the chunks write "
                    "mattes only)");
    sub->add_option("--out-dir", o->outDir, "one shot: its outputs, and farm/ (scripts, logs)");
    sub->add_option("--chunk-frames", o->workflow.chunkFrames, "frames per chunk job")
        ->check(CLI::PositiveNumber);
    sub->add_option("--chunks", o->workflow.chunks, "number of chunk jobs (default 4 when "
                    "--chunk-frames is not given)")->check(CLI::PositiveNumber);
    sub->add_option("--partition", o->workflow.partition, "Slurm partition (#SBATCH "
                    "--partition)");
    sub->add_option("--account", o->workflow.account, "Slurm account (#SBATCH --account)");
    sub->add_option("--time", o->workflow.timeLimit, "time limit of each job (#SBATCH --time, "
                    "e.g. 02:00:00)");
    sub->add_option("--augocc", o->workflow.augocc, "the augocc binary on the nodes (default: "
                    "augocc on their PATH)");
    sub->add_option("--setup", o->workflow.setup, "a shell line every job runs first, e.g. "
                    "'module load opencv' (repeatable)");
    sub->add_flag("--no-photo-refine", o->noPhotoRefine, "clones from the silhouettes alone");
    sub->add_option("--sbatch", o->sbatch, "the sbatch command (squeue beside it)")
        ->capture_default_str();
    sub->add_flag("--dry-run", o->dryRun, "write and print the scripts and the sbatch calls; "
                  "submit nothing");
    CLI::App* resume = sub->add_subcommand("resume", "submit what is not finished of shots "
                                           "already written by augocc farm: failed chunks only, "
                                           "a finished output is never redone");
    resume->add_option("--out-dir", o->resumeDirs, "a shot's out-dir (repeatable)");
    resume->add_option("--shots", o->resumeShots, "or every shot of a shots file");
    resume->add_option("--sbatch", o->sbatch, "the sbatch command (squeue beside it)")
        ->capture_default_str();
    resume->add_flag("--dry-run", o->dryRun, "print the sbatch calls; submit nothing");
    resume->callback([&g, o]() { runResume(g, *o); });
    sub->callback([&g, o, sub, resume]() {
        if (!sub->got_subcommand(resume))
            runFarm(g, *o);
    });
}

} // namespace augocc_cli
