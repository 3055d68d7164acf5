// bodypoint: the catalogue of splitting tables and the lists of tables each kernel family accepts.
//
// A table type (declared next to its coefficients, one header per source) carries what is known
// about it: a name tag, the order, the stage count (force evaluations per step when consecutive steps
// share their boundary kicks, the count papers quote) and a citation. `AllTables` lists every table;
// a family lists the tables it accepts (`LiePoissonTables`, `ThesisTables` here, the time-transformed
// ones too), each entry a table under its own tag or under a name the family gives it; the lists of the
// Kepler split and the time transformations are AllTables filtered by what their kernels need. The
// method registry, the SIMD batch kernels, `bodypoint methods` (and the README's table from it) and
// the tests' method lists are generated from these lists, so adding a table is its header and one
// entry in `AllTables`; a family is its kernel and one list.
#pragma once

#include "bodypoint/splitting/blanes_moan.hpp"
#include "bodypoint/splitting/classic.hpp"
#include "bodypoint/splitting/code_slip.hpp"
#include "bodypoint/splitting/composition.hpp"
#include "bodypoint/splitting/kahan_li.hpp"
#include "bodypoint/splitting/mclachlan.hpp"
#include "bodypoint/splitting/omelyan.hpp"
#include "bodypoint/splitting/sofroniou_spaletta.hpp"
#include "bodypoint/splitting/suzuki.hpp"
#include "bodypoint/splitting/yoshida.hpp"

#include <cstddef>
#include <string>
#include <string_view>
#include <type_traits>

