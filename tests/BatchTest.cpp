// SPDX-License-Identifier: LGPL-2.1-or-later
// defocus --batch without GL: the manifest (TSV and JSON lines, per-clip options, what it
// refuses), the shard a process takes (--shard, Slurm array variables), report paths, the atomic
// report and what a rerun does again.
#include <atomic>
#include <chrono>
#include <fstream>
#include <thread>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include <gtest/gtest.h>

#include "samples/Batch.hpp"
#include "tests/TestSupport.hpp"

namespace defocus::batch {
namespace {

namespace fs = std::filesystem;

std::vector<Clip> parse(const std::string& text, const fs::path& base = "/data")
{
    std::istringstream in(text);
    return parseManifest(in, "m.tsv", base);
}

std::string errorOf(const std::string& text)
{
    try {
        parse(text);
    } catch (const ManifestError& error) {
        return error.what();
    }
    return "no error";
}

// Defect: columns read in the wrong order, '-' taken as a depth file, the options column dropped
// or not split into words, or relative paths not taken from the manifest's folder.
TEST(Manifest, TsvLinesGiveInputDepthOutputAndOptions)
{
    const auto clips = parse("# input depth output options\n"
                             "\n"
                             "rgb/a\tdepth/a\tout/a.mp4\t--focus 1.2 --f-number=1.4\t--no-near-field\n"
                             "tum\t-\t/abs/b/\n");
    ASSERT_EQ(clips.size(), 2u);
    EXPECT_EQ(clips[0].input, fs::path("/data/rgb/a"));
    EXPECT_EQ(clips[0].depth, fs::path("/data/depth/a"));
    EXPECT_EQ(clips[0].output, fs::path("/data/out/a.mp4"));
    EXPECT_EQ(clips[0].line, 3u);
    EXPECT_EQ(clips[0].index, 0u);
    EXPECT_EQ(clips[0].options, (std::vector<std::string>{"--focus", "1.2", "--f-number=1.4", "--no-near-field"}));
    EXPECT_EQ(clips[1].input, fs::path("/data/tum"));
    EXPECT_TRUE(clips[1].depth.empty());
    EXPECT_EQ(clips[1].output, fs::path("/abs/b/"));
    EXPECT_EQ(clips[1].index, 1u);
}

// Defect: JSON values not turned into the options the command line takes (a number losing its
// digits, false giving the flag instead of its --no- form), or null keys not ignored.
TEST(Manifest, JsonLinesGiveTheSameOptions)
{
    const auto clips = parse(R"({"input": "tum", "output": "o.mp4", "focus": 1.25, "quality": "high",)"
                             R"( "near-field": false, "highlight-sprites": true, "always-on": false, "depth": null})"
                             "\n");
    ASSERT_EQ(clips.size(), 1u);
    EXPECT_TRUE(clips[0].depth.empty());
    const std::set<std::string> options(clips[0].options.begin(), clips[0].options.end());
    EXPECT_EQ(options, (std::set<std::string>{"--focus=1.25", "--quality=high", "--no-near-field",
                                              "--highlight-sprites"}));
    // Defect: "-" taken as a depth file named '-' in JSON, although it means none in TSV.
    EXPECT_TRUE(parse(R"({"input": "tum", "depth": "-", "output": "o.mp4"})")[0].depth.empty());
    EXPECT_EQ(parse(R"({"input": "tum", "depth": "d", "output": "o.mp4"})")[0].depth, fs::path("/data/d"));
}

// Defect: a bad line accepted, so the batch fails (or writes somewhere wrong) hours later, or an
// error that does not say which line.
TEST(Manifest, BadLinesAreRefusedWithTheirLine)
{
    EXPECT_EQ(errorOf("a\tb\n"), "m.tsv:1: expected INPUT<TAB>DEPTH<TAB>OUTPUT[<TAB>OPTIONS], got 2 columns");
    EXPECT_EQ(errorOf("#\na\t-\t\n"), "m.tsv:2: no output");
    EXPECT_EQ(errorOf("\t-\to\n"), "m.tsv:1: empty INPUT column");
    EXPECT_EQ(errorOf("a\t-\to\t--focus\n"), "m.tsv:1: '--focus' needs a value");
    EXPECT_EQ(errorOf("a\t-\to\tfocus 1\n"), "m.tsv:1: 'focus' is not an option (options start with --)");
    EXPECT_NE(errorOf("a\t-\to\t--shard 0/2\n").find("m.tsv:1: '--shard' cannot be set per clip"),
              std::string::npos);
    EXPECT_NE(errorOf("{\"input\": \"a\", \"output\": \"o\", \"batch\": \"x\"}\n")
                  .find("m.tsv:1: \"batch\" cannot be set per clip"),
              std::string::npos);
    EXPECT_EQ(errorOf("{\"input\": \"a\", \"output\": \"o\", \"near-field\": 1}"),
              "m.tsv:1: \"near-field\" is a flag: true or false");
    EXPECT_EQ(errorOf("{\"input\": \"a\", \"output\": \"o\", \"focus\": true}"),
              "m.tsv:1: \"focus\" takes a value, not true/false");
    EXPECT_EQ(errorOf("{\"input\": \"a\", \"output\": 3}"), "m.tsv:1: \"output\" must be a string");
    EXPECT_NE(errorOf("{\"input\": \"a\",\n").find("m.tsv:1: not valid JSON"), std::string::npos);
    EXPECT_EQ(errorOf("a\t-\tout/x.mp4\nb\t-\tout/./x.mp4\n"), "m.tsv:2: output 'out/./x.mp4' is also line 1's");
    EXPECT_EQ(errorOf("# nothing\n"), "m.tsv: no clips (one line per clip: INPUT<TAB>DEPTH<TAB>OUTPUT, or JSON)");
}

// Defect: a manifest path read from the current folder instead of the manifest's.
TEST(Manifest, FileResolvesPathsFromItsFolder)
{
    const fs::path dir = test::scratchDir("BatchManifestFile");
    std::ofstream(dir / "m.tsv") << "clip\t-\tout/clip.mp4\n";
    const auto clips = readManifest(dir / "m.tsv");
    ASSERT_EQ(clips.size(), 1u);
    EXPECT_EQ(clips[0].input, dir / "clip");
    EXPECT_EQ(clips[0].output, dir / "out/clip.mp4");
    EXPECT_THROW(readManifest(dir / "missing.tsv"), ManifestError);
}

// Defect: shards that overlap or leave a clip out (every clip must be in exactly one), or a
// malformed --shard accepted.
TEST(Shards, EveryClipIsInExactlyOneShard)
{
    std::string text;
    for (int i = 0; i < 11; ++i)
        text += fmt::format("in{}\t-\tout{}.mp4\n", i, i);
    const auto clips = parse(text);
    for (std::size_t count : {1u, 2u, 3u, 11u, 16u}) {
        std::map<std::size_t, int> seen;
        for (std::size_t index = 0; index < count; ++index)
            for (const Clip& clip : select(clips, Shard{index, count}))
                ++seen[clip.index];
        EXPECT_EQ(seen.size(), clips.size()) << count << " shards";
        for (const auto& [clip, times] : seen)
            EXPECT_EQ(times, 1) << "clip " << clip << " of " << count << " shards";
    }
    const auto shard = parseShard("2/5");
    ASSERT_TRUE(shard);
    EXPECT_EQ(shard->index, 2u);
    EXPECT_EQ(shard->count, 5u);
    for (const char* bad : {"5/5", "1/0", "1", "a/2", "-1/2", "1/2/3", "/2", "1/"})
        EXPECT_FALSE(parseShard(bad)) << bad;
}

// Defect: the Slurm array index used as the shard without subtracting the array's first index
// (--array=1-4 would skip shard 0 and ask for shard 4 of 4), or a list of indices taken as a range.
TEST(Shards, SlurmArrayVariablesGiveTheShard)
{
    std::map<std::string, std::string> env;
    const auto getenv = [&](const char* name) -> const char* {
        const auto found = env.find(name);
        return found == env.end() ? nullptr : found->second.c_str();
    };
    EXPECT_FALSE(shardFromSlurm(getenv));
    env = {{"SLURM_ARRAY_TASK_ID", "4"}, {"SLURM_ARRAY_TASK_MIN", "1"}, {"SLURM_ARRAY_TASK_MAX", "4"},
           {"SLURM_ARRAY_TASK_COUNT", "4"}};
    auto shard = shardFromSlurm(getenv);
    ASSERT_TRUE(shard);
    EXPECT_EQ(shard->index, 3u);
    EXPECT_EQ(shard->count, 4u);
    env = {{"SLURM_ARRAY_TASK_ID", "6"}, {"SLURM_ARRAY_TASK_MIN", "0"}, {"SLURM_ARRAY_TASK_MAX", "8"},
           {"SLURM_ARRAY_TASK_STEP", "2"}, {"SLURM_ARRAY_TASK_COUNT", "5"}};
    shard = shardFromSlurm(getenv);
    ASSERT_TRUE(shard);
    EXPECT_EQ(shard->index, 3u);
    EXPECT_EQ(shard->count, 5u);
    // --array=1,5,9: three tasks, min 1, max 9, step unset.
    env = {{"SLURM_ARRAY_TASK_ID", "5"}, {"SLURM_ARRAY_TASK_MIN", "1"}, {"SLURM_ARRAY_TASK_MAX", "9"},
           {"SLURM_ARRAY_TASK_COUNT", "3"}};
    EXPECT_THROW(shardFromSlurm(getenv), ManifestError);
    env = {{"SLURM_ARRAY_TASK_ID", "1"}};
    EXPECT_THROW(shardFromSlurm(getenv), ManifestError);
}

// Defect: reports of different clips landing on one file (one clip's report would mark another
// done), or a folder output's report put inside the folder.
TEST(Reports, PathsAreBesideTheOutputOrInTheReportFolder)
{
    const auto clips = parse("a\t-\tout/a.mp4\nb\t-\tout/b/\nc\t-\t./x/c.png\n");
    EXPECT_EQ(reportPath(clips[0], {}), fs::path("/data/out/a.mp4.report.json"));
    EXPECT_EQ(reportPath(clips[1], {}), fs::path("/data/out/b.report.json"));
    EXPECT_EQ(reportPath(clips[1], "/r"), fs::path("/r/out_b.report.json"));
    EXPECT_EQ(reportPath(clips[2], "/r"), fs::path("/r/x_c.png.report.json"));
    EXPECT_NO_THROW(checkReportPaths(clips, "/r"));
    const auto clash = parse("a\t-\tout/a_b.mp4\nb\t-\tout_a/b.mp4\n");
    EXPECT_NO_THROW(checkReportPaths(clash, {}));
    EXPECT_THROW(checkReportPaths(clash, "/r"), ManifestError);
}

// Defect: a report written in place (a reader, or a rerun after a kill, would see a half-written
// file as "done"), or its temporary file left behind.
TEST(Reports, WriteIsAtomicAndLeavesNoTemporary)
{
    const fs::path dir = test::scratchDir("BatchReports");
    const fs::path path = dir / "sub" / "clip.report.json";
    EXPECT_FALSE(hasReport(path));
    writeReport(path, {{"frames_out", 3}});
    EXPECT_TRUE(hasReport(path));
    writeReport(path, {{"frames_out", 4}});
    std::ifstream in(path);
    EXPECT_EQ(nlohmann::json::parse(in)["frames_out"], 4);
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir / "sub"))
        ++files;
    EXPECT_EQ(files, 1u);
    std::ofstream(dir / "plain") << "x";
    EXPECT_THROW(writeReport(dir / "plain" / "r.json", {}), std::runtime_error);
}

