// bodypoint: the catalogue of splitting tables and the lists of tables each kernel family accepts.
//
// A table type (declared next to its coefficients, one header per source) carries what is known
// about it: a name tag, the order, the stage count (force evaluations per step when consecutive steps
// share their boundary kicks, the count papers quote) and a citation. `AllTables` lists every table;
// a family lists the tables it accepts (`LiePoissonTables`, `ThesisTables` here, the time-transformed
// ones in adaptive/), each entry a table under its own tag or under a name the family gives it. The
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

/// The Kepler split (kepler_split.hpp) takes the DKD compositions (a stage is a Kepler solve, none
/// shared between steps); being compositions, they also make its three-part methods for several centres.
using KeplerSplitTables = List<Use<StrangDkd, "verlet">, Yoshida4, Yoshida6, KahanLi6, Yoshida8, KahanLi8>;

/// The thesis's five schemes (sec. 2.5) with the published code's index slip (code_slip.hpp) of
/// each; the thesis calls Yoshida 4 "Forest-Ruth 4".
using ThesisTables = List<Euler, VerletKdk, Use<Ruth3, "", CodeSlip::third_v_z>,
                          Use<Yoshida4, "fr4", CodeSlip::third_v_z>, Use<Yoshida6, "", CodeSlip::third_vw_z>>;

/// The stage count a table type states is the one its coefficients give.
template <class... T>
constexpr bool stage_counts_match(List<T...> /*list*/) {
  return ((T::stages == static_cast<int>(ops_of<T>.kicks_merged())) && ...);
}
static_assert(stage_counts_match(AllTables{}), "a table's stated stage count differs from its coefficients");

}  // namespace bodypoint::splitting
