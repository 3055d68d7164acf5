// bodypoint: one generic composition engine for every drift/kick splitting method.
//
// A splitting table is a sequence of pairs  D(a_0 h) K(b_0 h) D(a_1 h) K(b_1 h) ... D(a_{N-1} h) K(b_{N-1} h),
// the form of the thesis's eq. 2.12 (C_i = a_i, D_i = b_i), where D is the drift (flow of the kinetic
// part) and K the kick (flow of the potential part). Zero coefficients are skipped.
//
// Symmetric compositions of a second-order basic method S2 with weights g_1..g_s,
//   S(h) = S2(g_s h) ... S2(g_2 h) S2(g_1 h),
// are built at compile time by `strang_dkd` (S2 = D(h/2) K(h) D(h/2)) or `strang_kdk`
// (S2 = K(h/2) D(h) K(h/2)); `triple_jump` raises the order of a symmetric method by two
// (Yoshida 1990, eq. 5.2-5.4; thesis appendix 2, eq. P2.1-P2.3).
//
// The engine (`integrate`) runs n steps and shares sub-flows between consecutive steps ("first same
// as last") when the kernel allows it, so a symmetric s-stage composition costs s force evaluations
// per step:
// - a table that starts and ends with a kick evaluates the force once at each step boundary and
//   uses it for the last kick of one step and the first kick of the next (the state handed to an
//   observer in between is exact), so this works with or without an observer;
// - a table that starts and ends with a drift merges the two drifts into one, which is possible only
//   when no observer needs the state at the step boundary.
//
// A sub-flow is one of up to three parts: the drift, the kick and a third exactly solvable part of a
// kernel that splits its Hamiltonian in three (`third(x, tau)`; the Kepler split's other centres).
// `flatten_three` makes a three-part method of a DKD composition (strang_dkd(g)): its basic step
// D(g/2) K(g) D(g/2) becomes the symmetric D(g/2) O(g/2) K(g) O(g/2) D(g/2), and the composition with
// the same weights g keeps the table's order (the composition theorem needs only a symmetric
// second-order basic method; Yoshida 1990, sec. 4; HLW II.4).
#pragma once

#include <array>
#include <cstddef>
#include <string_view>
#include <type_traits>

