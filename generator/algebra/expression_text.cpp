#include "algebra/expression_text.hpp"

#include <algorithm>
#include <memory>
#include <sstream>
#include <unordered_map>
#include <utility>
#include <vector>

namespace hamel {

using GiNaC::ex;
using GiNaC::ex_to;
using GiNaC::is_a;
using GiNaC::numeric;

namespace {

// GiNaC's precedences (add.h, mul.h, power.h, container.h): what decides its parentheses.
constexpr unsigned add_precedence = 40, mul_precedence = 50, power_precedence = 60;

struct Node;
using Ptr = std::shared_ptr<const Node>;

// An expression in canonical form: operands sorted structurally, signs of sums moved out where that is an identity.
struct Node {
  // Also the order of kinds: numbers first, sums and products after the atoms and functions.
  enum Kind { number, symbol, constant, function, add, mul, power };
  Kind kind = number;
  ex object;                          // number, constant, other: the object; function: the function (for printing)
  std::string name;                   // symbol: its name; function: its name
  numeric coefficient;                // add: the constant term; mul: the numeric factor
  std::vector<Ptr> operands;          // add: the terms' monomials; mul: factors; power: base, exponent; function: args
  std::vector<numeric> coefficients;  // add: the terms' coefficients, with `operands`
};

template <class T>
int three_way(const T& a, const T& b) {
  return a < b ? -1 : b < a ? 1 : 0;
}

int compare(const Node& a, const Node& b);

int compare_numbers(const numeric& a, const numeric& b) {
  if (const int c = a.compare(b)) return c;  // by value
  return three_way(!a.is_rational(), !b.is_rational());
}

const Node& base_of(const Node& factor) { return factor.kind == Node::power ? *factor.operands[0] : factor; }

const Node& exponent_of(const Node& factor) {
  static const Node one{Node::number, numeric(1), "", 0, {}, {}};
  return factor.kind == Node::power ? *factor.operands[1] : one;
}

// Factors of a product: by base, then by exponent (a factor that is no power has exponent 1).
int compare_factors(const Node& a, const Node& b) {
  if (const int c = compare(base_of(a), base_of(b))) return c;
  return compare(exponent_of(a), exponent_of(b));
}

// The factors of a monomial (a term of a sum without its coefficient).
std::vector<const Node*> factors_of(const Node& m) {
  std::vector<const Node*> out;
  if (m.kind == Node::mul)
    for (const Ptr& f : m.operands) out.push_back(f.get());
  else
    out.push_back(&m);
  return out;
}

// Monomials: their factors compared in turn, a prefix first (x before x*y before y).
int compare_monomials(const Node& a, const Node& b) {
  const std::vector<const Node*> fa = factors_of(a), fb = factors_of(b);
  for (std::size_t k = 0; k < fa.size() && k < fb.size(); ++k)
    if (const int c = compare_factors(*fa[k], *fb[k])) return c;
  return three_way(fa.size(), fb.size());
}

int compare_lists(const std::vector<Ptr>& a, const std::vector<Ptr>& b, int (*by)(const Node&, const Node&)) {
  for (std::size_t k = 0; k < a.size() && k < b.size(); ++k)
    if (const int c = by(*a[k], *b[k])) return c;
  return three_way(a.size(), b.size());
}

int compare(const Node& a, const Node& b) {
  if (a.kind != b.kind) return three_way(a.kind, b.kind);
  switch (a.kind) {
    case Node::number:
      return compare_numbers(ex_to<numeric>(a.object), ex_to<numeric>(b.object));
    case Node::symbol:
    case Node::constant:
      return three_way(a.name, b.name);
    case Node::function:
      if (const int c = three_way(a.name, b.name)) return c;
      return compare_lists(a.operands, b.operands, compare);
    case Node::add:
      for (std::size_t k = 0; k < a.operands.size() && k < b.operands.size(); ++k) {
        if (const int c = compare_monomials(*a.operands[k], *b.operands[k])) return c;
        if (const int c = compare_numbers(a.coefficients[k], b.coefficients[k])) return c;
      }
      if (const int c = three_way(a.operands.size(), b.operands.size())) return c;
      return compare_numbers(a.coefficient, b.coefficient);
    case Node::mul:
      if (const int c = compare_lists(a.operands, b.operands, compare_factors)) return c;
      return compare_numbers(a.coefficient, b.coefficient);
    case Node::power:
      return compare_lists(a.operands, b.operands, compare);
  }
  return 0;
}

Ptr number_node(const numeric& v) {
  auto n = std::make_shared<Node>();
  n->kind = Node::number;
  n->object = v;
  return n;
}

// A sum whose first printed term (the constant, else the first term) is negative.
bool leads_negative(const Node& n) {
  switch (n.kind) {
    case Node::number:
      return ex_to<numeric>(n.object).csgn() < 0;
    case Node::mul:
      return n.coefficient.csgn() < 0;
    case Node::add:
      return !n.coefficient.is_zero() ? n.coefficient.csgn() < 0 : n.coefficients.front().csgn() < 0;
    default:
      return false;
  }
}

void sort_terms(Node& sum) {
  std::vector<std::size_t> order(sum.operands.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
    if (const int c = compare_monomials(*sum.operands[i], *sum.operands[j])) return c < 0;
    return compare_numbers(sum.coefficients[i], sum.coefficients[j]) < 0;
  });
  std::vector<Ptr> operands;
  std::vector<numeric> coefficients;
  for (std::size_t k : order) operands.push_back(sum.operands[k]), coefficients.push_back(sum.coefficients[k]);
  sum.operands = std::move(operands);
  sum.coefficients = std::move(coefficients);
}

// −n for a number, a product or a sum (the only kinds leads_negative() can be true for).
Ptr negated(const Node& n) {
  if (n.kind == Node::number) return number_node(-ex_to<numeric>(n.object));
  auto out = std::make_shared<Node>(n);
  out->coefficient = -n.coefficient;
  if (n.kind == Node::add) {
    for (numeric& c : out->coefficients) c = -c;
    sort_terms(*out);
  }
  return out;
}

void sort_factors(std::vector<Ptr>& factors) {
  std::stable_sort(factors.begin(), factors.end(),
                   [](const Ptr& a, const Ptr& b) { return compare_factors(*a, *b) < 0; });
}

// coefficient · Π factors, flattened and sorted; a lone factor or number as itself.
Ptr product(numeric coefficient, const std::vector<Ptr>& factors) {
  std::vector<Ptr> flat;
  for (const Ptr& f : factors) {
    if (f->kind == Node::mul) {
      coefficient *= f->coefficient;
      flat.insert(flat.end(), f->operands.begin(), f->operands.end());
    } else if (f->kind == Node::number) {
      coefficient *= ex_to<numeric>(f->object);
    } else {
      flat.push_back(f);
    }
  }
  if (flat.empty() || coefficient.is_zero()) return number_node(coefficient);
  if (flat.size() == 1 && coefficient.is_equal(1)) return flat.front();
  sort_factors(flat);
  auto n = std::make_shared<Node>();
  n->kind = Node::mul;
  n->coefficient = coefficient;
  n->operands = std::move(flat);
  return n;
}

Ptr power_node(const Ptr& base, const Ptr& exponent) {
  auto n = std::make_shared<Node>();
  n->kind = Node::power;
  n->operands = {base, exponent};
  return n;
}

class Canonical {
 public:
  Ptr of(const ex& e) {
    if (auto it = memo_.find(e); it != memo_.end()) return it->second;
    Ptr n = compute(e);
    memo_.emplace(e, n);
    return n;
  }

