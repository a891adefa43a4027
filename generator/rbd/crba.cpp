#include "rbd/crba.hpp"

namespace hamel::rbd {

void composite_inertias(const TreeModel& model, CommonFrame& frame, const Namer<Ex>& name) {
  const std::size_t N = model.size();
  frame.composite = frame.inertia;
  for (std::size_t i = N; i-- > 0;) {  // children come after their parents
    if (i == 0 && model.fixed_base()) break;
    frame.composite[i] = name(frame.composite[i]);
    if (i > 0) frame.composite[static_cast<std::size_t>(model.parent[i])].add(frame.composite[i]);
  }
}

GiNaC::matrix mass_matrix(const TreeModel& model, const CommonFrame& frame, const Namer<Ex>& name) {
  const std::size_t m = model.base.size(), N = model.size(), d = m + N - 1;
  GiNaC::matrix M(static_cast<unsigned>(d), static_cast<unsigned>(d));
  const auto set = [&](std::size_t r, std::size_t c, const Ex& v) {
    M(static_cast<unsigned>(r), static_cast<unsigned>(c)) = v;
    M(static_cast<unsigned>(c), static_cast<unsigned>(r)) = v;
  };
  const std::vector<Vec6<Ex>>& e = model.base;
  for (std::size_t alpha = 0; alpha < m; ++alpha)
    for (std::size_t beta = alpha; beta < m; ++beta) set(alpha, beta, dot(e[alpha], frame.composite[0](e[beta])));
  for (std::size_t i = 1; i < N; ++i) {
    const Vec6<Ex> U = name(frame.composite[i](frame.axis[i]));
    set(m + i - 1, m + i - 1, dot(frame.axis[i], U) + model.armature[i]);
    for (std::size_t j = static_cast<std::size_t>(model.parent[i]); j != 0;
         j = static_cast<std::size_t>(model.parent[j]))
      set(m + j - 1, m + i - 1, dot(frame.axis[j], U));
    for (std::size_t alpha = 0; alpha < m; ++alpha) set(alpha, m + i - 1, dot(e[alpha], U));
  }
  return M;
}

}  // namespace hamel::rbd
