// bodypoint: a searched step as a way of advancing time (search.hpp); where a search starts is the method's
// catalogue row's (search_first_step, run.hpp).
#include "search.hpp"

#include "bodypoint/adaptive/methods.hpp"
#include "bodypoint/field.hpp"
#include "bodypoint/detail/run_parts.hpp"
#include "bodypoint/detail/model_parts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bodypoint::adaptive::detail {

Advance step_advance(const MethodInfo& m, double h, double t_end, double dt_out) {
  const Advance how = advance_of(m, {.step = h, .end = t_end, .dt_out = dt_out});
  if (const auto* f = std::get_if<FixedSteps>(&how); f && !(static_cast<double>(f->steps) <= 1e12))
    throw SearchLimit("tol: the step the search needs (" + std::to_string(h) + ") is too small");
  return how;
}

}  // namespace bodypoint::adaptive::detail
