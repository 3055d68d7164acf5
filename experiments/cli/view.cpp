// `bodypoint view`: one self-contained HTML page that animates a run in 3D (experiments/viewer/).
//
// The page is the trajectory as JSON plus the viewer's script (three.js and viewer/src/viewer.js,
// bundled by esbuild at build time and compiled into this binary by view_bundle.cpp): it opens from
// disk with no server and no network. Every step of a run is seen; at most `--frames` states per body
// are kept, at equal arc length along the path, with the state closest to a centre always kept, so a
// run of 10^6 steps still makes a page of a few MB.
#include "process.hpp"
#include "bodypoint/field.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/scattering.hpp"
#include "budget.hpp"
#include "cli.hpp"
#include "view_bundle.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>

namespace bodypoint::cli {
namespace {

struct Frame {
  double t = 0.0;
  Vec3 R, v, w;
  double dE = 0.0, dt = 0.0;  ///< relative energy deviation; the physical step that ended here
};

/// Receives every state of a run and keeps a bounded, evenly thinned subset (uniform in the step
/// index: when `cap` states are held every other one is dropped and the stride doubles), the last
/// state and the state closest to a centre; `frames` then picks states at equal arc length.
class Decimator {
 public:
  Decimator(const std::vector<Centre>& centres, std::size_t cap) : centres_(centres), cap_(cap) {}

  void add(const Sample& s) {
    Frame f{s.t, s.s.R, s.s.v, s.s.w, s.rel_dE, seen_ > 0 ? s.t - last_.t : 0.0};
    if (!(std::isfinite(f.t) && f.R.allFinite() && f.v.allFinite() && f.w.allFinite()) && !bad_) bad_ = f.t;
    if (seen_ == 1 && kept_.size() == 1) kept_.front().dt = f.dt;  // the first state shows the first step
    for (const Centre& c : centres_) {
      const double r = (f.R - c.c).norm();
      if (r < r_min_) {
        r_min_ = r;
        closest_ = f;
      }
    }
    if (seen_ % stride_ == 0) {
      kept_.push_back(f);
      if (kept_.size() >= cap_) {
        std::size_t j = 0;
        for (std::size_t i = 0; i < kept_.size(); i += 2) kept_[j++] = kept_[i];
        kept_.resize(j);
        stride_ *= 2;
      }
    }
    last_ = f;
    ++seen_;
  }

  [[nodiscard]] long seen() const { return seen_; }
  [[nodiscard]] std::optional<double> non_finite_at() const { return bad_; }
  [[nodiscard]] double r_min() const { return r_min_; }
  [[nodiscard]] const Frame& closest() const { return closest_; }

  /// At most n states (n >= 2): the first, the last, the closest approach, the rest at equal arc length.
  [[nodiscard]] std::vector<Frame> frames(std::size_t n) const {
    std::vector<Frame> all = kept_;
    if (all.empty() || all.back().t != last_.t) all.push_back(last_);
    if (all.size() <= n) return with_closest(all);
    std::vector<double> arc(all.size(), 0.0);
    for (std::size_t i = 1; i < all.size(); ++i) arc[i] = arc[i - 1] + (all[i].R - all[i - 1].R).norm();
    const double total = arc.back();
    std::vector<Frame> out;
    out.reserve(n + 1);
    std::size_t i = 0;
    const std::size_t picks = n - 1;  // one place is kept for the closest approach
    for (std::size_t k = 0; k < picks; ++k) {
      // Equal arc length; a body that does not move (total 0) gets equal shares of its states.
      const double frac = static_cast<double>(k) / static_cast<double>(picks - 1);
      if (total > 0.0) {
        while (i + 1 < all.size() && arc[i] < frac * total) ++i;
      } else {
        i = static_cast<std::size_t>(std::lround(frac * static_cast<double>(all.size() - 1)));
      }
      if (out.empty() || all[i].t > out.back().t) out.push_back(all[i]);
    }
    if (out.back().t != all.back().t) out.push_back(all.back());
    return with_closest(out);
  }

 private:
  [[nodiscard]] std::vector<Frame> with_closest(std::vector<Frame> f) const {
    if (!centres_.empty() && std::isfinite(r_min_)) {
      const auto at = std::lower_bound(f.begin(), f.end(), closest_.t, [](const Frame& a, double t) { return a.t < t; });
      if (at == f.end() || at->t != closest_.t) f.insert(at, closest_);
    }
    return f;
  }

