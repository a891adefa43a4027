// What `hamel derive` prints: the derived quantities as a JSON document (--json), as text read from that document,
// and as a LaTeX fragment in the paper's notation (--latex). Expressions are printed in structural order
// (algebra/expression_text.hpp) after ExpressionDisplay, so the text depends only on the mathematics.
#pragma once

#include "algebra/intermediates.hpp"
#include "derive/derivation.hpp"
#include "derive/riemann.hpp"
#include "model/model.hpp"

#include <ginac/ginac.h>
#include <nlohmann/json.hpp>

#include <functional>
#include <optional>
#include <ostream>

namespace hamel {

/// How derive shows an expression: with `inline_through` (--inline), expanded through that program's
/// intermediates when the result stays below 20000 nodes, and simplified; then sin/cos of single angles contracted
/// back to multiple and sum angles where shorter (algebra/contract_trig.hpp: the normal form the derivation keeps for
/// exact cancellation writes sin(3t) as 4 sin t cos² t − sin t). Values are unaffected.
struct ExpressionDisplay {
  const Intermediates* inline_through = nullptr;
  GiNaC::ex operator()(const GiNaC::ex& e) const;
};

/// The number an expression has at the point derive was given (--at and the parameters), or nothing where a symbol
/// it needs has no value.
using ValueOf = std::function<std::optional<double>(const GiNaC::ex&)>;

/// Everything derive prints, as the JSON document --json writes. `program` is the equations' intermediates, extended
/// by those of `accelerations` (u̇ as rhs computes it by a recursion, JSON key "accelerations"; empty when rhs solves
/// M u̇ = f) up to `derived`, then by the Riemannian quantities' when `riemann` is given (JSON key "riemann").
nlohmann::json derivation_json(const Model& model, const Derivation& d, const std::vector<GiNaC::ex>& accelerations,
                               const RiemannGeometry* riemann, const Intermediates& program, std::size_t derived,
                               CurvatureSign sign, const ExpressionDisplay& display, const ValueOf& value);

/// The text output: the JSON document's entries with their equation labels.
void print_derivation_text(std::ostream& out, nlohmann::json j, const Model& model, const Derivation& d);

/// `derive --latex`: the text output's quantities as a LaTeX fragment (amsmath), section by section.
void print_derivation_latex(std::ostream& out, const Model& model, const Derivation& d, CurvatureSign sign,
                            const ExpressionDisplay& display);

}  // namespace hamel