namespace bodypoint::splitting {

/// D(a_i) K(b_i) pairs, i = 0..N-1.
template <std::size_t N>
struct Table {
  std::array<double, N> a{};
  std::array<double, N> b{};
};

/// The n-th root of x > 0 by Newton's method, usable in constant expressions.
constexpr double nth_root(double x, int n) {
  double y = x > 1.0 ? x : 1.0;
  for (int it = 0; it < 200; ++it) {
    double p = 1.0;
    for (int k = 0; k < n - 1; ++k) p *= y;
    const double next = y - (p * y - x) / (n * p);
    if (next == y) break;
    y = next;
  }
  return y;
}

/// Triple jump of a symmetric method of order 2k with weights g (Yoshida 1990, eq. 5.4):
/// S_{2k+2}(h) = S_{2k}(x1 h) S_{2k}(x0 h) S_{2k}(x1 h), x1 = 1/(2 - 2^{1/(2k+1)}), x0 = 1 - 2 x1.
template <std::size_t S>
constexpr std::array<double, 3 * S> triple_jump(const std::array<double, S>& g, int order_of_g) {
  const double r = nth_root(2.0, order_of_g + 1);
  const double x1 = 1.0 / (2.0 - r);
  const double x0 = -r / (2.0 - r);
  std::array<double, 3 * S> out{};
  for (std::size_t i = 0; i < S; ++i) {
    out[i] = x1 * g[i];
    out[S + i] = x0 * g[i];
    out[2 * S + i] = x1 * g[i];
  }
  return out;
}

/// Full palindromic weight list g_1..g_s from its first half (s = 2 H - 1): the middle weight
/// g_H is derived from the consistency condition sum g = 1 (the tables list only g_1..g_{H-1}).
template <std::size_t H>
constexpr std::array<double, 2 * H + 1> palindrome(const std::array<double, H>& half) {
  std::array<double, 2 * H + 1> g{};
  double sum = 0.0;
  for (std::size_t i = 0; i < H; ++i) {
    g[i] = half[i];
    g[2 * H - i] = half[i];
    sum += half[i];
  }
  g[H] = 1.0 - 2.0 * sum;
  return g;
}

/// S(h) = prod S2(g_i h) with S2 = D(h/2) K(h) D(h/2), adjacent half drifts merged:
/// a = (g1/2, (g1+g2)/2, ..., gs/2), b = (g1, ..., gs, 0).
template <std::size_t S>
constexpr Table<S + 1> strang_dkd(const std::array<double, S>& g) {
  Table<S + 1> t{};
  t.a[0] = 0.5 * g[0];
  for (std::size_t i = 1; i < S; ++i) t.a[i] = 0.5 * (g[i - 1] + g[i]);
  t.a[S] = 0.5 * g[S - 1];
  for (std::size_t i = 0; i < S; ++i) t.b[i] = g[i];
  t.b[S] = 0.0;
  return t;
}

/// S(h) = prod S2(g_i h) with S2 = K(h/2) D(h) K(h/2): a = (0, g1, ..., gs),
/// b = (g1/2, (g1+g2)/2, ..., gs/2).
template <std::size_t S>
constexpr Table<S + 1> strang_kdk(const std::array<double, S>& g) {
  Table<S + 1> t{};
  t.a[0] = 0.0;
  for (std::size_t i = 0; i < S; ++i) t.a[i + 1] = g[i];
  t.b[0] = 0.5 * g[0];
  for (std::size_t i = 1; i < S; ++i) t.b[i] = 0.5 * (g[i - 1] + g[i]);
  t.b[S] = 0.5 * g[S - 1];
  return t;
}

/// The part of the Hamiltonian a sub-flow belongs to.
enum class Part : unsigned char { drift, kick, third };

/// One sub-flow of a step: a drift, a kick or the third part for c*h.
struct Op {
  Part part = Part::drift;
  double c = 0.0;
};

/// A table flattened to its non-zero sub-flows, adjacent flows of one part merged.
template <std::size_t M>
struct OpSequence {
  std::array<Op, M> ops{};
  std::size_t size = 0;
  [[nodiscard]] constexpr std::size_t count(Part p) const {
    std::size_t k = 0;
    for (std::size_t i = 0; i < size; ++i) k += ops[i].part == p ? 1 : 0;
    return k;
  }
  [[nodiscard]] constexpr std::size_t kicks() const { return count(Part::kick); }
  /// True when the sequence uses a third part (the kernel must provide `third`).
  [[nodiscard]] constexpr bool has_third() const { return count(Part::third) > 0; }
  /// First and last sub-flows are of one part, so consecutive steps can share them.
  [[nodiscard]] constexpr bool fsal() const { return size >= 2 && ops[0].part == ops[size - 1].part; }
  /// Force evaluations per step when consecutive steps are merged.
  [[nodiscard]] constexpr std::size_t kicks_merged() const {
    return fsal() && ops[0].part == Part::kick ? kicks() - 1 : kicks();
  }
  /// Whether the step is its own adjoint, S(-h) S(h) = id (time-symmetric): its sub-flows read the same
  /// backwards, each coefficient to a relative 1e-12 (the tables' decimal digits and the triple jump's roots).
  [[nodiscard]] constexpr bool symmetric() const {
    for (std::size_t i = 0; i < size / 2; ++i) {
      const Op& x = ops[i];
      const Op& y = ops[size - 1 - i];
      const double d = x.c - y.c, scale = (x.c < 0.0 ? -x.c : x.c) + 1e-300;
      if (x.part != y.part || (d < 0.0 ? -d : d) > 1e-12 * scale) return false;
    }
    return true;
  }
  /// Appends c of part p, merged into the last sub-flow when it is of the same part; zeros skipped.
  constexpr void push(Part p, double c) {
    if (c == 0.0) return;
    if (size > 0 && ops[size - 1].part == p) {
      ops[size - 1].c += c;
    } else {
      ops[size++] = Op{p, c};
    }
  }
};

template <std::size_t N>
constexpr OpSequence<2 * N> flatten(const Table<N>& t) {
  OpSequence<2 * N> s{};
  for (std::size_t i = 0; i < N; ++i) {
    s.push(Part::drift, t.a[i]);
    s.push(Part::kick, t.b[i]);
  }
  return s;
}

/// True when t is strang_dkd(g) for some weights g (then g = b): the tables built as compositions.
template <std::size_t N>
constexpr bool is_dkd_composition(const Table<N>& t) {
  if (N < 2 || t.b[N - 1] != 0.0 || t.a[0] != 0.5 * t.b[0] || t.a[N - 1] != 0.5 * t.b[N - 2]) return false;
  for (std::size_t i = 1; i + 1 < N; ++i)
    if (t.a[i] != 0.5 * (t.b[i - 1] + t.b[i])) return false;
  return true;
}

/// The three-part method of a DKD composition (file comment): every kick K(g) becomes O(g/2) K(g) O(g/2).
template <std::size_t N>
constexpr OpSequence<4 * N> flatten_three(const Table<N>& t) {
  OpSequence<4 * N> s{};
  for (std::size_t i = 0; i < N; ++i) {
    s.push(Part::drift, t.a[i]);
    s.push(Part::third, 0.5 * t.b[i]);
    s.push(Part::kick, t.b[i]);
    s.push(Part::third, 0.5 * t.b[i]);
  }
  return s;
}

/// An observer that observes nothing; the engine compiles it away.
struct NullObserver {
  static constexpr bool active = false;
  template <class X>
  void operator()(long, const X&) const {}
};

/// After step i: whether the run goes on. Calls obs.poll(i) where the observer has one (a run's
/// cancellation and its sink's Flow::stop, run_support.hpp); the loop ends where it says false.
template <class Observer>
[[nodiscard]] inline bool poll(Observer& obs, long i) {
  if constexpr (requires { obs.poll(i); }) return obs.poll(i);
  else return true;
}

/// Kernel concept: `state_type`, `drift(x, tau)`, `kick(x, tau)`, `begin_step(x)`, `third(x, tau)` for
/// sequences with a third part,
/// `static constexpr bool mergeable` (false when a step depends on the state at its start), and for
/// mergeable kernels `force(x)` (one evaluation) and `apply_kick(x, tau, F)`.
template <const auto& Seq, class Kernel, class Observer>
void integrate(Kernel& k, typename Kernel::state_type& x, double h, long n, Observer& obs) {
  constexpr std::size_t M = Seq.size;
  static_assert(M >= 1, "empty splitting");
  auto apply = [&k, &x](const Op& op, double hh) {
    if (op.part == Part::kick) {
      k.kick(x, op.c * hh);
    } else if constexpr (Seq.has_third()) {
      if (op.part == Part::third) {
        k.third(x, op.c * hh);
      } else {
        k.drift(x, op.c * hh);
      }
    } else {
      k.drift(x, op.c * hh);
    }
  };
  constexpr bool share_force = Seq.fsal() && Seq.ops[0].part == Part::kick && Kernel::mergeable;
  constexpr bool merge_drift = Seq.fsal() && Seq.ops[0].part != Part::kick && Kernel::mergeable && !Observer::active;
  if constexpr (share_force) {
    if (n <= 0) return;
    auto F = k.force(x);
    for (long i = 0; i < n; ++i) {
      k.apply_kick(x, Seq.ops[0].c * h, F);
      for (std::size_t j = 1; j + 1 < M; ++j) apply(Seq.ops[j], h);
      F = k.force(x);
      k.apply_kick(x, Seq.ops[M - 1].c * h, F);
      if constexpr (Observer::active) obs(i + 1, x);
      if (!poll(obs, i + 1)) break;
    }
  } else if constexpr (merge_drift) {
    if (n <= 0) return;
    apply(Seq.ops[0], h);
    // Only an observer that observes nothing gets here: its poll says false never (a cancellation
    // leaves the run by an error), so no step ends half merged.
    for (long i = 0; i < n; ++i) {
      for (std::size_t j = 1; j + 1 < M; ++j) apply(Seq.ops[j], h);
      Op last = Seq.ops[M - 1];
      if (i + 1 < n) last.c += Seq.ops[0].c;
      apply(last, h);
      if (!poll(obs, i + 1)) break;
    }
  } else {
    for (long i = 0; i < n; ++i) {
      k.begin_step(x);
      for (std::size_t j = 0; j < M; ++j) apply(Seq.ops[j], h);
      if constexpr (Observer::active) obs(i + 1, x);
      if (!poll(obs, i + 1)) break;
    }
  }
}

}  // namespace bodypoint::splitting
