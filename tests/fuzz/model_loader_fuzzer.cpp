// libFuzzer target for the model front end: the YAML loader (load_model_from_text, with every check
// it makes), the A(q)/B checks of derive_quasi_velocities for small models, and the expression parser
// on the raw bytes. Any outcome other than success or hamel::InputError from the loader (another
// exception, a crash, a sanitizer report, a hang) is a bug: the CLI would report it as an internal
// error (exit 1) or die. Build and run with tools/fuzz.sh.
#include "derive/quasi_velocities.hpp"
#include "model/expression_parser.hpp"
#include "model/input_error.hpp"
#include "model/load_model.hpp"

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const hamel::Model model = hamel::load_model_from_text(text, "fuzz.yaml");
    // Symbolic determinants grow factorially; the checks are the same for any size.
    if (model.n() <= 3) (void)hamel::derive_quasi_velocities(model);
  } catch (const hamel::InputError&) {
    // expected: bad input reported as such
  }

  // The expression front end on its own. The loader turns any std::exception of the parser into an
  // InputError, so only crashes and sanitizer reports count here.
  static const GiNaC::realsymbol x("x"), y("y"), m("m"), x_dot("x_dot");
  static const GiNaC::symtab table = {{"x", x}, {"y", y}, {"m", m}, {"x_dot", x_dot}};
  try {
    const GiNaC::ex e = hamel::parse_expression(text, table);
    (void)hamel::unsupported_part(e);
  } catch (const std::exception&) {
  }
  return 0;
}
