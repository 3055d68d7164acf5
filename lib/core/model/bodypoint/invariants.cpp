// bodypoint: E in the field of a list of centres (invariants.hpp), through the production field.
#include "bodypoint/detail/monitor.hpp"

namespace bodypoint {

double energy(const BodyPoint& p, const std::vector<Centre>& centres, const State& s) {
  return energy(p, CentreList{centres}, s);
}

}  // namespace bodypoint
