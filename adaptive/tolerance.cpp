// bodypoint: the accuracy mode's entry points (tolerance.hpp): the checks of a request, made once, and the
// search (search/search.hpp, one concern per file: its start, its runs, the ladder of order-p methods, the
// round-off probe, the pair of methods without an order).
#include "bodypoint/adaptive/tolerance.hpp"

#include "bodypoint/adaptive/methods.hpp"
#include "bodypoint/field.hpp"
#include "search/search.hpp"
#include "bodypoint/detail/model_parts.hpp"

#include <algorithm>
#include <string>

namespace bodypoint::adaptive {

void check_searchable(const MethodInfo& method) {
  if (takes_tolerance_per_step(method))
    throw Error(std::string(method.name) + " controls its own step: give it a tolerance per step, not the accuracy mode's "
                "search (which is for fixed-step and time-transformed methods)");
  if (method.traits.search == SearchStrategy::none || (method.traits.search == SearchStrategy::ladder && method.order == 0))
    throw Error(std::string(method.name) + " has no fixed order for the error estimate");
}

ToleranceResult run_to_tolerance(const MethodInfo& method, const Body& body, const std::vector<Centre>& centres,
                                 const Accuracy& accuracy, const RunOptions& delivery, bool verify) {
  check_tolerance(accuracy.tol);
  check(Advance(accuracy));
  check(delivery);
  check_searchable(method);
  validate(Scene{centres, {body}});
  if (non_coulomb(centres)) throw Error(std::string(kNeedsCoulomb));
  if (const std::string why = refusal(method, body, centres); !why.empty()) throw Error(why);
  return search_step(method, body, centres, accuracy, delivery, verify);
}

ToleranceResult search_step(const MethodInfo& method, const Body& body, const std::vector<Centre>& centres,
                            const Accuracy& accuracy, const RunOptions& delivery, bool verify) {
  return detail::Search(method, body, centres, accuracy, delivery, verify).search();
}

}  // namespace bodypoint::adaptive