namespace bodypoint::splitting {

template <class T>
concept TableType = requires {
  { T::tag } -> std::convertible_to<std::string_view>;
  { T::title } -> std::convertible_to<std::string_view>;
  { T::citation } -> std::convertible_to<std::string_view>;
  { T::order } -> std::convertible_to<int>;
  { T::stages } -> std::convertible_to<int>;
  T::table;
};

/// A table flattened to its sub-flows; static storage, so it can be a template argument of `integrate`.
template <TableType T>
inline constexpr auto ops_of = flatten(T::table);
/// A DKD composition's three-part method (composition.hpp, flatten_three).
template <TableType T>
inline constexpr auto three_part_ops_of = flatten_three(T::table);

/// Runge-Kutta-Nystrom tables reach their order only for a kinetic part quadratic in the momenta
/// and a potential part of the positions (blanes_moan.hpp says why the body-point qualifies).
template <TableType T>
constexpr bool is_nystrom() {
  if constexpr (requires { T::nystrom; }) {
    return T::nystrom;
  } else {
    return false;
  }
}

/// A compile-time string, for names given as template arguments.
template <std::size_t N>
struct Name {
  char s[N]{};
  constexpr Name(const char (&x)[N]) {  // NOLINT(google-explicit-constructor): used as "literal"
    for (std::size_t i = 0; i < N; ++i) s[i] = x[i];
  }
  [[nodiscard]] constexpr std::string_view view() const { return {s, N - 1}; }
};

/// An entry of a family's list: table T under its own tag or under `As`, with an option `extra` of
/// the family's own (the thesis family: the index slip of the published code, thesis.hpp).
template <TableType T, Name As = "", auto Extra = 0>
struct Use {
  using type = T;
  static constexpr std::string_view tag = As.view().empty() ? T::tag : As.view();
  static constexpr auto extra = Extra;
};

template <class... E>
struct List {};

namespace detail {
template <class E>
struct AsUse {
  using type = Use<E>;
};
template <TableType T, Name As, auto Extra>
struct AsUse<Use<T, As, Extra>> {
  using type = Use<T, As, Extra>;
};
}  // namespace detail

/// An entry of a list as a Use (a bare table type T is Use<T>).
template <class E>
using entry_t = typename detail::AsUse<E>::type;

/// "family: title [citation]", the description of a method `bodypoint methods` prints.
template <TableType T>
std::string describe(std::string_view family) {
  return std::string(family) + ": " + std::string(T::title) + " [" + std::string(T::citation) + "]";
}

/// The number of entries of a list.
template <class... E>
constexpr std::size_t size(List<E...> /*list*/) {
  return sizeof...(E);
}

/// Calls f.template operator()<Use<...>>() for every entry of a list, in listing order.
template <class... E, class F>
constexpr void for_each(List<E...> /*list*/, F&& f) {
  (f.template operator()<entry_t<E>>(), ...);
}

/// Every table, in listing order.
using AllTables = List<Euler, VerletKdk, StrangDkd, Ruth3, Yoshida4, BlanesMoan4, BlanesMoanRkn4, BlanesMoanRkn6,
                       Yoshida6, KahanLi6, Yoshida8, Yoshida8D, McLachlan8, KahanLi8, SofroniouSpaletta10,
                       Suzuki4, Pefrl4>;

/// The exact Lie-Poisson splitting (lp-*) takes every table.
using LiePoissonTables = AllTables;

// A family's list is AllTables filtered by what the family's kernel needs of a table (a predicate on
// its coefficients), so that a table added to AllTables reaches every family it fits.

namespace detail {
template <template <class> class Keep, class L>
struct Filter;
template <template <class> class Keep>
struct Filter<Keep, List<>> {
  using type = List<>;
};
template <template <class> class Keep, class H, class... T>
struct Filter<Keep, List<H, T...>> {
  template <class... X>
  static List<H, X...> prepend(List<X...>);
  using rest = typename Filter<Keep, List<T...>>::type;
  using type = std::conditional_t<Keep<H>::value, decltype(prepend(rest{})), rest>;
};
template <template <class> class F, class L>
struct Map;
template <template <class> class F, class... T>
struct Map<F, List<T...>> {
  using type = List<F<T>...>;
};
}  // namespace detail

/// The entries of list L that Keep<T>::value accepts, in order; each renamed by F.
template <template <class> class Keep, class L, template <class> class F>
using filtered_t = typename detail::Map<F, typename detail::Filter<Keep, L>::type>::type;

/// Coefficients equal within this many of their own roundings count as equal (a palindrome's mirrored
/// coefficients are computed by different sums).
inline constexpr double kMirrorUlps = 8.0;

/// A symmetric step that starts and ends with a drift: the compositions a time transformation takes
/// (its drift carries the time variable; a symmetric step keeps the method time-reversible).
template <TableType T>
constexpr bool is_symmetric_drift_first() {
  constexpr const auto& s = ops_of<T>;
  if (s.size == 0 || s.ops[0].part != Part::drift) return false;
  for (std::size_t i = 0; i < s.size; ++i) {
    const Op a = s.ops[i], b = s.ops[s.size - 1 - i];
    const double scale = a.c < 0.0 ? -a.c : a.c;
    const double diff = a.c - b.c < 0.0 ? b.c - a.c : a.c - b.c;
    if (a.part != b.part || diff > kMirrorUlps * 2.220446049250313e-16 * (scale > 1.0 ? scale : 1.0)) return false;
  }
  return true;
}
template <class T>
struct IsSymmetricDriftFirst : std::bool_constant<is_symmetric_drift_first<T>()> {};
template <class T>
struct IsDkdComposition : std::bool_constant<is_dkd_composition(T::table)> {};

/// The name a drift-first family gives a table: DKD Strang is its "verlet".
template <class T>
using DriftFirstName = std::conditional_t<std::is_same_v<T, StrangDkd>, Use<StrangDkd, "verlet">, T>;

/// The Kepler split (kepler_split.hpp) takes the DKD compositions (a stage is a Kepler solve, none
/// shared between steps); being compositions, they also make its three-part methods for several centres.
using KeplerSplitTables = filtered_t<IsDkdComposition, AllTables, DriftFirstName>;

/// The time-transformed families (logH, TTL: adaptive/) take the symmetric drift-first tables.
using TimeTransformedTables = filtered_t<IsSymmetricDriftFirst, AllTables, DriftFirstName>;

/// The thesis's five schemes (sec. 2.5) with the published code's index slip (code_slip.hpp) of
/// each; the thesis calls Yoshida 4 "Forest-Ruth 4".
using ThesisTables = List<Euler, VerletKdk, Use<Ruth3, "", CodeSlip::third_v_z>,
                          Use<Yoshida4, "fr4", CodeSlip::third_v_z>, Use<Yoshida6, "", CodeSlip::third_vw_z>>;

/// The batch kernels' numbers (MethodInfo::batch_kernel; batch/batch_w.cpp runs them): RK4, then one
/// per table of ThesisTables, then one per table of LiePoissonTables, each in its list's order.
inline constexpr int kBatchRk4 = 0;
constexpr int batch_thesis_kernel(std::size_t table) { return 1 + static_cast<int>(table); }
constexpr int batch_lie_kernel(std::size_t table) {
  return 1 + static_cast<int>(size(ThesisTables{}) + table);
}
inline constexpr int kBatchKernels = batch_lie_kernel(size(LiePoissonTables{}));

/// The stage count a table type states is the one its coefficients give.
template <class... T>
constexpr bool stage_counts_match(List<T...> /*list*/) {
  return ((T::stages == static_cast<int>(ops_of<T>.kicks_merged())) && ...);
}
static_assert(stage_counts_match(AllTables{}), "a table's stated stage count differs from its coefficients");

}  // namespace bodypoint::splitting
