// The rate-distortion figure: log axes (equal decades, plain tick labels, units in the axis
// labels) fitted to the points, a path and one circle per point for each series, unplottable
// points left out.
#include <doctest/doctest.h>

#include <algorithm>
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
  CHECK(svg.find(">500<") != std::string::npos);
  CHECK(svg.find(">1000<") == std::string::npos);  // the axis ends a little above 500
  CHECK(svg.find("max error (% of the skeleton size, log scale)") != std::string::npos);
  CHECK(svg.find("compression ratio (raw float32 / .kanim bytes, log scale)") != std::string::npos);
  CHECK(svg.find(">2 files<") != std::string::npos);
}

// Issue 28, item 15: whole decades put eval's usual points (0.05% and 0.5%, ratios 9 to 38) in
// a corner of 0.01..1 x 1..100. Fitted, they span the plot area but for its margins, and there
// are ticks inside (1, 2, 5 times powers of ten, labelled).
TEST_CASE("rd plot: the axes fit the data") {
  const std::vector<RdSeries> series{{"a", {{0.0497, 10.78}, {0.497, 31.71}}},
                                     {"b", {{0.0499, 9.21}, {0.5, 24.33}}},
                                     {"c", {{0.0462, 16.17}, {0.463, 38.31}}}};
  const std::string svg = rd_plot(series, "3 files");
  const auto pts = circles(svg);
  REQUIRE(pts.size() == 6);
  double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
  for (const auto& [x, y] : pts) x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  // The plot area: 600 x 400 px from (96, 76).
  CHECK(x0 >= 96);
  CHECK(x1 <= 696);
  CHECK(y0 >= 76);
  CHECK(y1 <= 476);
  CHECK(x1 - x0 >= 0.85 * 600);
  CHECK(y1 - y0 >= 0.85 * 400);
  for (const char* tick : {">0.05<", ">0.1<", ">0.2<", ">0.5<", ">10<", ">20<"}) CHECK_MESSAGE(svg.find(tick) != std::string::npos, tick);
  // One point: half a decade around it, with at least three ticks.
  const std::string one = rd_plot({{"one", {{0.3, 12.0}}}}, "1 file");
  CHECK(count(one, "class=\"tick-labels\"") == 1);
  const size_t from = one.find("class=\"tick-labels\""), to = one.find("</g>", from);
  CHECK(count(one.substr(from, to - from), "<text") >= 6);  // three on each axis
}

TEST_CASE("rd plot: an empty or unplottable input still makes a valid document") {
  const std::string svg = rd_plot({{"none", {{0.0, 0.0}}}}, "nothing");
  CHECK(svg.find("</svg>") != std::string::npos);
  CHECK(circles(svg).empty());
}
