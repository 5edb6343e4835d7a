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
constexpr size_t kMaxLegend = 24;  // entries beyond this are summed up in one line

// Decade range [10^lo, 10^hi] holding every value (at least one decade wide).
svg::Range decades(double lo, double hi) {
  if (!(lo > 0.0) || !std::isfinite(lo) || !(hi >= lo) || !std::isfinite(hi)) return {0.0, 1.0};  // no point
  double a = std::floor(std::log10(lo) + 1e-9), b = std::ceil(std::log10(hi) - 1e-9);
  if (b <= a) b = a + 1.0;
  return {a, b};
}

// Tick values of a log axis over decades [lo, hi]: every decade, and 2 and 5 times it when
// the axis spans at most three decades.
std::vector<double> log_ticks(svg::Range r) {
  std::vector<double> t;
  const bool fine = r.hi - r.lo <= 3.0;
  for (double k = r.lo; k <= r.hi + 1e-9; k += 1.0) {
    const double d = std::pow(10.0, k);
    t.push_back(d);
    if (fine && k < r.hi - 1e-9) t.push_back(2 * d), t.push_back(5 * d);
  }
  return t;
}

// "0.002", "0.5", "20", "1000": plain numbers, enough decimals for the value.
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
  const svg::Range xr = decades(xlo, xhi), yr = decades(ylo, yhi);
  const svg::Rect area{96, 76, 600, 400};
  // Axes over the exponents: px(log10 v).
  const svg::Axes axes(area, xr, yr);
  const double legend_x = area.x + area.w + 28;
  const size_t legend_rows = std::min(series.size(), kMaxLegend) + (series.size() > kMaxLegend ? 1 : 0);
  const double height = std::max(area.y + area.h + 60, 92.0 + 18.0 * double(legend_rows));
  svg::Document doc(1000, height);
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

  std::vector<svg::LegendEntry> legend;
  for (size_t s = 0; s < series.size(); ++s) {
    const std::string colour = kColours[s % std::size(kColours)];
    std::vector<svg::Point> pts;
    for (const RdPoint& p : shown[s]) pts.push_back(axes.at(std::log10(p.error_percent), std::log10(p.ratio)));
    doc.open_group(attr("class", "series-group") + attr("data-label", series[s].label));
    doc.path(pts, attr("class", "series rd") + " fill=\"none\"" + attr("stroke", colour) + " stroke-width=\"1.6\"");
    for (const svg::Point& p : pts) doc.circle(p, 3.0, attr("class", "point") + attr("fill", colour));
    doc.close_group();
    if (s < kMaxLegend) legend.push_back({series[s].label, colour, true, 1.6});
  }
  for (size_t i = 0; i < legend.size(); ++i) svg::legend(doc, {legend_x, area.y + 4 + 18.0 * double(i)}, {legend[i]});
  if (series.size() > kMaxLegend)
    doc.text({legend_x, area.y + 4 + 18.0 * double(kMaxLegend)}, "... and " + std::to_string(series.size() - kMaxLegend) + " more",
             attr("class", "legend-more") + " fill=\"#444\"");
  return doc.finish();
}

}  // namespace keyanim::cli
