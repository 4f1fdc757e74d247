// SPDX-License-Identifier: LGPL-2.1-or-later
// Many clips in one process (defocus --batch MANIFEST): the manifest, the share of it one process
// takes (--shard I/N, or a Slurm array task's index), each clip's report, written last and
// atomically, and what a rerun does again: every clip whose report does not say done. The
// rendering itself stays in defocus.cpp; nothing here needs GL.
//
// Manifest, one clip per line; blank lines and lines starting with '#' are skipped; both forms
// may be mixed. Relative paths are taken from the manifest's folder.
//   TSV:        INPUT <TAB> DEPTH <TAB> OUTPUT [<TAB> OPTIONS]...
//               DEPTH empty or '-' for none (TUM folders); each OPTIONS column holds per-clip
//               options separated by spaces, e.g. "--focus 1.2 --f-number 1.4"
//   JSON lines: {"input": "...", "depth": "...", "output": "...", "focus": 1.2, "near-field": false}
//               "depth" absent, null, "" or "-" for none, as in TSV; every key other than
//               input/depth/output is an option: a string or number is its value, true gives
//               the flag, false its --no- form (or nothing where there is none)
// Per-clip options are the lens, quality and output options of clipOptions(); the others
// (--batch, --shard, --report-dir, --egl-device, ...) are the whole run's and are refused here.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <istream>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace defocus::batch {

/// A manifest that cannot be used; the message starts "MANIFEST:LINE:" where a line is at fault.
class ManifestError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct Clip {
    std::size_t index = 0; ///< position among the manifest's clips, 0-based: what --shard splits
    std::size_t line = 0;  ///< line in the manifest, 1-based, for messages
    std::filesystem::path input;
    std::filesystem::path depth; ///< empty: none
    std::filesystem::path output;
    std::string outputAsWritten; ///< OUTPUT as the manifest spells it: names the report in --report-dir
    /// Per-clip command-line options, e.g. {"--focus", "1.2", "--no-near-field"}.
    std::vector<std::string> options;
};

/// The options a manifest line may set (without the leading "--").
const std::vector<std::string_view>& clipOptions();

/// Parses a manifest; `name` is used in messages and `base` resolves relative paths. Throws
/// ManifestError for a malformed line, an option a clip may not set, a missing input or output,
/// and two clips with the same output.
std::vector<Clip> parseManifest(std::istream& in, const std::string& name, const std::filesystem::path& base);
/// Reads the manifest file (relative paths from its folder).
std::vector<Clip> readManifest(const std::filesystem::path& file);

/// This process's share: clip k belongs to shard k % count (round robin, so that long clips
/// that sit together in the manifest spread over the shards).
struct Shard {
    std::size_t index = 0; ///< 0-based, < count
    std::size_t count = 1;
};
/// Parses "I/N" (0 <= I < N); nullopt when malformed.
std::optional<Shard> parseShard(std::string_view text);
/// The shard a Slurm array task is: (SLURM_ARRAY_TASK_ID - SLURM_ARRAY_TASK_MIN) / STEP of
/// SLURM_ARRAY_TASK_COUNT. nullopt when not in an array task; throws ManifestError when the
/// array's indices are not a range (--array=1,5,9 would leave shards unrun). `getenv` is for tests.
std::optional<Shard> shardFromSlurm(const std::function<const char*(const char*)>& getenv);
/// The clips of `all` that belong to `shard`, in manifest order.
std::vector<Clip> select(const std::vector<Clip>& all, Shard shard);

/// Where a clip's report goes: beside its output as OUTPUT.report.json (a folder output "dir/"
/// gives dir.report.json), or, with `reportDir`, there, named after OUTPUT as the manifest
/// spells it with '/' as '_'.
std::filesystem::path reportPath(const Clip& clip, const std::filesystem::path& reportDir);
/// Throws ManifestError when two clips' reports would be the same file.
void checkReportPaths(const std::vector<Clip>& clips, const std::filesystem::path& reportDir);
/// True when the clip has a report, done or failed.
bool hasReport(const std::filesystem::path& report);
/// True when the clip's report says "status": "done": an earlier run did it, a rerun skips it.
/// A failed report is a failure until the clip is done: a rerun tries it again.
bool isDone(const std::filesystem::path& report);
/// Writes `report` to a temporary file beside `path`, flushes it to disk and renames it over
/// `path`, so that `path` is either absent or complete. Creates the folder. Throws
/// std::runtime_error naming the file when it cannot.
void writeReport(const std::filesystem::path& path, const nlohmann::json& report);

/// What makes outputs differ between machines, besides the renderer: defocus's version and git
/// commit, OpenCV's version (it encodes the videos), the host and the compiler.
nlohmann::json buildInfo();

/// What one clip gave: its exit status (ExitStatus.hpp) and what its report says besides the
/// fields runBatch() adds (frames in and out, settings, renderer, timings, the error).
struct ClipOutcome {
    int status = 0;
    nlohmann::json report = nlohmann::json::object();
};
/// Runs clips on one worker; made on the worker's own thread (it owns a GL context there). It
/// says a clip's error once itself (runBatch names the clip after it), writes nothing under the
/// clip's output name unless the clip is done, and throws only what it did not say.
using ClipRunner = std::function<ClipOutcome(const Clip&)>;

struct BatchOptions {
    std::filesystem::path reportDir; ///< empty: reports beside the outputs
    bool redo = false;               ///< run clips that have a report again
    std::size_t inFlight = 1;        ///< clips processed at once, one worker thread each
    Shard shard;                     ///< for the reports
};

/// Runs `clips` (this process's shard) on `options.inFlight` workers, each made by
/// `makeWorker(worker)` on its own thread; a worker that cannot be made (no GL) throws. Clips
/// whose report says done are skipped unless `redo`; those whose report says failed are tried
/// again (the input may be there now) and counted as done or failed. After each clip: status 0
/// (done) or 1 (bad input) writes its report, last; any other status (stopped, GL lost) writes
/// none, so a rerun does it again. No new clip starts once `stopStatus()` is not 0 or once a
/// clip or worker gave 75. Returns the batch's status: the stop's (130, 143) when stopped, else
/// 75 when GL failed, else 1 when a clip of this run failed, else 0.
int runBatch(const std::vector<Clip>& clips, const BatchOptions& options,
             const std::function<ClipRunner(std::size_t worker)>& makeWorker,
             const std::function<int()>& stopStatus);

} // namespace defocus::batch