 private:
  Ptr compute(const ex& e) {
    if (is_a<numeric>(e)) return number_node(ex_to<numeric>(e));
    auto n = std::make_shared<Node>();
    if (is_a<GiNaC::symbol>(e)) {
      n->kind = Node::symbol;
      n->name = ex_to<GiNaC::symbol>(e).get_name();
      return n;
    }
    if (is_a<GiNaC::add>(e)) return sum(e);
    if (is_a<GiNaC::mul>(e)) {
      numeric coefficient = 1;
      std::vector<Ptr> factors;
      for (std::size_t i = 0; i < e.nops(); ++i) {
        const Ptr f = of(e.op(i));
        if (f->kind == Node::add && leads_negative(*f)) {
          coefficient = -coefficient;
          factors.push_back(negated(*f));
        } else {
          factors.push_back(f);
        }
      }
      return product(coefficient, factors);
    }
    if (is_a<GiNaC::power>(e)) return power(of(e.op(0)), of(e.op(1)));
    if (is_a<GiNaC::function>(e)) return function(e);
    // Constants (Pi) and anything else: GiNaC's printing, ordered by its text.
    n->kind = Node::constant;
    n->object = e;
    std::ostringstream text;
    e.print(GiNaC::print_dflt(text));
    n->name = text.str();
    return n;
  }

