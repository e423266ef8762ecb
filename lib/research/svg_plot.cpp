// SPDX-License-Identifier: Apache-2.0
#include "svg_plot.hpp"

#include <cstdio>

namespace cellmap::research {

SvgPlot::SvgPlot(double width, double height) {
  out_ << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
       << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
       << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
}

void SvgPlot::line(double x1, double y1, double x2, double y2, const std::string& stroke,
                   double stroke_width) {
  out_ << "<line x1=\"" << fixed(x1, 1) << "\" y1=\"" << fixed(y1, 1) << "\" x2=\"" << fixed(x2, 1)
       << "\" y2=\"" << fixed(y2, 1) << "\" stroke=\"" << stroke << "\"";
  if (stroke_width != 1.0) out_ << " stroke-width=\"" << stroke_width << "\"";
  out_ << "/>\n";
}

void SvgPlot::rect(double x, double y, double width, double height, const std::string& fill,
                   const std::string& stroke) {
  out_ << "<rect x=\"" << fixed(x, 1) << "\" y=\"" << fixed(y, 1) << "\" width=\"" << fixed(width, 1)
       << "\" height=\"" << fixed(height, 1) << "\" fill=\"" << fill << "\"";
  if (stroke != "none") out_ << " stroke=\"" << stroke << "\"";
  out_ << "/>\n";
}

void SvgPlot::text(double x, double y, const std::string& text, const std::string& anchor, double size,
                   double rotate) {
  out_ << "<text x=\"" << fixed(x, 1) << "\" y=\"" << fixed(y, 1) << "\"";
  if (anchor != "start") out_ << " text-anchor=\"" << anchor << "\"";
  if (size > 0) out_ << " font-size=\"" << size << "\"";
  if (rotate != 0)
    out_ << " transform=\"rotate(" << rotate << " " << fixed(x, 1) << " " << fixed(y, 1) << ")\"";
  out_ << ">" << text << "</text>\n";
}

void SvgPlot::polyline(const std::vector<std::pair<double, double>>& points, const std::string& stroke,
                       double stroke_width) {
  out_ << "<polyline fill=\"none\" stroke=\"" << stroke << "\" stroke-width=\"" << stroke_width
       << "\" points=\"";
  for (const auto& [x, y] : points) out_ << fixed(x, 1) << "," << fixed(y, 1) << " ";
  out_ << "\"/>\n";
}

std::string SvgPlot::str() const {
  return out_.str() + "</svg>\n";
}

std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

}  // namespace cellmap::research
