// What auto's step search costs with each composition table it may choose, measured (issue #55): the data
// behind lib/api/auto.cpp's kMeasuredCost (from 1e-4 to 1e-8, where auto takes it).
//
// For each named scene (auto's family for it: logH, TTL or Lie-Poisson) and each TOL, the search of every
// candidate table runs as auto runs its choice (verified about several centres only: auto_verifies), and
// its force evaluations (the whole search), its delivered error against the long-double reference and its
// estimate are printed. Then, per TOL, each table's geometric mean over the scenes of its cost over the
// cheapest table's on that scene: the row auto's table takes. A table that refuses TOL on a scene (round-off
// floor, budget) has no mean at that TOL. Honesty: runs whose delivered error exceeds TOL, and estimates more
// than 3x below an error above 1e-12. Deterministic (force evaluations, not times): any machine, any load.
//
//     build/bin/auto_costs [--scenes thesis,close,long,two-centres,three-centres] [--tols 1e-4,...,1e-12]
#include "bodypoint/adaptive/tolerance.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/reference.hpp"
#include "bodypoint/scenes.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using namespace bodypoint;

namespace {

/// The tables auto may choose (lib/api/auto.cpp), in its order.
const std::vector<std::string> kTables = {"verlet", "y4", "pefrl", "bm4", "kl6", "mcl8", "kl8"};
/// An estimate this many times below a delivered error above kRoundingLevel is not honest (the estimate
/// ladder's criterion, issue #56: below 1e-12 an error is the run's rounding).
constexpr double kLowEstimate = 3.0;
constexpr double kRoundingLevel = 1e-12;

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string x; std::getline(in, x, ',');)
    if (!x.empty()) out.push_back(x);
  return out;
}

/// One search: its force evaluations, its error against the reference and its estimate (NaN: refused).
struct Cell {
  double evals = NAN, err = NAN, est = NAN;
};
/// By (TOL text, TOL), by "scene/table".
using Cells = std::map<std::pair<std::string, double>, std::map<std::string, Cell>>;
struct Tally {
  int missed = 0, low = 0, delivered = 0;
};

/// Every table of auto's chosen family searched at every TOL on every scene, each printed as it is made.
Cells measure(const std::string& scenes, const std::string& tols, Tally& tally) {
  Cells cells;
  for (const std::string& name : split(scenes)) {
    const NamedScene ns = named_scene(name);
    const Body& body = ns.scene.bodies.front();
    const std::vector<Centre>& centres = ns.scene.centres;
    const State ref = reference_state(body, centres, ns.t_end);
    for (const std::string& t : split(tols)) {
      const double tol = std::stod(t);
      const std::string chosen = choose_method(body, centres, tol, nullptr).name;
      const std::string prefix = chosen.substr(0, chosen.find('-') + 1);
      for (const std::string& table : kTables) {
        const MethodInfo* m = find_method(prefix + table);
        Cell c;
        if (m == nullptr || prefix.empty()) continue;
        try {
          const adaptive::ToleranceResult r =
              adaptive::search_step(*m, body, centres, Accuracy{tol, ns.t_end}, RunOptions{}, auto_verifies(centres));
          c.evals = static_cast<double>(r.total_force_evals);
          c.err = bodypoint::state_distance(r.result.final, ref);
          c.est = r.err_estimate;
          ++tally.delivered;
          tally.missed += c.err > tol;
          tally.low += c.err > kRoundingLevel && c.err > kLowEstimate * c.est;
        } catch (const Error& e) {
          std::printf("%-13s %6s %-12s refused: %s\n", name.c_str(), t.c_str(), m->name.c_str(), e.what());
        }
        cells[{t, tol}][name + "/" + table] = c;
        if (!std::isnan(c.evals))
          std::printf("%-13s %6s %-12s %10.0f evaluations  error %.2e  estimate %.2e\n", name.c_str(), t.c_str(),
                      m->name.c_str(), c.evals, c.err, c.est);
      }
    }
  }
  return cells;
}

/// A table's geometric mean over the scenes of its search's evaluations over the cheapest table's at one TOL;
/// NaN where it was refused on a scene another table delivered.
double mean_over_cheapest(const std::map<std::string, Cell>& row, const std::string& scenes, const std::string& table) {
  double log_sum = 0.0;
  int n = 0;
  for (const std::string& name : split(scenes)) {
    double best = INFINITY;
    for (const std::string& other : kTables) {
      const auto it = row.find(name + "/" + other);
      if (it != row.end() && !std::isnan(it->second.evals)) best = std::min(best, it->second.evals);
    }
    if (std::isinf(best)) continue;  // no table delivered TOL on this scene
    const auto it = row.find(name + "/" + table);
    if (it == row.end() || std::isnan(it->second.evals)) return NAN;
    log_sum += std::log(it->second.evals / best);
    ++n;
  }
  return n > 0 ? std::exp(log_sum / n) : NAN;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scenes = "thesis,close,long,two-centres,three-centres", tols = "1e-4,1e-5,1e-6,1e-7,1e-8,1e-9,1e-10,1e-11,1e-12";
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--scenes")) scenes = argv[i + 1];
    else if (!std::strcmp(argv[i], "--tols")) tols = argv[i + 1];
    else {
      std::fprintf(stderr, "auto_costs: unknown option %s (--scenes, --tols)\n", argv[i]);
      return 2;
    }
  }
  Tally tally;
  Cells cells = measure(scenes, tols, tally);
  std::printf("\nper TOL, each table's geometric mean over the scenes of its search's force evaluations over the "
              "cheapest table's (-: refused on a scene)\n%6s", "TOL");
  for (const std::string& table : kTables) std::printf(" %7s", table.c_str());
  std::printf("\n");
  for (const std::string& t : split(tols)) {
    std::printf("%6s", t.c_str());
    for (const std::string& table : kTables) {
      const double mean = mean_over_cheapest(cells[{t, std::stod(t)}], scenes, table);
      if (std::isnan(mean)) std::printf(" %7s", "-");
      else std::printf(" %7.2f", mean);
    }
    std::printf("\n");
  }
  std::printf("\n%d searches delivered: %d missed TOL, %d estimates more than %.0fx below an error above %.0e\n",
              tally.delivered, tally.missed, tally.low, kLowEstimate, kRoundingLevel);
  return 0;
}
