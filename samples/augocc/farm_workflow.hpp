// augocc farm: the Slurm workflow of a shot as data and script text, without Slurm (doc/farm.md).
// cmd_farm.cpp reads the shots, writes these scripts and calls sbatch; the tests check the text.

#ifndef AUGOCC_FARM_WORKFLOW_HPP
#define AUGOCC_FARM_WORKFLOW_HPP

#include <string>
#include <utility>
#include <vector>

namespace augocc_cli {
namespace farm {

//! One shot: absolute paths on the shared filesystem (the shots file's are resolved against its
//! folder). `scene` may be empty: the chunks then render mattes only.
struct Shot
{
    std::string name;    //!< job name part: the out-dir's folder name
    std::string input;   //!< video, image folder or printf pattern
    std::string masks;   //!< key-frame masks, MASKS/<object>/%04d.png
    std::string scene;   //!< scene.yml, or empty
    std::string outDir;  //!< every output of the shot, and outDir/farm/ (scripts, logs)
};

//! Options of the generated workflow (flags of augocc farm).
struct Options
{
    int chunkFrames = 0;          //!< frames per chunk (0: from `chunks`)
    int chunks = 0;               //!< number of chunks (0: from `chunkFrames`)
    std::string partition;        //!< #SBATCH --partition (empty: the cluster's default)
    std::string account;          //!< #SBATCH --account (empty: none)
    std::string timeLimit;        //!< #SBATCH --time (empty: the partition's default)
    std::string augocc = "augocc";  //!< the augocc binary as the nodes see it (path or on PATH)
    std::vector<std::string> setup;  //!< shell lines run first in every job (module load ...)
    bool photoRefine = true;      //!< clone --input (photo-consistency carving), as augocc run
};

//! A shot with what the submitting machine found out: frame count, frame rate, chunks, objects.
struct Plan
{
    Shot shot;
    int frameCount = 0;
    double fps = 25;
    std::vector<std::pair<int, int> > chunks;  //!< [first, end) frame ranges, in order
    //! The objects of the masks folder (its subfolders, sorted) when the shot was submitted:
    //! task i of the clone array builds objects[i].
    std::vector<std::string> objects;
};

//! The stages of a shot's workflow, in dependency order.
enum Stage
{
    STAGE_SFM = 0,    //!< tracking and camera recovery, one job
    STAGE_CLONE = 1,  //!< per-object clone parts, a job array over Plan::objects
    STAGE_MERGE = 2,  //!< the parts merged and finished into clones.yml.gz, one job
    STAGE_CHUNKS = 3, //!< mattes or composite per frame chunk, a job array
    STAGE_JOIN = 4    //!< the chunks joined, the video encoded
};

//! The name of a stage in job names and messages (sfm, clone, merge, chunks, join).
const char* stageName(Stage stage);

//! The partial clones file of `object`, relative to the out-dir: clones.parts/<object>.yml.gz.
std::string clonePartFile(const std::string& object);

//! A generated script: file name inside outDir/farm/ and its text.
struct Script
{
    Stage stage;
    std::string file;
    std::string text;
};

/** @brief Reads a shots file: one shot a line, `input masks scene out-dir` separated by blanks
(`-` for no scene), `#` starts a comment, relative paths are relative to the file's folder.
Throws UsageError naming the file and line on a malformed line, on two shots with one out-dir
name (their job names would clash) or on no shot at all. */
std::vector<Shot> readShotsFile(const std::string& path);

//! `dir`'s last folder name made safe for a Slurm job name ([A-Za-z0-9._-], others '_').
std::string shotName(const std::string& outDir);

/** @brief Frames [0, frameCount) cut into consecutive chunks: `chunkFrames` each (the last one
shorter), or `chunks` of near-equal size (the first ones one frame longer); exactly one of them
is positive. Never an empty chunk (fewer chunks when frames are few). */
std::vector<std::pair<int, int> > splitFrames(int frameCount, int chunkFrames, int chunks);

//! The chunk's folder, relative to the out-dir: chunks/FIRST-END (%04d each, END exclusive).
std::string chunkDir(const std::pair<int, int>& chunk);

//! `s` quoted for bash: as is when only safe characters, else in single quotes.
std::string shellQuote(const std::string& s);

//! The five scripts of a shot (sfm, clone array, merge, chunks array, join), in stage order.
std::vector<Script> makeScripts(const Plan& plan, const Options& options);

//! What a shot's outputs say is finished (files found in the out-dir).
struct Status
{
    bool sfm = false;                //!< tracks.yml and reconstruction.yml
    std::vector<bool> cloneParts;    //!< per object of the plan: its clones.parts file
    bool clone = false;              //!< clones.yml.gz (the parts merged)
    std::vector<bool> chunks;        //!< per chunk: its outputs complete
    bool join = false;               //!< mattes/ (+ composite/ and composite.mp4 with a scene)
};

//! The finished stages of `plan`, from the files in its out-dir.
Status readStatus(const Plan& plan);

//! One sbatch call: the script, the array indices (empty: not an array) and the stage it
//! waits for (-1: none, else the index of that earlier submission in the list).
struct Submission
{
    Stage stage;
    std::string script;          //!< absolute path
    std::vector<int> arrayTasks;
    int dependsOn = -1;
};

/** @brief The sbatch calls that finish a shot: only the stages not finished, the clone array
over the objects without a part only and the chunk array over the unfinished chunks only (no
clone array nor merge once clones.yml.gz is there); each waits (afterok) for the nearest earlier
stage submitted. */
std::vector<Submission> planSubmissions(const Plan& plan, const Status& progress);

//! The sbatch argument list of `s` (after "sbatch"), `dependency` the job id waited for or "".
std::vector<std::string> sbatchArgs(const Submission& s, const std::string& dependency);

//! Slurm's array syntax for sorted task ids: 0-3,5,7-8.
std::string arraySpec(const std::vector<int>& tasks);

//! Writes / reads outDir/farm/plan.yml (what resume needs; cv::FileStorage YAML).
//! plan.yml's text: what `augocc farm resume` reads back (readPlan).
std::string planText(const Plan& plan, const Options& options);
/** @brief Writes outDir/farm/: the scripts (mode 0755) and plan.yml, all or nothing: each is
written completely into a staging folder and only then renamed into place, so a full disk or an
unwritable folder is a cv::Exception naming the file with nothing new left behind (folders made
for it removed again); logs/ is made for the jobs. */
void writeWorkflow(const Plan& plan, const std::vector<Script>& scripts, const Options& options);
//! writeWorkflow() with no scripts: plan.yml alone.
void writePlan(const Plan& plan, const Options& options);
void readPlan(const std::string& outDir, Plan& plan, Options& options);

} // namespace farm
} // namespace augocc_cli

#endif