  const std::vector<Centre>& centres_;
  std::size_t cap_;
  std::vector<Frame> kept_;
  Frame last_, closest_;
  long seen_ = 0, stride_ = 1;
  double r_min_ = std::numeric_limits<double>::infinity();
  std::optional<double> bad_;
};

/// A JSON string literal that is also safe inside an HTML <script> element.
/// x with `digits` significant digits (JSON: non-finite values never reach here, Decimator refuses them).
void put(std::string& out, double x, int digits) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*g", digits, x);
  out += buf;
}

template <class Get>
void put_array(std::string& out, const char* name, const std::vector<Frame>& frames, int digits, Get get) {
  out += '"';
  out += name;
  out += "\": [";
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (i) out += ',';
    get(out, frames[i], digits);
  }
  out += ']';
}

void put_vec(std::string& out, const Vec3& v, int digits) {
  put(out, v.x(), digits);
  out += ',';
  put(out, v.y(), digits);
  out += ',';
  put(out, v.z(), digits);
}

/// Digits kept: positions carry the shape of a close approach at |R| ~ 1e5 |r_min|; the rest is drawn.
constexpr int kPositionDigits = 10;
constexpr int kOtherDigits = 6;
/// Bytes a frame takes in the page (13 numbers), for the size estimate made before the run.
constexpr double kBytesPerFrame = 150.0;

struct TrackJson {
  std::string json;
  double t_end = 0.0;
};

/// The marks of the encounter: the located closest approach (nearest of every centre's) and, for a
/// single Coulomb centre, the incoming and outgoing asymptotes (scattering.hpp) as a point on each line
/// and its direction.
std::string encounter_json(const Body& body, const std::vector<Centre>& centres, const BodyResult& br,
                           const std::vector<Event>& events) {  // the events br's hits index
  const EventHit* nearest = nearest_approach(br.events, events);
  const Scattering sc = scattering(body.p, centres, body.s0, br.run.final, br.run.t_end);
  std::string out = ", \"encounter\": {\"R_min\": " + (nearest ? json_vec(nearest->s.R) : std::string("null"));
  if (nearest) out += ", \"r_min\": " + json_number(nearest->r) + ", \"t_min\": " + json_number(nearest->t);
  out += ", \"asymptotes\": [";
  if (sc.in && sc.out) {
    const Vec3& c = centres.front().c;
    out += "{\"point\": " + json_vec(c + sc.in->impact) + ", \"direction\": " + json_vec(sc.in->direction) +
           ", \"incoming\": true}, {\"point\": " + json_vec(c + sc.out->impact) + ", \"direction\": " +
           json_vec(sc.out->direction) + ", \"incoming\": false}";
  }
  return out + "], \"deflection\": " + (std::isfinite(sc.deflection) ? json_number(sc.deflection) : "null") + "}";
}

