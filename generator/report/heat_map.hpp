// A dependency-free SVG heat map with curves over it: a scalar field sampled on a grid, coloured on a
// diverging scale symmetric about zero (blue negative, white zero, red positive) with a colour bar, and
// lines (a gait's path) drawn on top — the way Hatton's sysplotter shows a gait over its curvature.
#pragma once

#include "report/svg_plot.hpp"

#include <string>
#include <vector>

namespace hamel {

struct HeatMapSpec {
  std::string title, x_label, y_label, value_label;
  std::vector<double> xs, ys;      ///< grid coordinates (increasing)
  std::vector<double> values;      ///< values[iy * xs.size() + ix]
  std::vector<PlotSeries> curves;  ///< lines (and markers) on top, in the same coordinates
};

/// The SVG document. Non-finite values are drawn grey.
std::string render_heat_map_svg(const HeatMapSpec& spec);

}  // namespace hamel
