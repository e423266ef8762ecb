// SPDX-License-Identifier: Apache-2.0
#pragma once
// Internal to the research stage: the one SVG writer behind its figures (the paper's fig. 6b line plot, the
// sensor comparison's bar charts). Plain SVG 1.1 text, white background, sans-serif 12 px; coordinates in
// pixels, y down.
// The paper: K. Zauner, J. El Dib, H. Gattringer, A. Müller, "Workspace Registration and Collision
// Detection for Industrial Robotics Applications", AIRoV 2024.

#include <cmath>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace cellmap::research {

/// A linear map from data values [v0, v1] to pixels [p0, p1].
struct PlotAxis final {
  double v0 = 0, v1 = 1, p0 = 0, p1 = 1;
  [[nodiscard]] double operator()(double v) const { return p0 + (v - v0) / (v1 - v0) * (p1 - p0); }
};

/// Builds one SVG document element by element. Text is written as given (callers pass plain text).
class SvgPlot final {
 public:
  SvgPlot(double width, double height);

  void line(double x1, double y1, double x2, double y2, const std::string& stroke, double stroke_width = 1.0);
  void rect(double x, double y, double width, double height, const std::string& fill,
            const std::string& stroke = "none");
  /// `anchor`: start, middle or end. `size` 0 keeps the document's 12 px. `rotate` turns it about (x, y).
  void text(double x, double y, const std::string& text, const std::string& anchor = "start", double size = 0,
            double rotate = 0);
  void polyline(const std::vector<std::pair<double, double>>& points, const std::string& stroke,
                double stroke_width);
  /// Horizontal grid lines from x_left to x_right at lo, lo + step, ... hi on `y`, each labelled left of
  /// x_left with label(v). The line at v = 0 is drawn in `zero_stroke`.
  template <typename Label>
  void y_grid(const PlotAxis& y, double lo, double hi, double step, double x_left, double x_right,
              const Label& label, const std::string& stroke, const std::string& zero_stroke) {
    for (double v = lo; v <= hi + 1e-9; v += step) {
      line(x_left, y(v), x_right, y(v), std::abs(v) < 1e-9 ? zero_stroke : stroke);
      text(x_left - 6, y(v) + 4, label(v), "end");
    }
  }

  /// The document, closed.
  [[nodiscard]] std::string str() const;

 private:
  std::ostringstream out_;
};

/// `value` with `decimals` digits after the point ("%.*f").
[[nodiscard]] std::string fixed(double value, int decimals);

}  // namespace cellmap::research