TrackJson body_json(const Body& body, const std::vector<Centre>& centres, RunPlan plan, const Advance& how,
                    std::size_t frames, const std::string& method_label, const std::vector<Event>& events) {
  plan.options.track_invariants = true;  // the energy panel and the header show the deviations
  plan.options.every = 1;
  Decimator d(centres, std::max<std::size_t>(8 * frames, 1 << 16));
  const SampleSink sink = [&d](const Sample& s) { d.add(s); };
  std::vector<Event> located = closest_approaches(centres.size());  // located for the marks
  const std::size_t first_asked = located.size();
  located.insert(located.end(), events.begin(), events.end());
  const BodyResult br = run_body(plan, body, centres, how, &sink, located);
  const std::string who = "body '" + body.name + "' with " + method_label;
  if (d.non_finite_at())
    throw Error(who + ": the state became non-finite at t = " + fmt(*d.non_finite_at()) + "; no page written");
  if (d.seen() < 2) throw Error(who + ": the run produced no trajectory (fewer than two states); no page written");
  // A diverged run has nothing to show (run_body threw for a refused or failed one); an unresolved,
  // inaccurate or colliding one is drawn with its flag in the header (a comparison of a poor method
  // with a good one is what view is for).
  if (br.outcome == Outcome::diverged) throw Error(who + ": " + br.reason + "; no page written");
  if (br.outcome != Outcome::ok)
    std::cerr << "bodypoint: warning: " << who << " is " << outcome_name(br.outcome) << ": " << br.reason
              << "; drawn with that flag\n";
  const std::vector<Frame> f = d.frames(frames);
  std::string out = "{\"name\": " + json_string(body.name, true) + ", \"outcome\": " +
                    json_string(std::string(outcome_name(br.outcome)), true) + ", \"reason\": " +
                    json_string(br.reason, true) + ", \"steps\": " + std::to_string(br.run.steps) +
                    ", \"force_evals\": " + std::to_string(br.run.force_evals) + ", \"invariants\": {";
  if (br.run.invariants) {
    const InvariantStats& inv = *br.run.invariants;
    out += "\"max_rel_dE\": " + json_number(inv.max_rel_dE) + ", \"max_rel_dK2sq\": " + json_number(inv.max_rel_dK2sq);
    if (inv.has_K2Q) out += ", \"max_abs_dK2Q\": " + json_number(inv.max_abs_dK2Q);
  }
  out += "}, \"closest\": {\"t\": " + json_number(d.closest().t) + ", \"r\": " +
         json_number(centres.empty() ? 0.0 : d.r_min()) + "}, \"frames\": {";
  put_array(out, "t", f, kPositionDigits, [](std::string& o, const Frame& x, int g) { put(o, x.t, g); });
  out += ", ";
  put_array(out, "R", f, kPositionDigits, [](std::string& o, const Frame& x, int g) { put_vec(o, x.R, g); });
  out += ", ";
  put_array(out, "v", f, kOtherDigits, [](std::string& o, const Frame& x, int g) { put_vec(o, x.v, g); });
  out += ", ";
  put_array(out, "w", f, kOtherDigits, [](std::string& o, const Frame& x, int g) { put_vec(o, x.w, g); });
  out += ", ";
  put_array(out, "dE", f, kOtherDigits, [](std::string& o, const Frame& x, int g) {
    put(o, std::isfinite(x.dE) ? x.dE : 0.0, g);
  });
  out += ", ";
  put_array(out, "dt", f, kOtherDigits, [](std::string& o, const Frame& x, int g) { put(o, x.dt, g); });
  out += "}" + encounter_json(body, centres, br, located) + ", \"events\": [";  // located: what the hits index
  bool first = true;
  for (const EventHit& h : br.events) {  // the asked events' hits, located to round-off (the marks)
    if (h.event < first_asked) continue;
    out += (first ? "" : ", ") + std::string("{\"label\": ") + json_string(located[h.event].label(), true) +
           ", \"t\": " + json_number(h.t) + ", \"R\": " + json_vec(h.s.R) + ", \"r\": " + json_number(h.r) + "}";
    first = false;
  }
  out += "]}";
  return {out, br.run.t_end};
}

/// The step the run used, as the header shows it.
std::string step_label(const RunPlan& plan) {
  if (plan.search) return "tol=" + fmt(plan.tol);
  if (const auto* c = std::get_if<ControlledSteps>(&plan.how)) return "tol=" + fmt(c->tol);
  if (const auto* f = std::get_if<FictitiousSteps>(&plan.how)) return "ds=" + fmt(f->ds);
  const auto& f = std::get<FixedSteps>(plan.how);
  return "h=" + fmt(f.h) + " steps=" + std::to_string(f.steps);
}

/// plan's way of advancing made to end at time t_end (--compare follows the first run's end time).
Advance ending_at(const RunPlan& plan, double t_end) {
  Advance how = plan.how;
  if (auto* a = std::get_if<Accuracy>(&how)) a->t_end = t_end;
  else if (auto* f = std::get_if<FictitiousSteps>(&how)) f->end = EndTime{t_end};
  else if (auto* c = std::get_if<ControlledSteps>(&how)) c->t_end = t_end;
  else how = fixed_steps_to(t_end, std::get<FixedSteps>(how).h);
  return how;
}