// Defect: the build's commit or version missing from the report (outputs could not be traced to
// the code that made them).
TEST(Reports, BuildInfoNamesVersionAndCommit)
{
    const auto info = buildInfo();
    EXPECT_EQ(info["version"], DEFOCUS_VERSION);
    EXPECT_FALSE(info["commit"].get<std::string>().empty());
    EXPECT_FALSE(info["opencv"].get<std::string>().empty());
    EXPECT_FALSE(info["host"].get<std::string>().empty());
}

/// A manifest of `n` clips writing into `dir`, and a fake worker that gives the status `statusOf`
/// says and, as the sinks do, writes the clip's output file only when it is done.
struct FakeBatch {
    fs::path dir;
    std::vector<Clip> clips;
    std::map<std::size_t, int> statusOf; // clip index -> status (default 0)
    std::atomic<int> runs{0};
    std::atomic<int> stop{0};
    std::atomic<int> inFlight{0}, mostInFlight{0};

    FakeBatch(const std::string& name, int n) : dir(test::scratchDir(name))
    {
        std::string text;
        for (int i = 0; i < n; ++i)
            text += fmt::format("in{}\t-\tout/clip{}.mp4\n", i, i);
        std::istringstream in(text);
        clips = parseManifest(in, "m.tsv", dir);
    }
    int run(std::size_t workers = 1, bool redo = false)
    {
        BatchOptions options;
        options.inFlight = workers;
        options.redo = redo;
        return runBatch(
            clips, options,
            [this](std::size_t) -> ClipRunner {
                return [this](const Clip& clip) {
                    const int now = ++inFlight;
                    for (int seen = mostInFlight; now > seen && !mostInFlight.compare_exchange_weak(seen, now);)
                        ;
                    ++runs;
                    std::this_thread::sleep_for(std::chrono::milliseconds(20));
                    --inFlight;
                    ClipOutcome outcome;
                    const auto found = statusOf.find(clip.index);
                    outcome.status = found == statusOf.end() ? 0 : found->second;
                    const fs::path output = clip.output.has_filename() ? clip.output : clip.output.parent_path();
                    if (!fs::is_directory(output.parent_path()))
                        outcome.status = 1; // as the sinks refuse an output whose folder is missing
                    if (outcome.status == 0)
                        std::ofstream(clip.output) << "frames";
                    if (outcome.status == 143)
                        stop = 143; // as the signal handler would
                    outcome.report["frames_out"] = 3;
                    return outcome;
                };
            },
            [this] { return stop.load(); });
    }
    bool reported(std::size_t clip) const { return hasReport(reportPath(clips[clip], {})); }
};

