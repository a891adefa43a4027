// Intermediate symbols: a straight-line program of named subexpressions (s_k := e_k, each e_k in the
// model's symbols and earlier s_j), the way a derivation avoids expression swell. A recursive derivation
// (derive/kinematic_tree.cpp) names every body's rotation, twist, momentum and composite inertia here,
// so each expression stays a few operations long and the whole program grows with the tree, not with
// the expanded formula. Differentiation follows the chain rule through the definitions (forward mode,
// memoized), so derivatives are programs of the same kind; the emitter turns the definitions into graph
// nodes before anything that uses them (emit/kernels.cpp).
#pragma once

#include <ginac/ginac.h>

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace hamel {

class Intermediates {
 public:
  struct Definition {
    GiNaC::realsymbol symbol;
    GiNaC::ex value;
  };

  /// `value` itself when it is a number or a symbol, otherwise a fresh symbol defined as `value`.
  GiNaC::ex define(const GiNaC::ex& value);

  /// A definition with a name of the user's (model key `definitions`), even when `value` is atomic.
  GiNaC::realsymbol define_named(const std::string& name, const GiNaC::ex& value);

  /// Applies `map` (symbols of the model → numbers, e.g. folded parameters) to every definition in place.
  void substitute_in_definitions(const GiNaC::exmap& map);

  /// `value` simplified when it is small (algebra/simplify.hpp, simplify_bounded) and kept inline when the
  /// result has at most `inline_size` nodes; otherwise defined as a new intermediate. Every derivation step
  /// passes its results through here, so small models keep readable closed forms and large ones stay a
  /// program that grows with the model, not with the expanded formula.
  GiNaC::ex keep(const GiNaC::ex& value, std::size_t inline_size = 24);

  /// `e` as one small closed form in the model's symbols, if it has one: inlined through the definitions (at most
  /// `inlined` nodes) and brought to its normal form (algebra/simplify.hpp), or left inlined where that is smaller;
  /// nothing when neither has at most `kept` nodes. Where a derivation multiplies out to little (a body's kinetic
  /// energy with RᵀR = I and sin² + cos² = 1 unapplied in its program) this finds it; a program whose closed form is
  /// large stays a program, which shares its subexpressions.
  std::optional<GiNaC::ex> closed_form(const GiNaC::ex& e, std::size_t inlined = 2000, std::size_t kept = 400) const;

  /// The definition of `e` if it is an intermediate symbol.
  std::optional<GiNaC::ex> definition_of(const GiNaC::ex& e) const;

  const std::vector<Definition>& definitions() const { return definitions_; }
  std::size_t size() const { return definitions_.size(); }
  bool empty() const { return definitions_.empty(); }
  bool is_intermediate(const GiNaC::ex& e) const { return position_.count(e) > 0; }

  /// Positions of the intermediates `e` uses directly (not through other definitions), ascending.
  std::vector<std::size_t> used_by(const GiNaC::ex& e) const;

  /// d e / d x by the chain rule through the definitions; derivatives of intermediates become new
  /// definitions (memoized per intermediate and variable). Without intermediates this is e.diff(x).
  GiNaC::ex diff(const GiNaC::ex& e, const GiNaC::symbol& x);
  /// d e / d x for every x of `xs`, in order: as diff(e, x) each, but e's partial derivatives with respect to
  /// the intermediates it uses are formed once (as they are for every definition), not once per variable.
  std::vector<GiNaC::ex> diff(const GiNaC::ex& e, const std::vector<GiNaC::symbol>& xs);

  /// `e` with `map` (symbols of the model → expressions) applied, also inside the definitions `e` uses:
  /// a definition that changes becomes a new intermediate, one that does not stays as it is. Memoized in
  /// `memo` (one per map) across calls.
  struct SubstitutionMemo {
    std::vector<std::optional<GiNaC::ex>> replaced;  ///< by position
  };
  GiNaC::ex substitute(const GiNaC::ex& e, const GiNaC::exmap& map, SubstitutionMemo& memo);

  /// inline_all(e) if that has at most `limit` nodes, else nothing; never builds anything larger (a
  /// definition whose inlined form exceeds the limit is remembered as such).
  std::optional<GiNaC::ex> inline_bounded(const GiNaC::ex& e, std::size_t limit) const;

  /// `e` with every intermediate replaced by its definition, recursively: one expression in the model's
  /// symbols. It can be exponentially larger than the program; for small systems and cross-checks.
  GiNaC::ex inline_all(const GiNaC::ex& e) const;

  /// Numeric values of all intermediates at `values` (symbol → number), evaluated in order with evalf at
  /// the current GiNaC precision; the result extends `values`.
  GiNaC::exmap evaluate(const GiNaC::exmap& values) const;

  /// The value of `e` at `values` (symbols of the model → numbers), evaluated with evalf through only the
  /// definitions it uses, in order and iteratively (the program may be deep), never by inlining them: a definition
  /// that does not evaluate to a number stays its symbol, so the result is then not a number, but never large.
  /// Memoized in `memo` (one per `values`) across calls; floating-point overflow and the like propagate as
  /// exceptions.
  struct ValueMemo {
    std::vector<std::optional<GiNaC::ex>> value;  ///< by position
  };
  GiNaC::ex value_at(const GiNaC::ex& e, const GiNaC::exmap& values, ValueMemo& memo) const;

 private:
  std::vector<Definition> definitions_;
  std::map<GiNaC::ex, std::size_t, GiNaC::ex_is_less> position_;
  struct KeyLess {  // std::pair's operator< would call GiNaC's ex < ex, which builds a relational
    bool operator()(const std::pair<std::size_t, GiNaC::ex>& a, const std::pair<std::size_t, GiNaC::ex>& b) const {
      if (a.first != b.first) return a.first < b.first;
      return GiNaC::ex_is_less()(a.second, b.second);
    }
  };
  std::map<std::pair<std::size_t, GiNaC::ex>, GiNaC::ex, KeyLess> derivative_memo_;
  /// ∂e/∂s_k for the intermediates s_k an expression uses directly (nonzero or not), with k.
  using Partials = std::vector<std::pair<std::size_t, GiNaC::ex>>;
  Partials partials_of(const GiNaC::ex& e) const;
  /// explicit_part + Σ_k ∂e/∂s_k · ds_k/dx, the ds_k/dx memoized definitions.
  GiNaC::ex chain_rule(const GiNaC::ex& explicit_part, const Partials& partials, const GiNaC::symbol& x);
  std::vector<std::optional<Partials>> partials_;                // of each definition's value, by position, formed once
  mutable std::vector<std::optional<GiNaC::ex>> inlined_;        // cache for inline_all, by position
  mutable std::vector<std::optional<GiNaC::ex>> small_inlined_;  // inline_bounded's cache (by position)
  mutable std::vector<std::size_t> small_limit_;                 // the limit each entry was computed with
};

}  // namespace hamel