struct ViewOptions {
  SceneOptions so;
  StepOptions st;
  std::string method_name = "lp-y4", compare, out = "bodypoint-view.html";
  double tol = kDefaultStepTolerance, compare_h = 0.0, max_mb = 32.0;
  long frames = 3000;
  bool dry_run = false, quiet = false;
  std::vector<std::string> event_text;  ///< --event: located on the method's steps and marked on the page
  std::vector<Event> events;
};

void add_view_options(po::options_description& desc, ViewOptions& o) {
  add_scene_options(desc, o.so);
  add_step_options(desc, o.st);
  desc.add_options()
      ("method", defaulted(&o.method_name), "integration method, or auto with --tol")
      ("tol", defaulted(&o.tol), "as for simulate: per-step tolerance of odeint-*/gsl-*, "
       "otherwise the final state's relative error to deliver")
      ("compare", po::value(&o.compare), "a second method on the same scene, drawn in a second colour")
      ("compare-h", po::value(&o.compare_h), "step (or ds) of the --compare method (default: --h)")
      ("frames", defaulted(&o.frames), "states kept per body (equal arc length, closest approach kept)")
      ("max-mb", defaulted(&o.max_mb), "refuse to write a page larger than this many MB")
      ("out", defaulted(&o.out), "the HTML file to write (atomically)")
      ("event", po::value(&o.event_text)->multitoken()->composing(),
       "as for simulate: locate these events on the method's steps and mark every hit on the page (closest, "
       "local-min, r=RADIUS, x=X, y=Y, z=Z, plane=nx,ny,nz,offset, departure, arrival=R)")
      ("dry-run", po::bool_switch(&o.dry_run), "check every option and the scene, run nothing, write nothing")
      ("quiet", po::bool_switch(&o.quiet), "no line announcing a long run, none for the page written (warnings and errors still print)");
}

void check_view_options(const po::variables_map& vm, const ViewOptions& o) {
  if (!viewer_bundle())
    throw Error("this binary was built without the viewer's script: run scripts/setup.sh (it needs npm) to "
                "install experiments/viewer's packages, then rebuild");
  if (o.frames < 16 || o.frames > 10'000'000) throw Error("--frames must be between 16 and 10000000");
  // The page is HTML whatever its name: a name like v.png would hold HTML that no image viewer opens.
  const std::string_view html = ".html";
  if (o.out.size() <= html.size() || o.out.compare(o.out.size() - html.size(), html.size(), html) != 0)
    throw Error("--out " + o.out + ": the viewer writes an HTML page; give a name ending in .html");
  if (!(std::isfinite(o.max_mb) && o.max_mb > 0.0)) throw Error("--max-mb must be a finite number > 0");
  if (vm.count("compare-h") && !vm.count("compare")) throw Error("--compare-h needs --compare");
  if (vm.count("compare-h") && !(std::isfinite(o.compare_h) && o.compare_h > 0.0))
    throw Error("--compare-h must be a finite number > 0");
}

/// The run and, with --compare, the second one.
std::vector<RunPlan> view_plans(const po::variables_map& vm, const ViewOptions& o) {
  std::vector<RunPlan> plans{plan_run(vm, o.st, o.method_name, vm["method"].defaulted(), o.tol)};
  if (vm.count("compare")) {
    StepOptions st2 = o.st;
    if (vm.count("compare-h")) st2.h = o.compare_h;
    plans.push_back(plan_run(vm, st2, o.compare, false, o.tol));
  }
  return plans;
}

/// The page's data: the scene, and every run of every body (the second run ends where the first did).
std::string page_json(const std::string& title, const std::string& scene_line, const Scene& scene,
                      const std::vector<RunPlan>& plans, const std::vector<std::string>& labels, long frames,
                      const std::vector<Event>& events) {
  std::string json = "{\"title\": " + json_string(title, true) + ", \"scene\": " + json_string(scene_line, true) +
                     ", \"revision\": " + json_string(git_revision(), true) + ", \"centres\": [";
  for (std::size_t i = 0; i < scene.centres.size(); ++i)
    json += (i ? ", " : "") + std::string("{\"c\": ") + json_vec(scene.centres[i].c) + ", \"A\": " +
            json_number(scene.centres[i].A) + "}";
  json += "], \"runs\": [";
  std::vector<double> t_end(scene.bodies.size(), 0.0);
  for (std::size_t k = 0; k < plans.size(); ++k) {
    json += (k ? ", " : "") + std::string("{\"method\": ") + json_string(labels[k], true) +
            ", \"step\": " + json_string(step_label(plans[k]), true) + ", \"bodies\": [";
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
      const Advance how = k == 0 ? plans[k].how : ending_at(plans[k], t_end[b]);
      const TrackJson tr = body_json(scene.bodies[b], scene.centres, plans[k], how,
                                     static_cast<std::size_t>(frames), labels[k], events);
      if (k == 0) t_end[b] = tr.t_end;
      json += (b ? ", " : "") + tr.json;
    }
    json += "]}";
  }
  return json + "]}";
}

}  // namespace

