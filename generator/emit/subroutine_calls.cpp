#include "emit/subroutine_calls.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace hamel {

std::vector<int> result_offsets(const Subroutine& sub) {
  const auto pattern = [](const Subroutine::Call& call) {
    std::vector<int> d;
    for (int r : call.results) d.push_back(r - call.results.front());
    return d;
  };
  const std::vector<int> offset = pattern(sub.calls.front());
  std::vector<int> sorted = offset;
  std::sort(sorted.begin(), sorted.end());
  bool regular = sub.calls.front().results.front() >= 0 && sorted.front() == 0 &&
                 std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end();
  for (const Subroutine::Call& call : sub.calls)
    regular = regular && call.results.front() >= 0 && pattern(call) == offset;
  if (!regular) throw std::logic_error("a subroutine's calls place their results in different patterns");
  return offset;
}

StageBeforeCalls stage_before_calls(const Kernel& k, const Subroutine& sub) {
  StageBeforeCalls staged{{k.name + "_stage", "", {}, {}, nullptr}, {}, {}};
  Kernel& stage = staged.kernel;
  std::vector<std::size_t>&direct = staged.direct, &slot = staged.slot;
  std::vector<bool> by_call(k.outputs.size(), false);
  for (const Subroutine::Call& call : sub.calls)
    for (int r : call.results)
      if (r >= 0) by_call[static_cast<std::size_t>(r)] = true;
  for (std::size_t o = 0; o < k.outputs.size(); ++o) {
    if (by_call[o]) continue;
    stage.outputs.push_back(k.outputs[o]);
    stage.output_names.push_back(k.output_names[o]);
    direct.push_back(o);
  }
  for (std::size_t j = 0; j < sub.shared.size(); ++j) {
    stage.outputs.push_back(sub.shared[j]);
    stage.output_names.push_back("shared " + std::to_string(j));
    slot.push_back(j);
  }
  const std::size_t lanes = sub.lanes;
  for (std::size_t c = 0; c < sub.calls.size(); ++c) {
    const std::vector<int>& arguments = sub.calls[c].arguments;
    const std::size_t per_lane = arguments.size() / lanes;
    for (std::size_t l = 0; l < lanes; ++l)
      for (std::size_t a = 0; a < per_lane; ++a) {
        stage.outputs.push_back(arguments[a * lanes + l]);
        stage.output_names.push_back("call " + std::to_string(c) + ", argument " + std::to_string(a) +
                                     (lanes > 1 ? ", lane " + std::to_string(l) : std::string()));
        slot.push_back(sub.shared.size() + c * arguments.size() + a * lanes + l);
      }
  }
  return staged;
}

}  // namespace hamel
