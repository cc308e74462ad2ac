// A small SVG line-plot writer for the experiments' figures: panels stacked
// vertically, each with axes, ticks, a title and a legend.
#pragma once

#include <string>
#include <vector>

namespace tonus::experiments {

struct Series {
  std::string name;
  std::vector<double> x, y;
  bool points = false;  // markers instead of a line
};

struct Panel {
  std::string title, x_label, y_label;
  std::vector<Series> series;
};

// Writes the panels to `path`; false with `error` set when the file cannot be written.
bool write_svg(const std::string& path, const std::string& title, const std::vector<Panel>& panels, std::string& error);

}  // namespace tonus::experiments
