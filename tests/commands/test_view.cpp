// `bodypoint view`: the page it writes (size, decimation, closest approach kept, embedded data) and
// its refusals. The page in a real browser is tested by experiments/viewer/test/browser_test.mjs.
#include "cli_helpers.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace bodypoint {
namespace {

namespace fs = std::filesystem;
using test::run_cli;

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The numbers of the first JSON array called `name` after position `from` in text.
std::vector<double> array_after(const std::string& text, const std::string& name, std::size_t from = 0) {
  const std::size_t at = text.find("\"" + name + "\": [", from);
  if (at == std::string::npos) return {};
  const std::size_t begin = text.find('[', at) + 1, end = text.find(']', begin);
  std::vector<double> out;
  std::stringstream ss(text.substr(begin, end - begin));
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(std::stod(item));
  return out;
}

/// Skips when the binary was built without the viewer's npm packages (the build stays usable then).
bool have_viewer() {
  const test::CliResult r = run_cli("view --help");
  return r.code == 0 && run_cli("view --steps 10 --out /dev/null/x.html").err.find("built without") == std::string::npos;
}

// The frames kept for a page: --frames at equal arc length plus the closest approach (and the last state).
constexpr std::size_t kExtraFrames = 2;
// "a 10^6-step run still makes a file under a few MB" (issue #11): 3 MB at the default 3000 frames.
constexpr double kMaxPageBytes = 3e6;

TEST(View, MillionStepRunMakesASmallPageWithTheClosestApproachKept) {
  if (!have_viewer()) GTEST_SKIP() << "built without the viewer's script";
  const fs::path out = test::temp_path("bp_view_1e6.html");
  fs::remove(out);
  // The close encounter (d = 0.05) at h = 8e-5: 10^6 steps.
  const auto r = run_cli("view --Kz 0.1 --d 0.05 --h 8e-5 --steps 1000000 --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string page = read(out);
  EXPECT_LT(static_cast<double>(page.size()), kMaxPageBytes);
  EXPECT_EQ(page.rfind("<!doctype html>", 0), 0u);
  // Nothing is loaded from elsewhere (the browser test also fails on any network request).
  EXPECT_EQ(page.find("<script src"), std::string::npos);
  EXPECT_EQ(page.find("<link"), std::string::npos);
  const std::vector<double> t = array_after(page, "t");
  ASSERT_GE(t.size(), 3000u);
  EXPECT_LE(t.size(), 3000u + kExtraFrames);
  EXPECT_TRUE(std::is_sorted(t.begin(), t.end()));
  EXPECT_DOUBLE_EQ(t.front(), 0.0);
  EXPECT_NEAR(t.back(), 80.0, 1e-9);
  // The closest approach is one of the frames.
  const std::size_t closest = page.find("\"closest\": {\"t\": ");
  ASSERT_NE(closest, std::string::npos);
  const double tc = std::stod(page.substr(closest + 17));
  EXPECT_GT(tc, 20.0);
  EXPECT_TRUE(std::any_of(t.begin(), t.end(), [&](double x) { return std::abs(x - tc) <= 1e-9 * 80.0; }))
      << "closest approach at t = " << tc << " is not a frame";
  // Positions: three per frame.
  EXPECT_EQ(array_after(page, "R").size(), 3 * t.size());
  fs::remove(out);
}

TEST(View, CompareAndSeveralBodiesEmbedEveryTrack) {
  if (!have_viewer()) GTEST_SKIP() << "built without the viewer's script";
  const fs::path out = test::temp_path("bp_view_cmp.html");
  const auto r = run_cli("view --scene " + std::string(BODYPOINT_SOURCE_DIR) +
                         "/scenes/two-centres.toml --method lp-verlet --h 0.01 --t-end 60 --compare logh-y4 "
                         "--compare-h 0.05 --frames 200 --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string page = read(out);
  std::size_t tracks = 0;
  for (std::size_t at = page.find("\"frames\": {"); at != std::string::npos; at = page.find("\"frames\": {", at + 1)) {
    ++tracks;
    const std::vector<double> t = array_after(page, "t", at);
    EXPECT_LE(t.size(), 200u + kExtraFrames);
    EXPECT_NEAR(t.back(), 60.0, 1e-9) << "--compare ends where the first run ends";
  }
  EXPECT_EQ(tracks, 4u) << "2 bodies x 2 runs";
  EXPECT_NE(page.find("\"method\": \"logh-y4\""), std::string::npos);
  fs::remove(out);
}

TEST(View, BadInputIsRefusedWithoutAPage) {
  if (!have_viewer()) GTEST_SKIP() << "built without the viewer's script";
  const fs::path dir = test::temp_path("bp_view_bad");
  fs::create_directories(dir);
  const fs::path out = dir / "v.html";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--frames 3", "--frames must be between"},
      {"--frames 100000000", "--frames must be between"},
      {"--max-mb 0.1", "above --max-mb"},
      {"--max-mb nan", "--max-mb must be"},
      {"--compare-h 0.1", "--compare-h needs --compare"},
      {"--compare rk9", "unknown method 'rk9'"},
      {"--compare lp-y4 --compare-h -1", "--compare-h must be"},
      // A material point dropped onto an attracting centre: the state turns non-finite.
      {"--method thesis-euler --A 5 --B 0 --K1 2 --L 1 --d 0 --Kz 0 --Kx 0 --h 0.5", "non-finite"},
      {"--m 0", "mass m must be > 0"},
  };
  for (const auto& [args, fragment] : cases) {
    const auto r = run_cli("view --steps 100 " + args + " --out " + out.string());
    EXPECT_NE(r.code, 0) << args;
    EXPECT_NE(r.err.find(fragment), std::string::npos) << args << " -> " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << " -> " << r.err;
    EXPECT_FALSE(fs::exists(out)) << args << " left a page";
    for (const auto& e : fs::directory_iterator(dir))
      EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << args << ": temporary left behind";
  }
  // An output name that is not .html would hold HTML under an image's name.
  const auto png = run_cli("view --steps 10 --out " + (dir / "v.png").string());
  EXPECT_NE(png.code, 0);
  EXPECT_NE(png.err.find("ending in .html"), std::string::npos) << png.err;
  EXPECT_FALSE(fs::exists(dir / "v.png"));
  const auto unwritable = run_cli("view --steps 10 --out /nonexistent-dir/v.html");
  EXPECT_NE(unwritable.code, 0);
  EXPECT_NE(unwritable.err.find("cannot write output file"), std::string::npos) << unwritable.err;
  fs::remove_all(dir);
}

// --event marks each located hit on the page; --quiet writes the page without a word; the header states
// the located closest approach. A bad event is refused in one line.
TEST(View, EventsAreLocatedAndQuietWritesNothingToStdout) {
  if (!have_viewer()) GTEST_SKIP() << "built without the viewer's script";
  const fs::path out = test::temp_path("bp_view_events.html");
  fs::remove(out);
  const auto r = run_cli("view --quiet --event x=0 --event r=50 --t-end 60 --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "");
  const std::string page = read(out);
  // The thesis body crosses x = 0 once near its closest approach and r = 50 on the way in and out.
  std::size_t x0 = 0, r50 = 0;
  for (std::size_t at = page.find("\"label\": \"x=0\""); at != std::string::npos; at = page.find("\"label\": \"x=0\"", at + 1)) ++x0;
  for (std::size_t at = page.find("\"label\": \"r=50\""); at != std::string::npos; at = page.find("\"label\": \"r=50\"", at + 1)) ++r50;
  EXPECT_EQ(x0, 1u);
  EXPECT_EQ(r50, 2u);
  const auto bad = run_cli("view --event r=-1 --steps 10 --out " + out.string());
  EXPECT_NE(bad.code, 0);
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
  fs::remove(out);
}

// Defaults are shown as the shortest text that reads back (0.7, not 0.69999999999999996).
TEST(View, HelpShowsDefaultsAsTheyWereWritten) {
  for (const std::string cmd : {"simulate", "sweep", "view", "timing", "work-precision", "study"}) {
    const auto r = run_cli(cmd + " --help");
    EXPECT_EQ(r.code, 0) << cmd;
    if (cmd != "work-precision" && cmd != "study") {
      EXPECT_NE(r.out.find("--B arg (=0.7)"), std::string::npos) << cmd;
    }
    EXPECT_EQ(r.out.find("99999999"), std::string::npos) << cmd << ": " << r.out;
  }
}

}  // namespace
}  // namespace bodypoint
