// bodypoint: the registry of every method (methods.hpp).
#include "bodypoint/methods.hpp"
#include "choice.hpp"

#include "bodypoint/adaptive/methods.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/detail/run_parts.hpp"

#include <algorithm>
#include <string>
#include <vector>

namespace bodypoint {

const std::vector<MethodInfo>& methods() {
  static const std::vector<MethodInfo> registry = [] {
    std::vector<MethodInfo> all = core_methods();
    for (const MethodInfo& m : adaptive::methods()) all.push_back(m);
    return all;
  }();
  return registry;
}

const MethodInfo* find_method(std::string_view name) {
  for (const MethodInfo& m : methods())
    if (m.name == name) return &m;
  return nullptr;
}

const MethodInfo& method_or_throw(std::string_view name) {
  if (const MethodInfo* m = find_method(name)) return *m;
  std::vector<std::string> names;
  for (const MethodInfo& m : methods()) names.push_back(m.name);
  throw Error(unknown_name("method", name, names));
}

const MethodInfo* detail::method_of(Family family, std::string_view table, const Body& body,
                                    const std::vector<Centre>& centres) {
  const MethodInfo* first = nullptr;
  for (const MethodInfo& m : methods()) {
    if (m.family != family || (!table.empty() && m.table != table)) continue;
    if (refusal(m, body, centres).empty()) return &m;
    if (!first) first = &m;
  }
  return first;
}

std::vector<const MethodInfo*> methods_named(std::string_view list) {
  std::vector<const MethodInfo*> ms;
  const bool all = list == "all", fixed = list == "fixed";
  if (all || fixed) {
    for (const MethodInfo& m : methods())
      if (all || m.traits.in_fixed_set)
        ms.push_back(&m);
    return ms;
  }
  for (std::size_t start = 0; start <= list.size();) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    const std::string_view name = list.substr(start, comma - start);
    if (!name.empty()) ms.push_back(&method_or_throw(name));
    start = comma + 1;
  }
  if (ms.empty()) throw Error("the method list is empty");
  return ms;
}

}  // namespace bodypoint