int cmd_view(int argc, char** argv) {
  ViewOptions o;
  po::options_description desc("bodypoint view");
  add_view_options(desc, o);
  po::variables_map vm;
  if (!parse(argc, argv, desc, vm,
             "usage: bodypoint view [options]\n"
             "Writes one self-contained HTML page (three.js inlined, no server or network needed) that animates\n"
             "the run in 3D: centres, bodies, trails coloured by the physical step, spin and velocity arrows,\n"
             "the energy error against t. Options as for simulate."))
    return 0;
  check_view_options(vm, o);
  for (const std::string& text : o.event_text) o.events.push_back(parse_event(text));
  const std::vector<RunPlan> plans = view_plans(vm, o);
  std::vector<std::string> labels;
  for (const RunPlan& p : plans) labels.push_back(p.automatic ? "auto" : std::string(p.method->name));
  const Scene scene = make_scene(vm, o.so);
  const std::string_view bundle = *viewer_bundle();
  const double estimate = static_cast<double>(bundle.size()) + kBytesPerFrame * static_cast<double>(o.frames + 2) *
                                                                   static_cast<double>(scene.bodies.size() * plans.size());
  const double limit = o.max_mb * 1e6;
  if (estimate > limit)
    throw Error("the page would hold about " + fmt(std::round(estimate / 1e5) / 10) + " MB (" + std::to_string(o.frames) +
                " frames x " + std::to_string(scene.bodies.size()) + " bodies x " + std::to_string(plans.size()) +
                " runs), above --max-mb " + fmt(o.max_mb) + ": lower --frames or raise --max-mb");
  for (const RunPlan& p : plans)
    if (!p.search)
      for (const Body& body : scene.bodies)
        if (const auto e = estimate_work(*p.method, body, scene.centres, p.how, p.options))
          check_budget(*e, vm["max-seconds"].as<double>() > 0.0 ? vm["max-seconds"].as<double>() : HUGE_VAL, o.quiet);
  if (o.dry_run) {
    std::cout << "would write " << o.out << ": " << plans.size() << " run(s) of " << scene.bodies.size()
              << " body-point(s), about " << std::round(estimate / 1e3) << " kB\n";
    return 0;
  }
  AtomicFile file(o.out);  // an unwritable path fails before the runs
  const std::string title = "bodypoint view: " + labels[0] + (plans.size() > 1 ? " vs " + labels[1] : "");
  const std::string json = page_json(title, vm.count("scene") ? "scene=" + o.so.scene_file : describe(o.so.params),
                                     scene, plans, labels, o.frames, o.events);
  std::ostream& os = file.stream();
  os << "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
     << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
     << "<meta name=\"generator\" content=\"bodypoint " << git_revision() << "\">"
     << "<title>" << title << "</title></head>\n<body>\n"
     << "<script id=\"bodypoint-data\" type=\"application/json\">" << json << "</script>\n"
     << "<script>" << bundle << "</script>\n</body></html>\n";
  const double size = static_cast<double>(os.tellp());
  if (size > limit)
    throw Error("the page holds " + fmt(std::round(size / 1e5) / 10) + " MB, above --max-mb " + fmt(o.max_mb) +
                ": lower --frames or raise --max-mb; nothing written");
  file.commit();
  if (!o.quiet)
    std::cout << "wrote " << o.out << " (" << std::round(size / 1e3) << " kB, " << scene.bodies.size()
            << " body-point(s), " << plans.size() << " run(s)); open it in a browser\n";
  return 0;
}

}  // namespace bodypoint::cli
