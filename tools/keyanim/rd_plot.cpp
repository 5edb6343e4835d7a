#include "rd_plot.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "svg.h"

namespace keyanim::cli {

using svg::attr;
using svg::number;

namespace {

// Distinct colours, cycled (Tableau 10).
constexpr const char* kColours[] = {"#4e79a7", "#f28e2b", "#e15759", "#76b7b2", "#59a14f",
                                    "#edc948", "#b07aa1", "#ff9da7", "#9c755f", "#bab0ac"};
constexpr size_t kMaxLegend = 24;     // entries beyond this are summed up in one line
constexpr size_t kLegendChars = 60;   // longer labels lose their middle to an ellipsis

// The exponents [log10 lo, log10 hi] of the values with a margin of 5% of the span on each
// side, at least half a decade wide (widened about the middle): the axis fits the data, where
// whole decades left a clip's points in a corner.
svg::Range log_range(double lo, double hi) {
  if (!(lo > 0.0) || !std::isfinite(lo) || !(hi >= lo) || !std::isfinite(hi)) return {0.0, 1.0};  // no point
  double a = std::log10(lo), b = std::log10(hi);
  if (b - a < 0.5) {
    const double mid = (a + b) / 2;
    a = mid - 0.25, b = mid + 0.25;
  }
  const double margin = 0.05 * (b - a);
  return {a - margin, b + margin};
}

// Tick values of a log axis over exponents [lo, hi]: 1, 2 and 5 times each power of ten inside,
// or only the powers when the axis spans more than four decades, or every 1..9 times one when
// that would leave fewer than three ticks.
std::vector<double> log_ticks(svg::Range r) {
  auto ticks = [&](std::initializer_list<double> steps) {
    std::vector<double> t;
    for (double k = std::floor(r.lo); k <= std::ceil(r.hi); k += 1.0)
      for (const double m : steps) {
        const double v = m * std::pow(10.0, k), e = std::log10(v);
        if (e >= r.lo - 1e-9 && e <= r.hi + 1e-9) t.push_back(v);
      }
    return t;
  };
  if (r.hi - r.lo > 4.0) return ticks({1});
  std::vector<double> t = ticks({1, 2, 5});
  return t.size() >= 3 ? t : ticks({1, 2, 3, 4, 5, 6, 7, 8, 9});
}

// "0.002", "0.5", "20", "1000", "0.03": plain numbers, enough decimals for the value's first digit.
std::string tick_text(double v) { return number(v, std::clamp(int(std::ceil(-std::log10(v) - 1e-9)), 0, 9)); }

}  // namespace

std::string rd_plot(const std::vector<RdSeries>& series, const std::string& subtitle) {
  double xlo = std::numeric_limits<double>::infinity(), xhi = 0.0, ylo = xlo, yhi = 0.0;
  std::vector<std::vector<RdPoint>> shown(series.size());
  for (size_t s = 0; s < series.size(); ++s) {
    for (const RdPoint& p : series[s].points) {
      if (!(p.error_percent > 0.0) || !(p.ratio > 0.0) || !std::isfinite(p.error_percent) || !std::isfinite(p.ratio))
        continue;
      shown[s].push_back(p);
      xlo = std::min(xlo, p.error_percent), xhi = std::max(xhi, p.error_percent);
      ylo = std::min(ylo, p.ratio), yhi = std::max(yhi, p.ratio);
    }
    std::sort(shown[s].begin(), shown[s].end(),
              [](const RdPoint& a, const RdPoint& b) { return a.error_percent < b.error_percent; });
  }
  const svg::Range xr = log_range(xlo, xhi), yr = log_range(ylo, yhi);
  const svg::Rect area{96, 76, 600, 400};
  // Axes over the exponents: px(log10 v).
  const svg::Axes axes(area, xr, yr);
  const double legend_x = area.x + area.w + 28;
  const size_t legend_rows = std::min(series.size(), kMaxLegend) + (series.size() > kMaxLegend ? 1 : 0);
  const double height = std::max(area.y + area.h + 60, 92.0 + 18.0 * double(legend_rows));
  // Wide enough for the longest legend row and the subtitle.
  std::vector<svg::LegendEntry> legend;
  for (size_t s = 0; s < series.size() && s < kMaxLegend; ++s)
    legend.push_back({svg::elide_middle(series[s].label, kLegendChars), kColours[s % std::size(kColours)], true, 1.6});
  double width = std::max(1000.0, area.x + svg::text_width(subtitle) + 24);
  for (const svg::LegendEntry& e : legend) width = std::max(width, legend_x + svg::legend_width({e}) + 16);
  svg::Document doc(width, height);
  doc.title("Compression against error");
  doc.text({area.x, 24}, "Compression against error", attr("class", "title") + " font-size=\"15\" font-weight=\"bold\"");
  doc.text({area.x, 44}, subtitle, attr("class", "subtitle") + " fill=\"#444\"");

  // Log axes: drawn over the exponents, labelled with the values.
  auto ticks = [](svg::Range r) {
    std::vector<svg::Axes::Tick> out;
    for (const double v : log_ticks(r)) out.push_back({std::log10(v), tick_text(v)});
    return out;
  };
  axes.draw(doc, "max error (% of the skeleton size, log scale)",
            "compression ratio (raw float32 / .kanim bytes, log scale)", ticks(xr), ticks(yr));

  for (size_t s = 0; s < series.size(); ++s) {
    const std::string colour = kColours[s % std::size(kColours)];
    std::vector<svg::Point> pts;
    for (const RdPoint& p : shown[s]) pts.push_back(axes.at(std::log10(p.error_percent), std::log10(p.ratio)));
    doc.open_group(attr("class", "series-group") + attr("data-label", series[s].label));
    doc.path(pts, attr("class", "series rd") + " fill=\"none\"" + attr("stroke", colour) + " stroke-width=\"1.6\"");
    for (const svg::Point& p : pts) doc.circle(p, 3.0, attr("class", "point") + attr("fill", colour));
    doc.close_group();
  }
  for (size_t i = 0; i < legend.size(); ++i) svg::legend(doc, {legend_x, area.y + 4 + 18.0 * double(i)}, {legend[i]});
  if (series.size() > kMaxLegend)
    doc.text({legend_x, area.y + 4 + 18.0 * double(kMaxLegend)}, "... and " + std::to_string(series.size() - kMaxLegend) + " more",
             attr("class", "legend-more") + " fill=\"#444\"");
  return doc.finish();
}

}  // namespace keyanim::cli
