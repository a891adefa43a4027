#include "report/heat_map.hpp"

#include "report/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>

namespace hamel {

namespace {

std::string number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", v);
  return buffer;
}

// Diverging colour of s in [−1, 1]: blue, white, red.
std::string colour(double s) {
  if (!std::isfinite(s)) return "#bbbbbb";
  s = std::clamp(s, -1.0, 1.0);
  const double a = std::abs(s);
  const int fade = static_cast<int>(std::lround(255 * (1 - a)));
  const int strong = static_cast<int>(std::lround(255 * (1 - 0.45 * a)));
  char buffer[8];
  if (s >= 0)
    std::snprintf(buffer, sizeof buffer, "#%02x%02x%02x", strong, fade, fade);
  else
    std::snprintf(buffer, sizeof buffer, "#%02x%02x%02x", fade, fade, strong);
  return buffer;
}

}  // namespace

std::string render_heat_map_svg(const HeatMapSpec& spec) {
  const double left = 80, top = 50, width = 440, height = 440, bar_x = left + width + 40;
  const std::size_t nx = spec.xs.size(), ny = spec.ys.size();
  const double x0 = spec.xs.front(), x1 = spec.xs.back(), y0 = spec.ys.front(), y1 = spec.ys.back();
  const auto X = [&](double x) { return left + (x - x0) / (x1 - x0) * width; };
  const auto Y = [&](double y) { return top + height - (y - y0) / (y1 - y0) * height; };
  double scale = 0;
  for (double v : spec.values)
    if (std::isfinite(v)) scale = std::max(scale, std::abs(v));
  if (scale == 0) scale = 1;

  std::ostringstream s;
  s << std::fixed << std::setprecision(1);
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"680\" height=\"600\" viewBox=\"0 0 680 600\" "
       "font-family=\"sans-serif\" font-size=\"12\">\n";
  s << "<rect width=\"680\" height=\"600\" fill=\"white\"/>\n";
  s << "<text x=\"340\" y=\"24\" text-anchor=\"middle\" font-size=\"14\">" << xml_escaped(spec.title) << "</text>\n";
  // Cells centred on the grid points, reaching halfway to the neighbours (clipped to the plot).
  const auto edge = [](const std::vector<double>& v, std::size_t k, bool upper) {
    if (upper) return k + 1 < v.size() ? 0.5 * (v[k] + v[k + 1]) : v[k];
    return k > 0 ? 0.5 * (v[k - 1] + v[k]) : v[k];
  };
  s << "<g shape-rendering=\"crispEdges\">\n";
  for (std::size_t iy = 0; iy < ny; ++iy)
    for (std::size_t ix = 0; ix < nx; ++ix) {
      const double xa = X(edge(spec.xs, ix, false)), xb = X(edge(spec.xs, ix, true));
      const double ya = Y(edge(spec.ys, iy, true)), yb = Y(edge(spec.ys, iy, false));
      s << "<rect x=\"" << xa << "\" y=\"" << ya << "\" width=\"" << xb - xa + 0.3 << "\" height=\"" << yb - ya + 0.3
        << "\" fill=\"" << colour(spec.values[iy * nx + ix] / scale) << "\"/>\n";
    }
  s << "</g>\n";
  s << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << width << "\" height=\"" << height
    << "\" fill=\"none\" stroke=\"black\"/>\n";
  for (int k = 0; k <= 4; ++k) {
    const double x = x0 + (x1 - x0) * k / 4, y = y0 + (y1 - y0) * k / 4;
    s << "<line x1=\"" << X(x) << "\" y1=\"" << top + height << "\" x2=\"" << X(x) << "\" y2=\"" << top + height + 5
      << "\" stroke=\"black\"/><text x=\"" << X(x) << "\" y=\"" << top + height + 18 << "\" text-anchor=\"middle\">"
      << number(x) << "</text>\n";
    s << "<line x1=\"" << left - 5 << "\" y1=\"" << Y(y) << "\" x2=\"" << left << "\" y2=\"" << Y(y)
      << "\" stroke=\"black\"/><text x=\"" << left - 8 << "\" y=\"" << Y(y) + 4 << "\" text-anchor=\"end\">"
      << number(y) << "</text>\n";
  }
  s << "<text x=\"" << left + width / 2 << "\" y=\"" << top + height + 38 << "\" text-anchor=\"middle\">"
    << xml_escaped(spec.x_label) << "</text>\n";
  s << "<text transform=\"translate(" << left - 50 << "," << top + height / 2
    << ") rotate(-90)\" text-anchor=\"middle\">" << xml_escaped(spec.y_label) << "</text>\n";
  // The colour bar.
  for (int k = 0; k < 100; ++k) {
    const double v = 1 - 2.0 * (k + 0.5) / 100;
    s << "<rect x=\"" << bar_x << "\" y=\"" << top + height * k / 100.0 << "\" width=\"18\" height=\""
      << height / 100.0 + 0.3 << "\" fill=\"" << colour(v) << "\" shape-rendering=\"crispEdges\"/>\n";
  }
  s << "<rect x=\"" << bar_x << "\" y=\"" << top << "\" width=\"18\" height=\"" << height
    << "\" fill=\"none\" stroke=\"black\"/>\n";
  for (int k = 0; k <= 2; ++k)
    s << "<text x=\"" << bar_x + 24 << "\" y=\"" << top + height * k / 2.0 + 4 << "\">" << number(scale * (1 - k))
      << "</text>\n";
  s << "<text transform=\"translate(" << bar_x + 75 << "," << top + height / 2
    << ") rotate(90)\" text-anchor=\"middle\">" << xml_escaped(spec.value_label) << "</text>\n";
  // Curves and their legend.
  const char* palette[] = {"black", "#2ca02c", "#9467bd", "#ff7f0e"};
  for (std::size_t c = 0; c < spec.curves.size(); ++c) {
    const PlotSeries& curve = spec.curves[c];
    const char* stroke = palette[c % 4];
    if (curve.line) {
      s << "<polyline fill=\"none\" stroke=\"" << stroke << "\" stroke-width=\"2\""
        << (curve.dashed ? " stroke-dasharray=\"6,4\"" : "") << " points=\"";
      for (std::size_t k = 0; k < curve.x.size(); ++k) s << X(curve.x[k]) << "," << Y(curve.y[k]) << " ";
      s << "\"/>\n";
    }
    if (curve.markers)
      for (std::size_t k = 0; k < curve.x.size(); ++k)
        s << "<circle cx=\"" << X(curve.x[k]) << "\" cy=\"" << Y(curve.y[k]) << "\" r=\"4\" fill=\"" << stroke
          << "\"/>\n";
    s << "<text x=\"" << left << "\" y=\"" << top + height + 58 + 14 * static_cast<double>(c) << "\" fill=\"" << stroke
      << "\">" << xml_escaped(curve.label) << "</text>\n";
  }
  s << "</svg>\n";
  return s.str();
}

}  // namespace hamel
