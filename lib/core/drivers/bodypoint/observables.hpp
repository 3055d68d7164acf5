// bodypoint: what a trajectory file can say about each sampled state, as one list (a schema).
//
// An observable has a name (its CSV column), one line of help (the file's header comment), when it
// applies to a scene, and how it is computed from a sample and the body's parameters. The default
// ones are the columns every trajectory has had (t, R, v, w and the integrals' deviations); the
// others are written when asked for (`simulate --observe`). `TrajectoryWriter` writes the header
// and the rows of the observables it is given, every number in io.hpp's one format (fmt: the
// shortest text that reads back to the same double). A new observable is one entry in observables.cpp.
#pragma once

#include "bodypoint/model.hpp"
#include "bodypoint/run.hpp"

#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace bodypoint {

struct Observable {
  std::string_view name;  ///< CSV column
  std::string_view help;  ///< one line for the file's header
  bool by_default;        ///< written unless the caller chooses the list
  /// Whether the scene has it (the integral K2Q exists only about a single centre).
  bool (*applies)(const std::vector<Centre>& centres);
  double (*value)(const Sample& s, const BodyPoint& p);
};

/// Every observable, in column order.
const std::vector<Observable>& observables();

/// The observables a trajectory of this scene gets: the default ones that apply, then `extra` (names;
/// an unknown name, or one that does not apply to the scene, is an Error).
std::vector<const Observable*> select_observables(const std::vector<Centre>& centres,
                                                  const std::vector<std::string>& extra = {});

/// Writes trajectory rows: an optional leading `body` column, then one column per observable.
class TrajectoryWriter {
 public:
  TrajectoryWriter(std::ostream& os, std::vector<const Observable*> columns, bool body_column);
  /// "# name: help" for every column.
  void help() const;
  void header() const;
  void row(long body, const Sample& s, const BodyPoint& p) const;

 private:
  std::ostream& os_;
  std::vector<const Observable*> columns_;
  bool body_column_;
};

}  // namespace bodypoint
