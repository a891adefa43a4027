#include "rbd/aba.hpp"

namespace hamel::rbd {

ArticulatedFactor articulated_factor(const FrameView& view, const Namer<Ex>& name) {
  const TreeModel& model = view.model();
  const std::size_t N = view.size(), m = model.base.size();
  const bool local = view.convention() == Frame::local;
  std::vector<Mat6<Ex>> IA(N);
  std::vector<bool> inner(N, false);  // has children: its 𝕀ᴬ is a sum, named
  for (std::size_t i = 0; i < N; ++i) {
    IA[i] = view.inertia(i).matrix();
    if (i > 0) inner[static_cast<std::size_t>(model.parent[i])] = true;
  }
  ArticulatedFactor f;
  f.U.assign(N, zero6<Ex>());
  f.W.assign(N, zero6<Ex>());
  f.D.assign(N, Ex(0));
  f.inverse_D.assign(N, Ex(0));
  if (local) f.passed.resize(N);
  for (std::size_t i = N; i-- > 1;) {
    if (inner[i]) IA[i] = name.symmetric(IA[i]);
    const Vec6<Ex>& s = view.axis(i);
    const Vec6<Ex> U = f.U[i] = name(times(IA[i], s));
    f.D[i] = name(dot(s, U) + model.armature[i]);
    const Ex inverse_D = f.inverse_D[i] = name(1 / f.D[i]);
    f.W[i] = name(U * inverse_D);
    const std::size_t l = static_cast<std::size_t>(model.parent[i]);
    if (l == 0 && m == 0) continue;  // a fixed base takes nothing
    const Mat6<Ex> passed = articulated_remainder(IA[i], U, f.W[i]);
    if (local) {
      f.passed[i] = name.symmetric(passed);
      IA[l] = IA[l] + inertia_to_parent(model.link[i], f.passed[i], name);
    } else {
      IA[l] = IA[l] + passed;
    }
  }
  if (m > 0) {
    f.base = IA[0] = name.symmetric(IA[0]);
    f.base_inertia.assign(m, std::vector<Ex>(m));
    for (std::size_t alpha = 0; alpha < m; ++alpha)
      for (std::size_t beta = 0; beta < m; ++beta)
        f.base_inertia[alpha][beta] = dot(model.base[alpha], times(IA[0], model.base[beta]));
  }
  return f;
}

}  // namespace hamel::rbd
