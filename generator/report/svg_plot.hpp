// Small, dependency-free SVG line plots for the reports (phase trajectories, work-precision diagrams):
// linear or logarithmic axes with "nice" ticks, optional equal aspect, lines, markers and a legend.
#pragma once

#include <string>
#include <vector>

namespace hamel {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;
  bool line = true;
  bool markers = false;
  bool dashed = false;
};

struct PlotSpec {
  std::string title, x_label, y_label;
  bool log_x = false, log_y = false;
  bool equal_aspect = false;  ///< one unit is as long on both axes (trajectories in a plane)
  std::vector<PlotSeries> series;
};

/// The SVG document. Non-finite points (and non-positive ones on a log axis) are skipped.
std::string render_svg(const PlotSpec& spec);

/// `s` as XML/HTML character data or attribute text: <, >, & and " escaped (the reports' SVG and HTML pages).
std::string xml_escaped(const std::string& s);

}  // namespace hamel
