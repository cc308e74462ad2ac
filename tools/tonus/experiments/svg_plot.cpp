// SVG line plots.
#include "svg_plot.hpp"

#include <fmt/core.h>
#include <fmt/os.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace tonus::experiments {

namespace {

constexpr double kWidth = 820.0, kPanelHeight = 280.0, kLeft = 70.0, kRight = 190.0, kTop = 40.0, kBottom = 45.0;
constexpr std::array<const char*, 8> kColors{"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e",
                                             "#9467bd", "#8c564b", "#e377c2", "#17becf"};

std::string escape(const std::string& s) {
  std::string o;
  for (const char c : s) {
    if (c == '<')
      o += "&lt;";
    else if (c == '>')
      o += "&gt;";
    else if (c == '&')
      o += "&amp;";
    else
      o += c;
  }
  return o;
}

// A "nice" tick step for a range.
double tick_step(double span) {
  if (!(span > 0.0)) return 1.0;
  const double raw = span / 5.0;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double f : {1.0, 2.0, 5.0, 10.0}) {
    if (raw <= f * mag) return f * mag;
  }
  return 10.0 * mag;
}

void panel(fmt::ostream& out, const Panel& p, double y0) {
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
  for (const Series& s : p.series) {
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      xmin = std::min(xmin, s.x[i]);
      xmax = std::max(xmax, s.x[i]);
      ymin = std::min(ymin, s.y[i]);
      ymax = std::max(ymax, s.y[i]);
    }
  }
  if (!std::isfinite(xmin)) xmin = 0.0, xmax = 1.0, ymin = 0.0, ymax = 1.0;
  if (xmax - xmin < 1e-12) xmax = xmin + 1.0;
  if (ymax - ymin < 1e-12) ymax = ymin + 1.0;
  const double pad = 0.05 * (ymax - ymin);
  ymin -= pad;
  ymax += pad;
  const double w = kWidth - kLeft - kRight, h = kPanelHeight - kTop - kBottom;
  const auto X = [&](double x) { return kLeft + (x - xmin) / (xmax - xmin) * w; };
  const auto Y = [&](double y) { return y0 + kTop + h - (y - ymin) / (ymax - ymin) * h; };
  out.print("<text x='{:.1f}' y='{:.1f}' font-size='14' font-weight='bold'>{}</text>\n", kLeft, y0 + 24.0,
            escape(p.title));
  out.print("<rect x='{:.1f}' y='{:.1f}' width='{:.1f}' height='{:.1f}' fill='none' stroke='#444'/>\n", kLeft,
            y0 + kTop, w, h);
  const double xs = tick_step(xmax - xmin), ys = tick_step(ymax - ymin);
  const auto ticks = [](double lo, double hi, double step) {
    const double first = std::ceil(lo / step);
    return std::pair{first, static_cast<int>(std::floor(hi / step + 1e-9) - first)};
  };
  const auto [x0, nx] = ticks(xmin, xmax, xs);
  for (int i = 0; i <= nx; ++i) {
    const double x = (x0 + i) * xs;
    out.print("<line x1='{0:.1f}' x2='{0:.1f}' y1='{1:.1f}' y2='{2:.1f}' stroke='#ddd'/>", X(x), y0 + kTop,
              y0 + kTop + h);
    out.print("<text x='{:.1f}' y='{:.1f}' font-size='11' text-anchor='middle'>{:g}</text>\n", X(x),
              y0 + kTop + h + 15.0, x);
  }
  const auto [y0t, ny] = ticks(ymin, ymax, ys);
  for (int i = 0; i <= ny; ++i) {
    const double y = (y0t + i) * ys;
    out.print("<line x1='{0:.1f}' x2='{1:.1f}' y1='{2:.1f}' y2='{2:.1f}' stroke='#ddd'/>", kLeft, kLeft + w, Y(y));
    out.print("<text x='{:.1f}' y='{:.1f}' font-size='11' text-anchor='end'>{:g}</text>\n", kLeft - 5.0, Y(y) + 4.0,
              std::abs(y) < 1e-12 * ys ? 0.0 : y);
  }
  out.print("<text x='{:.1f}' y='{:.1f}' font-size='12' text-anchor='middle'>{}</text>\n", kLeft + w / 2.0,
            y0 + kPanelHeight - 8.0, escape(p.x_label));
  out.print("<text transform='translate({:.1f},{:.1f}) rotate(-90)' font-size='12' text-anchor='middle'>{}</text>\n",
            18.0, y0 + kTop + h / 2.0, escape(p.y_label));
  for (std::size_t k = 0; k < p.series.size(); ++k) {
    const Series& s = p.series[k];
    const char* color = kColors[k % kColors.size()];
    if (s.points) {
      for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
        if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
          // Alternate filled and ringed markers so coinciding series stay visible.
          if (k % 2 == 0)
            out.print("<circle cx='{:.1f}' cy='{:.1f}' r='6' fill='none' stroke='{}' stroke-width='2'/>\n", X(s.x[i]),
                      Y(s.y[i]), color);
          else
            out.print("<circle cx='{:.1f}' cy='{:.1f}' r='3' fill='{}'/>\n", X(s.x[i]), Y(s.y[i]), color);
        }
      }
    } else {
      out.print("<polyline fill='none' stroke='{}' stroke-width='1.6' points='", color);
      for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
        if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) out.print("{:.1f},{:.1f} ", X(s.x[i]), Y(s.y[i]));
      }
      out.print("'/>\n");
    }
    const double ly = y0 + kTop + 12.0 + 18.0 * static_cast<double>(k);
    if (s.points)
      out.print("<circle cx='{:.1f}' cy='{:.1f}' r='4' fill='{}'/>", kLeft + w + 20.0, ly, color);
    else
      out.print("<line x1='{0:.1f}' x2='{1:.1f}' y1='{2:.1f}' y2='{2:.1f}' stroke='{3}' stroke-width='3'/>",
                kLeft + w + 10.0, kLeft + w + 30.0, ly, color);
    out.print("<text x='{:.1f}' y='{:.1f}' font-size='11'>{}</text>\n", kLeft + w + 35.0, ly + 4.0, escape(s.name));
  }
}

}  // namespace

bool write_svg(const std::string& path, const std::string& title, const std::vector<Panel>& panels,
               std::string& error) {
  try {
    auto out = fmt::output_file(path);
    const double height = 30.0 + kPanelHeight * static_cast<double>(panels.size());
    out.print("<svg xmlns='http://www.w3.org/2000/svg' width='{:.0f}' height='{:.0f}' font-family='sans-serif'>\n",
              kWidth, height);
    out.print("<rect width='100%' height='100%' fill='white'/>\n");
    out.print("<text x='{:.1f}' y='20' font-size='15' font-weight='bold'>{}</text>\n", kLeft, escape(title));
    for (std::size_t i = 0; i < panels.size(); ++i) panel(out, panels[i], 30.0 + kPanelHeight * static_cast<double>(i));
    out.print("</svg>\n");
    out.close();
  } catch (const std::exception& e) {
    error = "cannot write " + path + ": " + e.what();
    return false;
  }
  return true;
}

}  // namespace tonus::experiments
