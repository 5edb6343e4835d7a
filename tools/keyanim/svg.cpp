#include "svg.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "escape.h"
#include "keyanim/offline/number_text.h"

namespace keyanim::svg {

std::string number(double v, int decimals) {
  if (!std::isfinite(v)) return "0";
  std::string s = offline::fixed_text(v, std::clamp(decimals, 0, 12));
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  return s;
}

std::string compact(double v, int decimals) {
  std::string s = number(v, decimals);
  if (s.rfind("0.", 0) == 0) s.erase(0, 1);
  else if (s.rfind("-0.", 0) == 0) s.erase(1, 1);
  return s;
}

std::string escape(std::string_view text) {
  // printable() first: XML 1.0 allows neither most control characters nor bytes that are not
  // UTF-8, and both may come from an input's names.
  const std::string safe = cli::printable(text);
  std::string out;
  out.reserve(safe.size());
  for (const char c : safe) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

namespace {

// Appends every part in turn: one buffer, no temporaries of the form "literal" + string.
template <class... Parts>
void append(std::string& out, const Parts&... parts) {
  ((out += parts), ...);
}

double tick_step(Range r, int target) {
  const double span = r.hi - r.lo;
  if (!(span > 0.0) || !std::isfinite(span)) return 0.0;
  const double raw = span / std::max(1, target);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / mag;
  return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * mag;
}

}  // namespace

std::string attr(std::string_view name, std::string_view value) {
  std::string out;
  append(out, ' ', name, "=\"", escape(value), '"');
  return out;
}

std::vector<double> nice_ticks(Range r, int target) {
  std::vector<double> ticks;
  const double step = tick_step(r, target);
  if (step == 0.0) {
    if (std::isfinite(r.lo)) ticks.push_back(r.lo);
    return ticks;
  }
  const double eps = step * 1e-9;
  for (double k = std::ceil((r.lo - eps) / step); k * step <= r.hi + eps && ticks.size() < 1000; k += 1.0) {
    const double t = k * step;
    ticks.push_back(std::abs(t) < eps ? 0.0 : t);
  }
  return ticks;
}

Range nice_range(Range r, int target) {
  if (!std::isfinite(r.lo) || !std::isfinite(r.hi)) return {0.0, 1.0};
  if (r.hi < r.lo) std::swap(r.lo, r.hi);
  if (r.hi - r.lo <= 1e-12 * std::max(1.0, std::abs(r.lo))) {
    const double pad = std::max(1.0, std::abs(r.lo) * 0.1);
    r = {r.lo - pad, r.hi + pad};
  }
  const double step = tick_step(r, target);
  return {std::floor(r.lo / step) * step, std::ceil(r.hi / step) * step};
}

Document::Document(double width, double height, double font_size)
    : width_(width), height_(height), font_size_(font_size) {}

void Document::title(std::string_view text) { append(body_, "<title>", escape(text), "</title>\n"); }

void Document::open_group(const std::string& attrs) { append(body_, "<g", attrs, ">\n"); }

void Document::close_group() { body_ += "</g>\n"; }

void Document::line(Point a, Point b, const std::string& attrs) {
  append(body_, "<line x1=\"", number(a.x), "\" y1=\"", number(a.y), "\" x2=\"", number(b.x), "\" y2=\"",
         number(b.y), '"', attrs, "/>\n");
}

void Document::path(const std::vector<Point>& points, const std::string& attrs) {
  if (points.size() < 2) return;
  // Relative steps between the rounded absolute points: shorter text, and no drift, since each
  // step is a difference of tenths (0.1 px is the precision of every coordinate here).
  auto tenths = [](double v) { return std::llround(v * 10.0); };
  long long px = tenths(points[0].x), py = tenths(points[0].y);
  append(body_, "<path d=\"M", number(double(px) / 10.0), ',', number(double(py) / 10.0), 'l');
  for (size_t i = 1; i < points.size(); ++i) {
    const long long x = tenths(points[i].x), y = tenths(points[i].y);
    append(body_, i > 1 ? " " : "", compact(double(x - px) / 10.0), ',', compact(double(y - py) / 10.0));
    px = x, py = y;
  }
  append(body_, '"', attrs, "/>\n");
}

void Document::path_data(std::string_view d, const std::string& attrs) {
  if (d.empty()) return;
  append(body_, "<path d=\"", escape(d), '"', attrs, "/>\n");
}

void Document::circle(Point c, double r, const std::string& attrs) {
  append(body_, "<circle cx=\"", number(c.x), "\" cy=\"", number(c.y), "\" r=\"", number(r), '"', attrs, "/>\n");
}

void Document::rect(Rect r, const std::string& attrs) {
  append(body_, "<rect x=\"", number(r.x), "\" y=\"", number(r.y), "\" width=\"", number(r.w), "\" height=\"",
         number(r.h), '"', attrs, "/>\n");
}

void Document::text(Point p, std::string_view text, const std::string& attrs, std::string_view anchor,
                    double rotate) {
  append(body_, "<text x=\"", number(p.x), "\" y=\"", number(p.y), '"');
  if (anchor != "start") append(body_, " text-anchor=\"", anchor, '"');
  if (rotate != 0.0) append(body_, " transform=\"rotate(", number(rotate), ' ', number(p.x), ' ', number(p.y), ")\"");
  append(body_, attrs, '>', escape(text), "</text>\n");
}

std::string Document::finish() const {
  const std::string w = number(width_), h = number(height_);
  std::string out;
  out.reserve(body_.size() + 400);
  append(out, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"", w,
         "\" height=\"", h, "\" viewBox=\"0 0 ", w, ' ', h,
         "\" font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\" font-size=\"", number(font_size_),
         "\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n", body_, "</svg>\n");
  return out;
}

Axes::Axes(Rect area, Range x, Range y) : area_(area), x_(x), y_(y) {
  // A degenerate range would divide by zero; give it a width.
  if (!(x_.hi > x_.lo)) x_ = {x_.lo - 0.5, x_.lo + 0.5};
  if (!(y_.hi > y_.lo)) y_ = {y_.lo - 0.5, y_.lo + 0.5};
}

void Axes::draw(Document& doc, const std::string& x_label, const std::string& y_label, int x_ticks,
                int y_ticks) const {
  const std::vector<double> xt = nice_ticks(x_, x_ticks), yt = nice_ticks(y_, y_ticks);
  // Decimals enough to tell neighbouring ticks apart.
  auto labelled = [](const std::vector<double>& t) {
    const int d = t.size() < 2 ? 2 : std::clamp(static_cast<int>(std::ceil(-std::log10(t[1] - t[0]) - 1e-9)), 0, 6);
    std::vector<Tick> out;
    for (const double v : t) out.push_back({v, number(v, d)});
    return out;
  };
  draw(doc, x_label, y_label, labelled(xt), labelled(yt));
}

void Axes::draw(Document& doc, const std::string& x_label, const std::string& y_label, const std::vector<Tick>& xt,
                const std::vector<Tick>& yt) const {
  const double left = area_.x, right = area_.x + area_.w, top = area_.y, bottom = area_.y + area_.h;
  std::string grid, ticks;  // disjoint segments, one path each
  for (const Tick& t : xt) {
    const std::string x = number(px(t.at));
    append(grid, 'M', x, ',', number(top), 'V', number(bottom));
    append(ticks, 'M', x, ',', number(bottom), "v5");
  }
  for (const Tick& t : yt) {
    const std::string y = number(py(t.at));
    append(grid, 'M', number(left), ',', y, 'H', number(right));
    append(ticks, 'M', number(left), ',', y, "h-5");
  }
  doc.open_group(attr("class", "axes"));
  doc.path_data(grid, attr("class", "grid") + " fill=\"none\" stroke=\"#e6e6e6\" stroke-width=\"1\"");
  doc.line({left, bottom}, {right, bottom}, attr("class", "axis x-axis") + " stroke=\"#222\" stroke-width=\"1\"");
  doc.line({left, bottom}, {left, top}, attr("class", "axis y-axis") + " stroke=\"#222\" stroke-width=\"1\"");
  doc.path_data(ticks, attr("class", "ticks") + " fill=\"none\" stroke=\"#222\" stroke-width=\"1\"");
  doc.open_group(attr("class", "tick-labels") + " fill=\"#222\" font-size=\"11\"");
  for (const Tick& t : xt) doc.text({px(t.at), bottom + 17.0}, t.label, "", "middle");
  for (const Tick& t : yt) doc.text({left - 8.0, py(t.at) + 4.0}, t.label, "", "end");
  doc.close_group();
  doc.text({left + area_.w / 2.0, bottom + 36.0}, x_label, attr("class", "label x-label"), "middle");
  doc.text({left - 52.0, top + area_.h / 2.0}, y_label, attr("class", "label y-label"), "middle", -90.0);
  doc.close_group();
}

namespace {
// The sample line's room before the label, and the gap that separates entries.
constexpr double kSampleWidth = 30.0, kEntryGap = 24.0;

// Characters of UTF-8 text: every byte that does not continue a sequence.
size_t characters(std::string_view text) {
  return static_cast<size_t>(std::count_if(text.begin(), text.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}
}  // namespace

double text_width(std::string_view text, double font_size, bool bold) {
  // What is written: printable() turns control characters and bad bytes into \xHH.
  return static_cast<double>(characters(cli::printable(text))) * font_size * (bold ? 0.68 : 0.62);
}

std::string elide_middle(std::string_view text, size_t max_chars) {
  const std::string safe = cli::printable(text);
  if (characters(safe) <= max_chars || max_chars < 3) return safe;
  // Byte offsets of the characters' starts, so that no UTF-8 sequence is split.
  std::vector<size_t> starts;
  for (size_t i = 0; i < safe.size(); ++i)
    if ((static_cast<unsigned char>(safe[i]) & 0xC0) != 0x80) starts.push_back(i);
  const size_t keep = max_chars - 1, head = keep / 2, tail = keep - head;
  return safe.substr(0, starts[head]) + "\xE2\x80\xA6" + safe.substr(starts[starts.size() - tail]);
}

double legend_width(const std::vector<LegendEntry>& entries) {
  double w = 0.0;
  for (const LegendEntry& e : entries) w += kSampleWidth + text_width(e.label) + kEntryGap;
  return entries.empty() ? 0.0 : w - kEntryGap;
}

void legend(Document& doc, Point at, const std::vector<LegendEntry>& entries) {
  doc.open_group(attr("class", "legend"));
  double x = at.x;
  for (const LegendEntry& e : entries) {
    const Point a{x, at.y - 4.0}, b{x + 24.0, at.y - 4.0};
    doc.line(a, b, attr("stroke", e.colour) + attr("stroke-width", number(e.stroke_width)));
    if (e.marker) doc.circle({x + 12.0, at.y - 4.0}, 3.0, attr("fill", e.colour));
    doc.text({x + kSampleWidth, at.y}, e.label, "");
    x += kSampleWidth + text_width(e.label) + kEntryGap;
  }
  doc.close_group();
}

}  // namespace keyanim::svg
