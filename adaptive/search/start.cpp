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
  if (is_time_transformed(m)) return FictitiousSteps{h, EndTime{t_end}, dt_out};
  const double n = steps_landing_on(t_end, h);
  if (!(n <= 1e12)) throw SearchLimit("tol: the step the search needs (" + std::to_string(h) + ") is too small");
  return FixedSteps{t_end / n, static_cast<long>(n), dt_out};
}

}  // namespace bodypoint::adaptive::detail
