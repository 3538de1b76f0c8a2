// The coverage-versus-count curve of camera placement as a table and an SVG plot
// (rig_placement.h).
#include <algorithm>
#include <cstdio>
#include <string>

#include "calf/samples/rig_placement.h"

namespace calf::samples {

namespace {

std::string format(const char* f, double a, double b = 0, double c = 0, double d = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, a, b, c, d);
  return buf;
}

std::string escape(std::string_view text) {
  std::string out;
  for (char ch : text) {
    if (ch == '<') {
      out += "&lt;";
    } else if (ch == '>') {
      out += "&gt;";
    } else if (ch == '&') {
      out += "&amp;";
    } else {
      out += ch;
    }
  }
  return out;
}

}  // namespace

std::string placement_table(const PlacementResult& r) {
  std::string t = "cameras\tx\ty\tz\tgain\tcoverage\thammersley\thand_made\n";
  for (const CoverageRow& row : r.curve) {
    t += std::to_string(row.cameras) + "\t";
    t += format("%.6g\t%.6g\t%.6g\t", row.position.x, row.position.y, row.position.z);
    t += format("%.6f\t%.6f\t%.6f\t", row.gain, row.coverage, row.hammersley);
    t += row.hand_made < 0 ? std::string("-") : format("%.6f", row.hand_made);
    t += "\n";
  }
  return t;
}

std::string placement_svg(const PlacementResult& r, std::string_view title) {
  constexpr double kW = 640, kH = 400, kLeft = 60, kRight = 150, kTop = 40, kBottom = 50;
  const double pw = kW - kLeft - kRight, ph = kH - kTop - kBottom;
  size_t n_max = std::max<size_t>(r.curve.size(), r.hand_made_count);
  n_max = std::max<size_t>(n_max, 2);
  double y_max = 1;
  for (const CoverageRow& row : r.curve) {
    y_max = std::max({y_max, row.coverage, row.hammersley, row.hand_made});
  }
  y_max = std::max(y_max, r.hand_made_coverage);
  auto x_of = [&](double n) { return kLeft + pw * (n - 1) / static_cast<double>(n_max - 1); };
  auto y_of = [&](double c) { return kTop + ph * (1 - c / y_max); };
  std::string s = format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%g\" height=\"%g\" "
      "font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"%g\" height=\"%g\" "
      "fill=\"white\"/>\n",
      kW, kH, kW, kH);
  s += format("<text x=\"%g\" y=\"20\">", kLeft) + escape(title) + "</text>\n";
  // Axes, ticks at every tenth of the coverage and at each count.
  s += format("<path d=\"M%g %gV%gH%g\" stroke=\"black\" fill=\"none\"/>\n", kLeft, kTop, kTop + ph,
              kLeft + pw);
  for (int i = 0; i <= 10; ++i) {
    const double c = y_max * i / 10;
    s += format("<text x=\"%g\" y=\"%g\" text-anchor=\"end\">%.2f</text>\n", kLeft - 6, y_of(c) + 4,
                c);
  }
  const size_t step = std::max<size_t>(1, n_max / 16);
  for (size_t n = 1; n <= n_max; n += step) {
    s += format("<text x=\"%g\" y=\"%g\" text-anchor=\"middle\">%g</text>\n", x_of(n),
                kTop + ph + 16, static_cast<double>(n));
  }
  s += format("<text x=\"%g\" y=\"%g\" text-anchor=\"middle\">cameras</text>\n", kLeft + pw / 2,
              kH - 10);
  s += format(
      "<text x=\"14\" y=\"%g\" transform=\"rotate(-90 14 %g)\" "
      "text-anchor=\"middle\">coverage</text>\n",
      kTop + ph / 2, kTop + ph / 2);
  struct Series {
    const char* name;
    const char* colour;
    double CoverageRow::*value;
  };
  const Series series[] = {{"Alg. 1 (auto)", "#d62728", &CoverageRow::coverage},
                           {"Hammersley", "#1f77b4", &CoverageRow::hammersley},
                           {"hand-made rig", "#2ca02c", &CoverageRow::hand_made}};
  double legend_y = kTop + 10;
  for (const Series& se : series) {
    std::string path;
    for (const CoverageRow& row : r.curve) {
      const double v = row.*se.value;
      if (v < 0) continue;
      path.append(path.empty() ? "M" : "L").append(format("%g %g", x_of(row.cameras), y_of(v)));
    }
    if (!path.empty()) {
      s += "<path d=\"" + path + "\" stroke=\"" + se.colour +
           "\" stroke-width=\"2\" fill=\"none\"/>\n";
    }
    s += format("<rect x=\"%g\" y=\"%g\" width=\"14\" height=\"3\" ", kLeft + pw + 12,
                legend_y - 4) +
         "fill=\"" + se.colour + "\"/>\n";
    s += format("<text x=\"%g\" y=\"%g\">", kLeft + pw + 30, legend_y) + se.name + "</text>\n";
    legend_y += 18;
  }
  // The whole hand-made rig as one point.
  if (r.hand_made_count > 0) {
    s += format("<circle cx=\"%g\" cy=\"%g\" r=\"4\" fill=\"#2ca02c\"/>\n", x_of(r.hand_made_count),
                y_of(r.hand_made_coverage));
  }
  s += "</svg>\n";
  return s;
}

}  // namespace calf::samples
