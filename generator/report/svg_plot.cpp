#include "report/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace hamel {

namespace {

constexpr double width = 720, height = 520, left = 90, right = 30, top = 50, bottom = 70;
const char* const palette[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"};

std::string num(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

struct Axis {
  bool log = false;
  double lo = 0, hi = 1;  // in transformed units (log10 when log)
  double tr(double v) const { return log ? std::log10(v) : v; }
  bool usable(double v) const { return std::isfinite(v) && (!log || v > 0); }

  // Ticks in data units: decades on a log axis, 1-2-5 steps otherwise.
  std::vector<double> ticks() const {
    std::vector<double> t;
    if (log) {
      for (double e = std::ceil(lo - 1e-9); e <= hi + 1e-9; e += std::max(1.0, std::floor((hi - lo) / 8) + 1))
        t.push_back(std::pow(10.0, e));
      return t;
    }
    const double raw = (hi - lo) / 6;
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    double step = mag;
    for (double f : {1.0, 2.0, 5.0, 10.0})
      if (f * mag >= raw) {
        step = f * mag;
        break;
      }
    for (double v = std::ceil(lo / step) * step; v <= hi + 1e-9 * step; v += step)
      t.push_back(std::fabs(v) < 1e-12 * step ? 0.0 : v);
    return t;
  }
};

void fit(Axis& axis, const std::vector<double>& values) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : values)
    if (axis.usable(v)) lo = std::min(lo, axis.tr(v)), hi = std::max(hi, axis.tr(v));
  if (!std::isfinite(lo)) lo = 0, hi = 1;
  if (hi - lo < 1e-12 * std::max(1.0, std::fabs(hi))) lo -= 0.5, hi += 0.5;
  const double pad = axis.log ? 0.05 * (hi - lo) : 0.05 * (hi - lo);
  axis.lo = lo - pad;
  axis.hi = hi + pad;
}

}  // namespace

std::string render_svg(const PlotSpec& spec) {
  Axis ax{spec.log_x}, ay{spec.log_y};
  std::vector<double> xs, ys;
  for (const auto& s : spec.series) {
    xs.insert(xs.end(), s.x.begin(), s.x.end());
    ys.insert(ys.end(), s.y.begin(), s.y.end());
  }
  fit(ax, xs);
  fit(ay, ys);
  const double pw = width - left - right, ph = height - top - bottom;
  // Head room for the legend box in the upper left corner.
  const double legend_fraction = (16 + 18 * static_cast<double>(spec.series.size())) / ph;
  ay.hi += legend_fraction / (1 - legend_fraction) * (ay.hi - ay.lo);
  if (spec.equal_aspect && !spec.log_x && !spec.log_y) {
    // Widen the axis with fewer units per pixel so that both scales agree.
    const double sx = (ax.hi - ax.lo) / pw, sy = (ay.hi - ay.lo) / ph;
    if (sx > sy) {
      const double c = (ay.hi + ay.lo) / 2, half = sx * ph / 2;
      ay.lo = c - half, ay.hi = c + half;
    } else {
      const double c = (ax.hi + ax.lo) / 2, half = sy * pw / 2;
      ax.lo = c - half, ax.hi = c + half;
    }
  }
  auto X = [&](double v) { return left + (ax.tr(v) - ax.lo) / (ax.hi - ax.lo) * pw; };
  auto Y = [&](double v) { return top + ph - (ay.tr(v) - ay.lo) / (ay.hi - ay.lo) * ph; };

  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height << "\" viewBox=\"0 0 "
    << width << " " << height << "\" font-family=\"sans-serif\" font-size=\"13\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<text x=\"" << width / 2 << "\" y=\"28\" text-anchor=\"middle\" font-size=\"16\">" << xml_escaped(spec.title)
    << "</text>\n";
  for (double t : ax.ticks()) {
    const double x = X(t);
    o << "<line x1=\"" << x << "\" y1=\"" << top << "\" x2=\"" << x << "\" y2=\"" << top + ph
      << "\" stroke=\"#e5e5e5\"/>\n<text x=\"" << x << "\" y=\"" << top + ph + 18 << "\" text-anchor=\"middle\">"
      << num(t) << "</text>\n";
  }
  for (double t : ay.ticks()) {
    const double y = Y(t);
    o << "<line x1=\"" << left << "\" y1=\"" << y << "\" x2=\"" << left + pw << "\" y2=\"" << y
      << "\" stroke=\"#e5e5e5\"/>\n<text x=\"" << left - 6 << "\" y=\"" << y + 4 << "\" text-anchor=\"end\">" << num(t)
      << "</text>\n";
  }
  o << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << pw << "\" height=\"" << ph
    << "\" fill=\"none\" stroke=\"black\"/>\n"
    << "<text x=\"" << left + pw / 2 << "\" y=\"" << height - 22 << "\" text-anchor=\"middle\">"
    << xml_escaped(spec.x_label) << "</text>\n"
    << "<text transform=\"translate(22," << top + ph / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
    << xml_escaped(spec.y_label) << "</text>\n";
  for (std::size_t k = 0; k < spec.series.size(); ++k) {
    const PlotSeries& s = spec.series[k];
    const char* colour = palette[k % (sizeof palette / sizeof *palette)];
    std::ostringstream points;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
      if (ax.usable(s.x[i]) && ay.usable(s.y[i])) points << X(s.x[i]) << "," << Y(s.y[i]) << " ";
    if (s.line)
      o << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"1.6\""
        << (s.dashed ? " stroke-dasharray=\"6,4\"" : "") << " points=\"" << points.str() << "\"/>\n";
    const char* radius = s.x.size() > 400 ? "1.4" : "3.5";  // dense point clouds (eigenvalue sweeps) stay legible
    if (s.markers)
      for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
        if (ax.usable(s.x[i]) && ay.usable(s.y[i]))
          o << "<circle cx=\"" << X(s.x[i]) << "\" cy=\"" << Y(s.y[i]) << "\" r=\"" << radius << "\" fill=\"" << colour
            << "\"/>\n";
  }
  // Legend: a white box in the upper left corner, sized to the longest label.
  std::size_t longest = 0;
  for (const auto& s : spec.series) longest = std::max(longest, s.label.size());
  const double box_w = 40 + 7.2 * static_cast<double>(longest),
               box_h = 8 + 18 * static_cast<double>(spec.series.size());
  o << "<rect x=\"" << left + 8 << "\" y=\"" << top + 8 << "\" width=\"" << box_w << "\" height=\"" << box_h
    << "\" fill=\"white\" fill-opacity=\"0.85\" stroke=\"#bbbbbb\"/>\n";
  for (std::size_t k = 0; k < spec.series.size(); ++k) {
    const PlotSeries& s = spec.series[k];
    const char* colour = palette[k % (sizeof palette / sizeof *palette)];
    const double ly = top + 22 + 18 * static_cast<double>(k), lx = left + 14;
    if (s.line)
      o << "<line x1=\"" << lx << "\" y1=\"" << ly << "\" x2=\"" << lx + 22 << "\" y2=\"" << ly << "\" stroke=\""
        << colour << "\" stroke-width=\"2\"" << (s.dashed ? " stroke-dasharray=\"6,4\"" : "") << "/>\n";
    if (s.markers) o << "<circle cx=\"" << lx + 11 << "\" cy=\"" << ly << "\" r=\"3.5\" fill=\"" << colour << "\"/>\n";
    o << "<text x=\"" << lx + 28 << "\" y=\"" << ly + 4 << "\">" << xml_escaped(s.label) << "</text>\n";
  }
  o << "</svg>\n";
  return o.str();
}

std::string xml_escaped(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace hamel
