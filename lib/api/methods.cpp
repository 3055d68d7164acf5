// bodypoint: the registry of every method (methods.hpp).
#include "bodypoint/methods.hpp"

#include "bodypoint/adaptive/methods.hpp"

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
  throw Error("unknown method '" + std::string(name) + "' (see 'bodypoint methods')");
}

}  // namespace bodypoint