  Ptr sum(const ex& e) {
    auto n = std::make_shared<Node>();
    n->kind = Node::add;
    n->coefficient = 0;
    for (std::size_t i = 0; i < e.nops(); ++i) {
      const Ptr t = of(e.op(i));
      if (t->kind == Node::number) {
        n->coefficient += ex_to<numeric>(t->object);
      } else if (t->kind == Node::mul && !t->coefficient.is_equal(1)) {
        n->coefficients.push_back(t->coefficient);
        n->operands.push_back(product(1, t->operands));
      } else {
        n->coefficients.push_back(1);
        n->operands.push_back(t);
      }
    }
    if (n->operands.empty()) return number_node(n->coefficient);
    sort_terms(*n);
    return n;
  }

  // base^exponent; for an integer exponent the sign of a sum or the coefficient of a product moves out.
  Ptr power(const Ptr& base, const Ptr& exponent) {
    if (exponent->kind == Node::number && ex_to<numeric>(exponent->object).is_integer()) {
      const numeric& k = ex_to<numeric>(exponent->object);
      if (base->kind == Node::add && leads_negative(*base))
        return product(k.is_even() ? 1 : -1, {power_node(negated(*base), exponent)});
      if (base->kind == Node::mul && !base->coefficient.is_equal(1))
        return product(GiNaC::pow(base->coefficient, k), {power_node(product(1, base->operands), exponent)});
    }
    return power_node(base, exponent);
  }

  // sin, cos and tan of an argument whose first term is negative: the argument negated (sin(−x) = −sin x).
  Ptr function(const ex& e) {
    auto n = std::make_shared<Node>();
    n->kind = Node::function;
    n->object = e;
    n->name = ex_to<GiNaC::function>(e).get_name();
    for (std::size_t i = 0; i < e.nops(); ++i) n->operands.push_back(of(e.op(i)));
    const bool odd = n->name == "sin" || n->name == "tan", even = n->name == "cos";
    if ((odd || even) && n->operands.size() == 1 && leads_negative(*n->operands[0])) {
      n->operands[0] = negated(*n->operands[0]);
      if (odd) return product(-1, {n});
    }
    return n;
  }

  struct Hash {
    std::size_t operator()(const ex& e) const { return e.gethash(); }
  };
  std::unordered_map<ex, Ptr, Hash, GiNaC::ex_is_equal> memo_;  // lookups only: its order is never used
};

// Prints a canonical expression with GiNaC's operators, precedences and parentheses (add.cpp, mul.cpp, power.cpp).
class Printer {
 public:
  Printer(bool latex, const std::function<std::string(const std::string&)>* symbol_tex)
      : latex_(latex), symbol_tex_(symbol_tex) {}

