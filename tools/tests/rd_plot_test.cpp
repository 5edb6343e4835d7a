// The rate-distortion figure: log axes (equal decades, plain tick labels, units in the axis
// labels), a path and one circle per point for each series, unplottable points left out.
#include <doctest/doctest.h>

#include <cmath>
#include <regex>
#include <string>
#include <vector>

#include "rd_plot.h"

using keyanim::cli::rd_plot;
using keyanim::cli::RdSeries;

namespace {

std::vector<std::pair<double, double>> circles(const std::string& svg) {
  std::vector<std::pair<double, double>> out;
  const std::regex re("<circle cx=\"([-0-9.]+)\" cy=\"([-0-9.]+)\" r=\"[0-9.]+\" class=\"point\"");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), re); it != std::sregex_iterator(); ++it)
    out.push_back({std::stod((*it)[1]), std::stod((*it)[2])});
  return out;
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("rd plot: equal decades on both log axes, points in order, one line per series") {
  // Errors 0.01, 0.1, 1 (%) and ratios 5, 50, 500: three decades apart on each axis.
  const std::vector<RdSeries> series{{"walk", {{0.1, 50}, {0.01, 5}, {1.0, 500}}},
                                     {"hop", {{0.05, 20}, {0.0, 30}, {0.5, -1}, {NAN, 3}}}};
  const std::string svg = rd_plot(series, "2 files");
  CHECK(svg.rfind("<?xml", 0) == 0);
  CHECK(count(svg, "class=\"series rd\"") == 1);  // "hop" has one plottable point: no line
  CHECK(count(svg, "data-label=\"walk\"") == 1);
  CHECK(count(svg, "data-label=\"hop\"") == 1);
  const auto pts = circles(svg);
  REQUIRE(pts.size() == 4);
  // Sorted by error: 0.01, 0.1, 1; each step one decade right and one decade up, equal in px.
  const double dx1 = pts[1].first - pts[0].first, dx2 = pts[2].first - pts[1].first;
  const double dy1 = pts[0].second - pts[1].second, dy2 = pts[1].second - pts[2].second;
  CHECK(dx1 > 0);
  CHECK(dy1 > 0);
  CHECK(dx1 == doctest::Approx(dx2).epsilon(0.01));
  CHECK(dy1 == doctest::Approx(dy2).epsilon(0.01));
  // hop's point (0.05, 20): log-halfway between 0.01 and 0.1 would be 0.0316; 0.05 lies at
  // log10(5) = 0.699 of the decade from 0.01.
  CHECK(pts[3].first - pts[0].first == doctest::Approx(std::log10(5.0) * dx1).epsilon(0.01));
  CHECK(svg.find(">0.01<") != std::string::npos);
  CHECK(svg.find(">0.1<") != std::string::npos);
  CHECK(svg.find(">1000<") != std::string::npos);
  CHECK(svg.find("max error (% of the skeleton size, log scale)") != std::string::npos);
  CHECK(svg.find("compression ratio (raw float32 / .kanim bytes, log scale)") != std::string::npos);
  CHECK(svg.find(">2 files<") != std::string::npos);
}

TEST_CASE("rd plot: an empty or unplottable input still makes a valid document") {
  const std::string svg = rd_plot({{"none", {{0.0, 0.0}}}}, "nothing");
  CHECK(svg.find("</svg>") != std::string::npos);
  CHECK(circles(svg).empty());
}
