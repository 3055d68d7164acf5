// Ensembles (issue #14): grids over several parameters, shards merged into the single-process CSV,
// and sweeps that resume after kill -9 with no row lost or duplicated.
#include "cli_helpers.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <sys/wait.h>
#include <thread>
#include <vector>

namespace bodypoint {
namespace {

namespace fs = std::filesystem;
using test::leftovers;
using test::read;
using test::run_cli;
using test::spawn;

/// The lines of a sweep CSV with the wall_s cell of every data row blanked: the one column that
/// differs between two runs of the same sweep. Header lines are kept whole.
std::vector<std::string> without_wall(const std::string& csv) {
  std::vector<std::string> lines;
  std::stringstream ss(csv);
  std::size_t wall = std::string::npos;
  for (std::string line; std::getline(ss, line);) {
    if (line.empty() || line[0] == '#' || wall == std::string::npos) {
      if (!line.empty() && line[0] != '#') {  // the column names
        std::stringstream cs(line);
        std::size_t k = 0;
        for (std::string c; std::getline(cs, c, ','); ++k)
          if (c == "wall_s") wall = k;
      }
      lines.push_back(line);
      continue;
    }
    std::vector<std::string> cells;
    std::stringstream cs(line);
    for (std::string c; std::getline(cs, c, ',');) cells.push_back(c);
    if (wall < cells.size()) cells[wall] = "W";
    std::string joined;
    for (std::size_t k = 0; k < cells.size(); ++k) joined += (k ? "," : "") + cells[k];
    lines.push_back(joined);
  }
  return lines;
}

/// The data rows (not comments, not the column names).
std::vector<std::string> data_rows(const std::vector<std::string>& lines) {
  std::vector<std::string> rows;
  bool names = true;
  for (const std::string& l : lines) {
    if (l.empty() || l[0] == '#') continue;
    if (names) names = false;
    else rows.push_back(l);
  }
  return rows;
}

using test::TempDir;

TEST(Grid, RowsAreEveryCombinationInOrderAndEqualOneParameterSweeps) {
  const std::string fixed = " --methods lp-y4,thesis-fr4 --h 5e-3 --steps 2000 --threads 2";
  const auto grid = run_cli("sweep --grid d=10,50 --grid Kx=-2:2:2" + fixed);
  ASSERT_EQ(grid.code, 0) << grid.err;
  const auto rows = data_rows(without_wall(grid.out));
  ASSERT_EQ(rows.size(), 2u * 3u * 2u);  // d values x Kx values x methods
  EXPECT_EQ(grid.out.rfind("d,Kx,method,", 0), 0u) << "the column names are the first line";
  for (const std::string d : {"10", "50"}) {
    const auto line = run_cli("sweep --param Kx --values -2,0,2 --d " + d + fixed);
    ASSERT_EQ(line.code, 0) << line.err;
    const auto expected = data_rows(without_wall(line.out));
    ASSERT_EQ(expected.size(), 6u);
    for (std::size_t k = 0; k < expected.size(); ++k)  // d slowest: its block of rows, d prefixed
      EXPECT_EQ(rows[(d == "10" ? 0 : 6) + k], d + "," + expected[k]);
  }
}

TEST(Grid, LogAxesAndListsAndBadGrids) {
  const auto log = run_cli("sweep --grid h=log:1e-3:1e-1:3 --grid d=20,40 --t-end 1 --methods rk4");
  ASSERT_EQ(log.code, 0) << log.err;
  const auto rows = data_rows(without_wall(log.out));
  ASSERT_EQ(rows.size(), 6u);
  EXPECT_EQ(rows[0].substr(0, 9), "0.001,20,");
  EXPECT_EQ(rows[5].substr(0, 7), "0.1,40,");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--grid q=1,2", "unknown parameter 'q'"},
      {"--grid d=1,2 --grid d=3", "names d twice"},
      {"--grid d", "give NAME=FROM:TO:STEP"},
      {"--grid d=1:2", "give NAME=FROM:TO:STEP"},
      {"--grid d=5:1:1", "never reaches --to"},
      {"--grid d=log:0:1:3", "--log needs --from and --to finite and > 0"},
      {"--grid d=log:1:10:1.5", "--grid d points"},
      {"--grid d=1,x", "'x' is not a number"},
      {"--grid d=1,2 --param L --values 1", "give --grid or --param"},
      {"--grid d=10 --grid B=0.5,1.5", "d = 10, B = 1.5: body: D = m J - B^2 must be > 0"},
      {"--grid d=10 --shard 3/2 --out x.rows", "K <= N"},
      {"--grid d=10 --shard 1/2", "--shard needs --out"},
      {"--grid d=10 --resume", "--resume needs --out"},
  };
  test::expect_refused("sweep --steps 10 ", cases);
}

constexpr const char* kShardSweep = "sweep --grid d=10,30,50 --grid L=100,200 --methods lp-y4,rk4,thesis-euler --steps 2000";

/// The three shards of kShardSweep at h = 5e-3, each written with its own thread count into dir.
std::vector<std::string> write_shards(const fs::path& dir) {
  std::vector<std::string> files;
  for (int k = 1; k <= 3; ++k) {
    files.push_back((dir / ("s" + std::to_string(k) + ".rows")).string());
    const auto r = run_cli(std::string(kShardSweep) + " --h 5e-3 --shard " + std::to_string(k) + "/3 --threads " + std::to_string(k) + " --out " + files.back());
    EXPECT_EQ(r.code, 0) << r.err;
  }
  return files;
}

/// merge refused its inputs: exit code 2, the reason, nothing on standard output.
void expect_merge_refused(const test::CliResult& r, const std::string& reason) {
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(reason), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST(Shards, MergedShardsEqualTheSingleProcessCsv) {
  const TempDir dir("bp_shards");
  const auto single = run_cli(std::string(kShardSweep) + " --h 5e-3 --threads 1");
  ASSERT_EQ(single.code, 0) << single.err;
  const std::vector<std::string> files = write_shards(dir.path);
  const auto merged = run_cli("merge --input " + files[2] + " " + files[0] + " " + files[1]);
  ASSERT_EQ(merged.code, 0) << merged.err;
  EXPECT_EQ(without_wall(merged.out), without_wall(single.out));
  EXPECT_EQ(data_rows(without_wall(merged.out)).size(), 18u);
}

TEST(Shards, MergeRefusesAMissingARepeatedOrAForeignShard) {
  const TempDir dir("bp_shards_sets");
  const std::vector<std::string> files = write_shards(dir.path);
  expect_merge_refused(run_cli("merge --input " + files[0] + " " + files[2]), "the shards hold 12 of 18 rows");
  expect_merge_refused(run_cli("merge --input " + files[0] + " " + files[1] + " " + files[2] + " " + files[1]), "is in both");
  const std::string other = (dir.path / "other.rows").string();
  ASSERT_EQ(run_cli(std::string(kShardSweep) + " --h 4e-3 --shard 2/3 --out " + other).code, 0);
  expect_merge_refused(run_cli("merge --input " + files[0] + " " + other + " " + files[2]),
                       "is a shard of another sweep than '" + files[0] + "' (the parameters, methods or accuracy differ)");
  // The same sweep over a scene file edited between its shards says so (it blamed "parameters, methods or build").
  const fs::path scene = dir.path / "scene.toml";
  fs::copy_file(fs::path(BODYPOINT_SOURCE_DIR) / "scenes" / "two-centres.toml", scene);
  const std::string over_scene = "sweep --scene " + scene.string() + " --param centre2.A --values -1,-2 --methods lp-y4 --h 1e-2 --steps 10";
  const std::string first = (dir.path / "s1.rows").string(), second = (dir.path / "s2.rows").string();
  ASSERT_EQ(run_cli(over_scene + " --shard 1/2 --out " + first).code, 0);
  std::ofstream(scene, std::ios::app) << "# edited\n";
  ASSERT_EQ(run_cli(over_scene + " --shard 2/2 --out " + second).code, 0);
  expect_merge_refused(run_cli("merge --input " + first + " " + second), "(the scene file was edited)");
  expect_merge_refused(run_cli("merge --input " + std::string(BODYPOINT_SOURCE_DIR) + "/README.md"),
                       "is not a bodypoint rows file");
  // Inputs that are not regular files are refused at once (a FIFO blocked, /dev/zero read 4 GB).
  ASSERT_EQ(::mkfifo((dir.path / "fifo").c_str(), 0644), 0);
  expect_merge_refused(run_cli("merge --input " + (dir.path / "fifo").string()), "is not a regular file");
}

TEST(Shards, MergeRefusesAnEditedShard) {
  const TempDir dir("bp_shards_edited");
  const std::vector<std::string> files = write_shards(dir.path);
  // One flipped digit in a row: its checksum no longer matches, and merge refuses the shard.
  std::string text = read(files[1]);
  const std::size_t at = text.find("\nR\t") + 8;
  text[at] = text[at] == '1' ? '2' : '1';
  std::ofstream(files[1], std::ios::trunc) << text;
  expect_merge_refused(run_cli("merge --input " + files[0] + " " + files[1] + " " + files[2]), "torn or corrupt");
  // An edited header line (issue #24: headers carried no checksum and were merged as edited).
  std::string header = read(files[2]);
  header.replace(header.find("\nH\t") + 3, 1, "X");
  const fs::path edited = dir.path / "edited.rows";
  std::ofstream(edited) << header;
  expect_merge_refused(run_cli("merge --input " + files[0] + " " + edited.string()), "torn or corrupt");
  // A shard whose header lines were removed (issue #40: merged into a CSV without its column names).
  std::string headless;
  {
    std::istringstream lines(read(files[0]));
    for (std::string l; std::getline(lines, l);)
      if (l.rfind("H\t", 0) != 0) headless += l + "\n";
  }
  const fs::path no_header = dir.path / "headless.rows";
  std::ofstream(no_header) << headless;
  expect_merge_refused(run_cli("merge --input " + no_header.string() + " " + files[1] + " " + files[2]), "has no header lines");
}

TEST(Shards, MergeRefusesTwoDifferentRowsForOneTask) {
  const TempDir dir("bp_shards_dup");
  const std::vector<std::string> files = write_shards(dir.path);
  // Two different rows under one task index: a file edited or mixed (the first was kept silently).
  std::string both = read(files[0]);
  const std::size_t rec = both.find("\nR\t") + 1;
  const std::string line = both.substr(rec, both.find('\n', rec) + 1 - rec);
  both += line;  // the same record twice is one row
  const fs::path dup = dir.path / "dup.rows";
  std::ofstream(dup) << both;
  const auto same = run_cli("merge --input " + dup.string() + " " + files[2]);
  EXPECT_EQ(same.err.find("two different rows"), std::string::npos) << same.err;
  ASSERT_EQ(run_cli(std::string(kShardSweep) + " --h 3e-3 --shard 1/3 --out " + (dir.path / "o.rows").string()).code, 0);
  const std::string foreign_text = read(dir.path / "o.rows");
  const std::size_t frec = foreign_text.find("\nR\t") + 1;
  std::ofstream(dup, std::ios::app) << foreign_text.substr(frec, foreign_text.find('\n', frec) + 1 - frec);
  expect_merge_refused(run_cli("merge --input " + dup.string() + " " + files[1] + " " + files[2]), "two different rows for task");
}

TEST(Shards, OneShardOfOneIsARowsFileToo) {
  // --shard 1/1 wrote a plain CSV that merge refused.
  const TempDir dir("bp_shard1");
  const auto single = run_cli(std::string(kShardSweep) + " --h 5e-3 --threads 1");
  const std::string rows = (dir.path / "all.rows").string();
  ASSERT_EQ(run_cli(std::string(kShardSweep) + " --h 5e-3 --shard 1/1 --out " + rows).code, 0);
  const auto merged = run_cli("merge --input " + rows);
  ASSERT_EQ(merged.code, 0) << merged.err;
  EXPECT_EQ(without_wall(merged.out), without_wall(single.out));
}

/// A sweep of 50 rows of ~10 ms each on 2 threads: long enough to be killed in the middle.
std::vector<std::string> resume_sweep(const fs::path& out, bool resume) {
  std::vector<std::string> a{"sweep", "--grid", "d=10:50:10", "--grid", "Kx=-2:2:1", "--methods", "lp-y4,rk4", "--h",
                             "1e-3", "--steps", "100000", "--threads", "2", "--out", out.string()};
  if (resume) a.push_back("--resume");
  return a;
}

std::string joined(const std::vector<std::string>& args) {
  std::string s;
  for (const auto& a : args) s += (s.empty() ? "" : " ") + a;
  return s;
}

std::size_t journal_records(const fs::path& journal) {
  const std::string j = read(journal);
  std::size_t rows = 0;
  for (std::size_t p = j.find("\nR\t"); p != std::string::npos; p = j.find("\nR\t", p + 1)) ++rows;
  return rows;
}

/// Kill delays drawn between these bounds land anywhere from before the first row to after the last
/// (the whole sweep takes ~0.3-0.6 s on 2 cores).
constexpr int kMinKillMs = 20, kMaxKillMs = 600;
constexpr int kKills = 4;

/// Kills `sweep(out, resume)` at random points up to kKills times, resumes it, and compares its CSV with
/// an uninterrupted run's (wall times aside): no row lost, duplicated or changed.
void kill_and_resume(const char* name, const std::function<std::vector<std::string>(const fs::path&, bool)>& sweep,
                     std::size_t expected_rows) {
  const TempDir dir(name);
  const fs::path ref = dir.path / "ref.csv", out = dir.path / "r.csv", journal = dir.path / "r.csv.journal";
  ASSERT_EQ(run_cli(joined(sweep(ref, false))).code, 0);
  const unsigned seed = std::random_device{}();
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> delay(kMinKillMs, kMaxKillMs);
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::size_t records = 0;
  for (int k = 0; k < kKills && !fs::exists(out); ++k) {
    const pid_t pid = spawn(sweep(out, k > 0), dir.path / "err.txt");
    ASSERT_GT(pid, 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(delay(rng)));
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
    if (!fs::exists(journal)) continue;
    EXPECT_GE(journal_records(journal), records) << "a resumed run keeps every row the journal had";
    records = journal_records(journal);
  }
  if (!fs::exists(out)) {  // an interrupted output is not restarted by accident
    const auto again = run_cli(joined(sweep(out, false)));
    EXPECT_NE(again.err.find("add --resume"), std::string::npos) << again.err;
    std::ofstream(journal, std::ios::app) << "R\t3\t10,-2,lp-y4,torn";  // a torn last record: dropped, run again
  }
  if (fs::exists(journal)) {  // killed at any point, even between the CSV's commit and the journal's removal
    const auto done = run_cli(joined(sweep(out, true)));
    ASSERT_EQ(done.code, 0) << done.err;
  }
  EXPECT_EQ(without_wall(read(out)), without_wall(read(ref)));
  EXPECT_EQ(data_rows(without_wall(read(out))).size(), expected_rows);
  EXPECT_EQ(leftovers(dir.path, "r.csv"), std::vector<std::string>{"r.csv"}) << "no journal, lock or temporary is left";
}

TEST(Resume, SurvivesKill9AtRandomPointsWithNoRowLostOrDuplicated) { kill_and_resume("bp_resume", resume_sweep, 50); }

/// A scene file's sweep: the second centre's charge of scenes/two-centres.toml over 50 values in the
/// accuracy mode, both bodies (100 rows; ~0.5 s on 2 cores).
std::vector<std::string> charge_sweep(const fs::path& out, bool resume) {
  std::vector<std::string> a{"sweep", "--scene", std::string(BODYPOINT_SOURCE_DIR) + "/scenes/two-centres.toml", "--param",
                             "centre2.A", "--from", "-2", "--to", "-0.04", "--points", "50", "--methods", "logh-kl6",
                             "--accuracy", "1e-12", "--t-end", "60", "--threads", "2", "--out", out.string()};
  if (resume) a.push_back("--resume");
  return a;
}

TEST(Resume, ASceneFilesChargeSweptWithAnAccuracySurvivesKill9) { kill_and_resume("bp_resume_scene", charge_sweep, 100); }

TEST(Resume, AJournalOfAnotherSweepIsRefused) {
  const TempDir dir("bp_resume_other");
  const fs::path out = dir.path / "r.csv";
  std::ofstream(dir.path / "r.csv.journal") << "#bodypoint-rows 1 key=0123456789abcdef tasks=50\n";
  const auto r = run_cli("sweep --grid d=10:50:10 --grid Kx=-2:2:1 --methods lp-y4,rk4 --h 1e-3 --steps 10 --out " +
                         out.string() + " --resume");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("belongs to another sweep"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  // An empty journal: its run was killed between creating it and writing its first line; it holds no
  // row and is started afresh, with or without --resume.
  for (const char* resume : {"", " --resume"}) {
    std::ofstream(dir.path / "r.csv.journal").close();
    const auto fresh = run_cli("sweep --grid d=10:50:10 --grid Kx=-2:2:1 --methods lp-y4,rk4 --h 1e-3 --steps 10 --out " +
                               out.string() + resume);
    EXPECT_EQ(fresh.code, 0) << resume << ": " << fresh.err;
    EXPECT_TRUE(fs::exists(out));
    EXPECT_FALSE(fs::exists(dir.path / "r.csv.journal"));
    fs::remove(out);
  }
}

}  // namespace
}  // namespace bodypoint
