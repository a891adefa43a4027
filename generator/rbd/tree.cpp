#include "rbd/tree.hpp"

#include "algebra/simplify.hpp"

namespace hamel::rbd {

Inertia<Ex> spatial_inertia(const BodyInertia& b) {
  const Mat3<Ex> C = skew(b.com);
  Inertia<Ex> I;
  I.m = b.mass;
  for (std::size_t r = 0; r < 3; ++r) {
    I.h[r] = expand_keeping_powers_of_sums(b.mass * b.com[r]);
    for (std::size_t k = 0; k < 3; ++k) {
      Ex cc = 0;
      for (std::size_t j = 0; j < 3; ++j) cc += C[r][j] * C[j][k];
      I.J[r][k] = expand_keeping_powers_of_sums(b.rotational[r][k] - b.mass * cc);
    }
  }
  return I;
}

bool TreeModel::has_external() const {
  for (const Vec6<Ex>& w : external)
    for (const Ex& e : w)
      if (!e.is_zero()) return true;
  return false;
}

FrameView::FrameView(const TreeModel& model) : model_(model), convention_(Frame::local), external_(model.external) {}

FrameView::FrameView(const TreeModel& model, const CommonFrame& frame, const Namer<Ex>& name)
    : model_(model), frame_(&frame), convention_(Frame::world) {
  for (std::size_t i = 0; i < model.size(); ++i) {
    const Vec6<Ex>& w = model.external[i];
    bool zero = true;
    for (const Ex& e : w) zero = zero && e.is_zero();
    external_.push_back(zero ? zero6<Ex>() : name(Link<Ex>{frame.R[i], frame.p[i]}.to_parent(w)));
  }
}

}  // namespace hamel::rbd