  void print(const Node& n, unsigned level) {
    switch (n.kind) {
      case Node::number:
      case Node::constant:
        print_ginac(n.object, level);
        return;
      case Node::symbol:
        os_ << (latex_ ? (*symbol_tex_)(n.name) : n.name);
        return;
      case Node::function:
        return print_function(n);
      case Node::add:
        return print_add(n, level);
      case Node::mul:
        return latex_ ? print_mul_latex(n, level) : print_mul(n, level);
      case Node::power:
        return latex_ ? print_power_latex(n, level) : print_power(n, level);
    }
  }
  std::string text() const { return os_.str(); }

 private:
  void print_ginac(const ex& e, unsigned level) {
    if (latex_) {
      GiNaC::print_latex c(os_);
      e.print(c, level);
    } else {
      GiNaC::print_dflt c(os_);
      e.print(c, level);
    }
  }
  void print_number(const numeric& v, unsigned level) { print_ginac(v, level); }
  void open(unsigned precedence, unsigned level) {
    if (precedence <= level) os_ << (latex_ ? "{(" : "(");
  }
  void close(unsigned precedence, unsigned level) {
    if (precedence <= level) os_ << (latex_ ? ")}" : ")");
  }

  // GiNaC prints the function with placeholder arguments; each placeholder is then replaced by the argument.
  void print_function(const Node& n) {
    GiNaC::exvector placeholders;
    std::vector<std::string> marks;
    for (std::size_t k = 0; k < n.operands.size(); ++k) {
      marks.push_back("\x01" + std::to_string(k) + "\x02");
      placeholders.push_back(GiNaC::symbol(marks.back(), marks.back()));
    }
    std::ostringstream head;
    const ex f = GiNaC::function(ex_to<GiNaC::function>(n.object).get_serial(), placeholders);
    if (latex_) {
      GiNaC::print_latex c(head);
      f.print(c);
    } else {
      GiNaC::print_dflt c(head);
      f.print(c);
    }
    const std::string s = head.str();
    std::size_t done = 0;
    while (done < s.size()) {
      const std::size_t at = s.find('\x01', done);
      if (at == std::string::npos) break;
      const std::size_t end = s.find('\x02', at);
      os_ << s.substr(done, at - done);
      print(*n.operands[static_cast<std::size_t>(std::stoul(s.substr(at + 1, end - at - 1)))], 0);
      done = end + 1;
    }
    os_ << s.substr(done);
  }

  void print_add(const Node& n, unsigned level) {
    open(add_precedence, level);
    bool first = true;
    if (!n.coefficient.is_zero()) {
      print_number(n.coefficient, 0);
      first = false;
    }
    for (std::size_t k = 0; k < n.operands.size(); ++k) {
      const numeric& c = n.coefficients[k];
      if (c.csgn() < 0)
        os_ << '-';
      else if (!first)
        os_ << '+';
      first = false;
      if (!c.is_equal(1) && !c.is_equal(-1)) {
        print_number(c.csgn() < 0 ? -c : c, c.is_rational() ? 0 : add_precedence);
        os_ << (latex_ ? " " : "*");
      }
      print(*n.operands[k], add_precedence);
    }
    close(add_precedence, level);
  }

  void print_coefficient(const numeric& c, const char* times) {
    if (c.csgn() < 0) os_ << '-';
    if (c.is_equal(1) || c.is_equal(-1)) return;
    print_number(c.csgn() < 0 ? -c : c, c.is_rational() ? 0 : mul_precedence);
    os_ << times;
  }

  void print_mul(const Node& n, unsigned level) {
    open(mul_precedence, level);
    print_coefficient(n.coefficient, "*");
    for (std::size_t k = 0; k < n.operands.size(); ++k) {
      if (k) os_ << '*';
      print(*n.operands[k], mul_precedence);
    }
    close(mul_precedence, level);
  }