// Defect: a rerun after preemption doing finished clips again (or not doing unfinished ones), or
// a report written for a clip whose output is not complete.
TEST(RunBatch, StopLeavesUnfinishedClipsToTheRerunAndSkipsDoneOnes)
{
    FakeBatch batch("BatchRunStop", 4);
    batch.statusOf[1] = 143; // SIGTERM while clip 1 is in hand
    EXPECT_EQ(batch.run(), 143);
    EXPECT_TRUE(batch.reported(0));
    EXPECT_FALSE(batch.reported(1));
    EXPECT_FALSE(batch.reported(2)) << "no clip starts after the stop";
    EXPECT_EQ(batch.runs, 2);
    std::ifstream in(reportPath(batch.clips[0], {}));
    const auto report = nlohmann::json::parse(in);
    EXPECT_EQ(report["status"], "done");
    EXPECT_EQ(report["exit_status"], 0);
    EXPECT_EQ(report["frames_out"], 3);
    EXPECT_EQ(report["clip"]["manifest_line"], 1);
    EXPECT_EQ(report["build"]["version"], DEFOCUS_VERSION);

    batch.statusOf.clear();
    batch.stop = 0;
    batch.runs = 0;
    EXPECT_EQ(batch.run(), 0);
    EXPECT_EQ(batch.runs, 3) << "the rerun does clips 1-3 only";
    for (std::size_t i = 0; i < 4; ++i)
        EXPECT_TRUE(batch.reported(i)) << i;
    batch.runs = 0;
    EXPECT_EQ(batch.run(1, true), 0);
    EXPECT_EQ(batch.runs, 4) << "--redo does them all";
}

