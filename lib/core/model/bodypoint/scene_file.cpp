#include "bodypoint/scene_file.hpp"
#include "bodypoint/detail/model_parts.hpp"

#include "bodypoint/io.hpp"

#include <filesystem>
#include <fstream>
#include <algorithm>
#include <initializer_list>
#include <set>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <sstream>
#include <toml++/toml.h>

namespace bodypoint {
namespace {

[[noreturn]] void fail(const std::string& origin, const std::string& what) {
  throw Error(origin + ": " + what);
}

double number(const toml::table& t, std::string_view key, const std::string& where, const std::string& origin) {
  const toml::node* n = t.get(key);
  if (!n) fail(origin, where + ": missing '" + std::string(key) + "'");
  if (auto v = n->value<double>()) return *v;  // accepts integers too
  fail(origin, where + ": '" + std::string(key) + "' must be a number");
}

Vec3 vector3(const toml::table& t, std::string_view key, const std::string& where, const std::string& origin) {
  const toml::node* n = t.get(key);
  if (!n) fail(origin, where + ": missing '" + std::string(key) + "'");
  const toml::array* a = n->as_array();
  if (!a || a->size() != 3) fail(origin, where + ": '" + std::string(key) + "' must be an array of 3 numbers");
  Vec3 v;
  for (std::size_t i = 0; i < 3; ++i) {
    auto x = (*a)[i].value<double>();
    if (!x) fail(origin, where + ": '" + std::string(key) + "' must be an array of 3 numbers");
    v[static_cast<Eigen::Index>(i)] = *x;
  }
  return v;
}

void only_keys(const toml::table& t, const std::set<std::string>& allowed, const std::string& where,
               const std::string& origin) {
  for (const auto& [k, _] : t)
    if (!allowed.count(std::string(k.str())))
      fail(origin, where + ": " + unknown_name("key", k.str(), {allowed.begin(), allowed.end()}));
}

const toml::array* array_of_tables(const toml::table& root, std::string_view key, const std::string& origin) {
  const toml::node* n = root.get(key);
  if (!n) return nullptr;
  const toml::array* a = n->as_array();
  if (!a || !a->is_array_of_tables())
    fail(origin, "'" + std::string(key) + "' must be written as [[" + std::string(key) + "]] tables");
  return a;
}

}  // namespace

/// Largest scene file read (a scene of 10^5 bodies is about 10 MB).
constexpr std::uintmax_t kMaxSceneFileBytes = 16u << 20;

namespace {

/// The names of the scene parameters of one kind (model.hpp, scene_parameters()), and `extra`.
std::set<std::string> keys_of(std::initializer_list<SceneParameter::Of> kinds, std::initializer_list<const char*> extra) {
  std::set<std::string> keys(extra.begin(), extra.end());
  for (const SceneParameter& q : scene_parameters())
    if (std::find(kinds.begin(), kinds.end(), q.of) != kinds.end()) keys.emplace(q.name);
  return keys;
}

/// Reads every parameter of kind `of` that the table has into p (each is required).
void read_parameters(const toml::table& t, SceneParameter::Of of, SceneParams& p, const std::string& where,
                     const std::string& origin) {
  for (const SceneParameter& q : scene_parameters())
    if (q.of == of && !(q.optional && !t.contains(q.name))) q.field(p) = number(t, std::string(q.name), where, origin);
}

Centre parse_centre(const toml::table& t, const std::string& where, const std::string& origin) {
  only_keys(t, keys_of({SceneParameter::Of::centre}, {"position", "law"}), where, origin);
  SceneParams p;
  read_parameters(t, SceneParameter::Of::centre, p, where, origin);
  Centre c;
  c.A = p.A;
  if (t.contains("position")) c.c = vector3(t, "position", where, origin);
  if (const toml::node* law = t.get("law")) {
    const auto name = law->value<std::string>();
    if (!name) fail(origin, where + ": 'law' must be a text (coulomb, thesis-code, thesis-code-force)");
    try {
      c.law = parse_force_law(*name);
    } catch (const Error& e) {
      fail(origin, where + ": " + e.what());
    }
  }
  return c;
}

/// A body in either form: R, v, w, or the thesis's start (d, L, K1, Kx, Kz; eq. 1.11-1.13).
Body parse_body(const toml::table& t, std::size_t i, const std::string& origin) {
  using Of = SceneParameter::Of;
  const std::string where = "body " + std::to_string(i + 1);
  only_keys(t, keys_of({Of::body, Of::start}, {"name", "R", "v", "w"}), where, origin);
  Body b;
  if (const toml::node* n = t.get("name")) {
    auto s = n->value<std::string>();
    if (!s) fail(origin, where + ": 'name' must be a string");
    b.name = *s;
  }
  SceneParams p;
  read_parameters(t, Of::body, p, where, origin);
  b.p = BodyPoint{p.m, p.B, p.J};
  const bool physical = t.contains("R") || t.contains("v") || t.contains("w");
  const std::set<std::string> start = keys_of({Of::start}, {});
  const bool thesis = std::any_of(start.begin(), start.end(), [&t](const std::string& k) { return t.contains(k); });
  if (physical == thesis)
    fail(origin, where + ": give either R, v, w or the thesis's d, L, K1, Kx, Kz (exactly one form)");
  try {
    validate(b.p, where);
  } catch (const Error& e) {
    fail(origin, e.what());
  }
  if (physical) {
    b.s0 = State{vector3(t, "R", where, origin), vector3(t, "v", where, origin), vector3(t, "w", where, origin)};
  } else {
    read_parameters(t, Of::start, p, where, origin);
    try {
      validate(p.start, where + ": ");
    } catch (const Error& e) {
      fail(origin, e.what());
    }
    b.s0 = to_state(b.p, thesis_momenta(p.start));
  }
  if (b.name.empty()) b.name = "body" + std::to_string(i + 1);
  return b;
}

std::vector<std::string> split_key(const std::string& key) {
  std::vector<std::string> parts;
  std::size_t from = 0;
  for (std::size_t at; (at = key.find('.', from)) != std::string::npos; from = at + 1) parts.push_back(key.substr(from, at - from));
  parts.push_back(key.substr(from));
  return parts;
}

/// "3" from "centre3" (prefix "centre"); 0 for the bare prefix (every one); nullopt otherwise.
std::optional<std::size_t> numbered(const std::string& part, const std::string& prefix) {
  if (part.rfind(prefix, 0) != 0) return std::nullopt;
  const std::string digits = part.substr(prefix.size());
  if (digits.empty()) return 0;
  if (digits.size() > 6 || !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return std::nullopt;
  const std::size_t k = std::stoul(digits);
  if (k == 0) return std::nullopt;
  return k;
}

/// The [[centre]] or [[body]] tables a key path's first part names, with that part's meaning.
std::vector<toml::table*> tables_of(toml::table& root, const std::string& head, const std::string& key,
                                    const std::string& origin) {
  const bool centre = numbered(head, "centre").has_value();
  toml::array* a = root.get(centre ? "centre" : "body") ? root.get(centre ? "centre" : "body")->as_array() : nullptr;
  std::vector<toml::table*> all;
  if (a && a->is_array_of_tables())
    for (auto& t : *a) all.push_back(t.as_table());
  const auto k = numbered(head, centre ? "centre" : "body");
  if (k) {
    if (*k == 0) return all;
    if (*k <= all.size()) return {all[*k - 1]};
    fail(origin, "scene key '" + key + "': the scene has " + std::to_string(all.size()) + (centre ? " centre(s)" : " body(ies)"));
  }
  std::vector<std::string> names;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const toml::node* n = all[i]->get("name");
    const std::string name = n && n->value<std::string>() ? *n->value<std::string>() : "body" + std::to_string(i + 1);
    if (name == head) return {all[i]};
    names.push_back(name);
  }
  fail(origin, "scene key '" + key + "': its first part is centreK, bodyK, centre, body or a body's name (" +
                   (names.empty() ? std::string("the scene has no body") : "bodies: " + join(names, ", ")) + ")");
}

void apply(toml::table& root, const SceneValue& kv, const std::string& origin) {
  const std::vector<std::string> parts = split_key(kv.key);
  const std::string& key = kv.key;
  if (parts.size() < 2 || parts.size() > 3)
    fail(origin, "scene key '" + key + "': give PART.KEY or PART.VECTOR.x|y|z (centre2.A, body.B, centre1.position.x)");
  const bool vector = parts.size() == 3;
  static const std::vector<std::string> axes{"x", "y", "z"};
  const auto axis = vector ? std::find(axes.begin(), axes.end(), parts[2]) : axes.end();
  if (vector && axis == axes.end()) fail(origin, "scene key '" + key + "': a vector's component is x, y or z");
  for (toml::table* t : tables_of(root, parts[0], key, origin)) {
    if (!vector) {
      if (t->get(parts[1]) && t->get(parts[1])->is_array())
        fail(origin, "scene key '" + key + "': '" + parts[1] + "' is a vector: give " + key + ".x, .y or .z");
      t->insert_or_assign(parts[1], kv.value);
      continue;
    }
    toml::node* n = t->get(parts[1]);
    if (!n && parts[1] == "position") {  // a centre's default position
      t->insert_or_assign("position", toml::array{0.0, 0.0, 0.0});
      n = t->get("position");
    }
    toml::array* a = n ? n->as_array() : nullptr;
    if (!a || a->size() != 3)
      fail(origin, "scene key '" + key + "': the scene has no vector '" + parts[1] + "' there" +
                       (parts[1] == "R" || parts[1] == "v" || parts[1] == "w" ? " (that body is given by the thesis's d, L, K1, Kx, Kz)" : ""));
    a->replace(a->begin() + (axis - axes.begin()), kv.value);
  }
}

}  // namespace

bool is_scene_key(const std::string& key) { return key.find('.') != std::string::npos; }

Scene parse_scene(const std::string& text, const std::string& origin, const std::vector<SceneValue>& set) {
  toml::table root;
  try {
    root = toml::parse(text, origin);
  } catch (const toml::parse_error& e) {
    const auto& src = e.source();
    fail(origin, "line " + std::to_string(src.begin.line) + ": " + std::string(e.description()));
  }
  only_keys(root, {"centre", "body"}, "top level", origin);
  for (const SceneValue& kv : set) apply(root, kv, origin);
  Scene scene;
  if (const toml::array* cs = array_of_tables(root, "centre", origin))
    for (std::size_t k = 0; k < cs->size(); ++k)
      scene.centres.push_back(parse_centre(*(*cs)[k].as_table(), "centre " + std::to_string(k + 1), origin));
  if (const toml::array* bs = array_of_tables(root, "body", origin))
    for (std::size_t i = 0; i < bs->size(); ++i) scene.bodies.push_back(parse_body(*(*bs)[i].as_table(), i, origin));
  return scene;
}

Scene read_scene_file(const std::string& path) {
  Scene scene = parse_scene(read_scene_text(path), path);
  try {
    validate(scene);
  } catch (const Error& e) {
    fail(path, e.what());
  }
  return scene;
}

std::string read_scene_text(const std::string& path) {
  // A scene file is a few lines; a device (/dev/zero) or a huge file would be read forever.
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw Error(path + ": cannot open scene file");
  if (!std::filesystem::is_regular_file(status)) throw Error(path + ": the scene file is not a regular file");
  if (std::filesystem::file_size(path, ec) > kMaxSceneFileBytes)
    throw Error(path + ": the scene file is larger than 16 MB");
  // Read with the C library, whose error indicator tells a read that failed (/proc/self/mem: EIO) from an
  // empty file; a file that says it is small (/proc files say 0) is held to the limit while it is read.
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> in(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!in) throw Error(path + ": cannot open scene file (" + std::strerror(errno) + ")");
  std::string text;
  std::array<char, 65536> buf{};
  for (std::size_t n; (n = std::fread(buf.data(), 1, buf.size(), in.get())) > 0;) {
    text.append(buf.data(), n);
    if (text.size() > kMaxSceneFileBytes) throw Error(path + ": the scene file is larger than 16 MB");
  }
  if (std::ferror(in.get())) throw Error(path + ": the scene file cannot be read (" + std::strerror(errno) + ")");
  return text;
}

}  // namespace bodypoint