  static bool negative_exponent(const Node& f) {
    return f.kind == Node::power && f.operands[1]->kind == Node::number &&
           ex_to<numeric>(f.operands[1]->object).csgn() < 0;
  }
  // base^(−k) as base^k (base itself for k = −1).
  static Ptr inverted(const Node& f) {
    const numeric k = -ex_to<numeric>(f.operands[1]->object);
    return k.is_equal(1) ? f.operands[0] : power_node(f.operands[0], number_node(k));
  }
  // A product of factors with coefficient 1 at level 0: GiNaC's mul(factors).eval().print(c).
  void print_factors_latex(const std::vector<Ptr>& factors) {
    if (factors.empty()) {
      os_ << "1";
    } else if (factors.size() == 1) {
      print(*factors.front(), 0);
    } else {
      for (const Ptr& f : factors) {
        os_ << ' ';
        print(*f, mul_precedence);
      }
    }
  }

  void print_mul_latex(const Node& n, unsigned level) {
    open(mul_precedence, level);
    print_coefficient(n.coefficient, " ");
    std::vector<Ptr> denominator, others;
    for (const Ptr& f : n.operands) {
      if (negative_exponent(*f))
        denominator.push_back(inverted(*f));
      else
        others.push_back(f);
    }
    if (!denominator.empty()) {
      os_ << "\\frac{";
      print_factors_latex(others);
      os_ << "}{";
      print_factors_latex(denominator);
      os_ << "}";
    } else {
      for (const Ptr& f : others) {
        os_ << ' ';
        print(*f, mul_precedence);
      }
    }
    close(mul_precedence, level);
  }

  static bool is_half(const Node& exponent) {
    return exponent.kind == Node::number && ex_to<numeric>(exponent.object).is_equal(numeric(1, 2));
  }

  void print_power(const Node& n, unsigned level) {
    if (is_half(*n.operands[1])) {
      os_ << "sqrt(";
      print(*n.operands[0], 0);
      os_ << ')';
      return;
    }
    open(power_precedence, level);
    print(*n.operands[0], power_precedence);
    os_ << '^';
    print(*n.operands[1], power_precedence);
    close(power_precedence, level);
  }

  void print_power_latex(const Node& n, unsigned level) {
    if (negative_exponent(n)) {
      os_ << "\\frac{1}{";
      print(*inverted(n), 0);
      os_ << '}';
    } else if (is_half(*n.operands[1])) {
      os_ << "\\sqrt{";
      print(*n.operands[0], 0);
      os_ << '}';
    } else {
      open(power_precedence, level);
      print(*n.operands[0], power_precedence);
      os_ << "^{";
      print(*n.operands[1], power_precedence);
      os_ << '}';
      close(power_precedence, level);
    }
  }

  bool latex_;
  const std::function<std::string(const std::string&)>* symbol_tex_;
  std::ostringstream os_;
};

}  // namespace

std::string to_text(const ex& e) {
  Canonical canonical;
  Printer printer(false, nullptr);
  printer.print(*canonical.of(e), 0);
  return printer.text();
}

bool structurally_less(const ex& a, const ex& b) {
  Canonical canonical;
  return compare(*canonical.of(a), *canonical.of(b)) < 0;
}

struct StructuralOrder::Forms : Canonical {};
StructuralOrder::StructuralOrder() : forms_(std::make_unique<Forms>()) {}
StructuralOrder::~StructuralOrder() = default;
bool StructuralOrder::operator()(const ex& a, const ex& b) { return compare(*forms_->of(a), *forms_->of(b)) < 0; }

std::string to_latex(const ex& e, const std::function<std::string(const std::string&)>& symbol_tex) {
  Canonical canonical;
  Printer printer(true, &symbol_tex);
  printer.print(*canonical.of(e), 0);
  return printer.text();
}

}  // namespace hamel