// Defect: a bad clip stopping the batch or retried forever (it gets a report saying it failed
// and the batch goes on, exiting 1), or a GL failure taken for a bad clip (it must exit 75, retry,
// with no report, and start no more clips).
TEST(RunBatch, BadClipsAreReportedAndGlFailuresAreRetried)
{
    FakeBatch bad("BatchRunBad", 3);
    bad.statusOf[0] = 1;
    EXPECT_EQ(bad.run(), 1);
    EXPECT_TRUE(bad.reported(0));
    EXPECT_TRUE(bad.reported(2));
    std::ifstream in(reportPath(bad.clips[0], {}));
    EXPECT_EQ(nlohmann::json::parse(in)["status"], "failed");

    FakeBatch gl("BatchRunGl", 3);
    gl.statusOf[1] = 75;
    EXPECT_EQ(gl.run(), 75);
    EXPECT_TRUE(gl.reported(0));
    EXPECT_FALSE(gl.reported(1));
    EXPECT_FALSE(gl.reported(2));

    FakeBatch noContext("BatchRunNoContext", 2);
    BatchOptions options;
    EXPECT_EQ(runBatch(
                  noContext.clips, options,
                  [](std::size_t) -> ClipRunner { throw std::runtime_error("no headless OpenGL 4.5 context"); },
                  [] { return 0; }),
              75);
    EXPECT_FALSE(noContext.reported(0));
}

// Defect: a clip whose report says failed taken as done by a rerun (skipped, exit 0, although its
// input may be there now), or a retried clip not counted in the rerun's status.
TEST(RunBatch, ClipsThatFailedAreTriedAgainByARerunUntilDone)
{
    FakeBatch batch("BatchRunRetry", 3);
    batch.statusOf[1] = 1; // its input is missing
    EXPECT_EQ(batch.run(), 1);
    EXPECT_TRUE(batch.reported(1));
    EXPECT_FALSE(isDone(reportPath(batch.clips[1], {})));
    EXPECT_TRUE(isDone(reportPath(batch.clips[0], {})));

    batch.runs = 0;
    EXPECT_EQ(batch.run(), 1) << "still missing: the rerun fails again";
    EXPECT_EQ(batch.runs, 1) << "the rerun tries the failed clip, and only it";

    batch.statusOf.clear(); // the input is there now
    batch.runs = 0;
    EXPECT_EQ(batch.run(), 0);
    EXPECT_EQ(batch.runs, 1);
    EXPECT_TRUE(isDone(reportPath(batch.clips[1], {})));
    batch.runs = 0;
    EXPECT_EQ(batch.run(), 0);
    EXPECT_EQ(batch.runs, 0) << "all done: nothing to do";
}

// Defect: a manifest whose outputs go into folders not made yet (out/scene3/clip.mp4) failing every
// clip, as the command line refuses a missing folder; the batch makes the folders it names.
TEST(RunBatch, TheFoldersAManifestNamesAreMade)
{
    FakeBatch batch("BatchRunFolders", 1);
    std::istringstream in("in0\t-\tout/scene/a/clip.mp4\nin1\t-\tout/scene/b/frames/\n");
    batch.clips = parseManifest(in, "m.tsv", batch.dir);
    EXPECT_EQ(batch.run(), 0);
    EXPECT_TRUE(fs::is_regular_file(batch.dir / "out/scene/a/clip.mp4"));
    EXPECT_TRUE(fs::is_directory(batch.dir / "out/scene/b"));
}

// Defect: --jobs 2 running one clip at a time, or two workers taking the same clip.
TEST(RunBatch, TwoWorkersRunTwoClipsAtOnceEachOnce)
{
    FakeBatch batch("BatchRunTwo", 6);
    EXPECT_EQ(batch.run(2), 0);
    EXPECT_EQ(batch.runs, 6);
    EXPECT_EQ(batch.mostInFlight, 2);
    for (std::size_t i = 0; i < 6; ++i)
        EXPECT_TRUE(batch.reported(i)) << i;
}

} // namespace
} // namespace defocus::batch
