// A tiny SVG writer: plain text, coordinates in viewBox units (pixels at 100%). Enough for line
// plots and stick figures: axes with ticks, labels and units, paths, lines, circle markers,
// text and a legend. Numbers are written with few decimals to keep files small.
#pragma once
#include <string>
#include <string_view>
#include <vector>

namespace keyanim::svg {

// Fixed-point text with at most `decimals` decimals, trailing zeros dropped ("-0" -> "0").
std::string number(double v, int decimals = 1);
// number() without the leading zero of |v| < 1 (".5", "-.25"): for long path data.
std::string compact(double v, int decimals = 1);
// Escapes & < > " for use in text and attribute values, after printable() (escape.h): what XML
// cannot hold (control characters, bytes that are not UTF-8) becomes visible \xHH text.
std::string escape(std::string_view text);
// ` name="value"` with the value escaped: builds the `attrs` arguments below.
std::string attr(std::string_view name, std::string_view value);

struct Range {
  double lo = 0.0, hi = 1.0;
};
struct Rect {
  double x = 0.0, y = 0.0, w = 0.0, h = 0.0;
};
struct Point {
  double x = 0.0, y = 0.0;
};

// Round tick values (steps of 1, 2 or 5 times a power of ten) inside [lo, hi], about `target`
// of them (at least 2 when the range allows).
std::vector<double> nice_ticks(Range r, int target);
// `r` widened to multiples of its tick step; an empty range is widened around its value.
Range nice_range(Range r, int target);

class Document {
 public:
  // viewBox "0 0 width height"; sans-serif text of `font_size` by default.
  Document(double width, double height, double font_size = 12.0);
  double width() const { return width_; }
  double height() const { return height_; }

  // <title> of the document (tooltips, accessibility).
  void title(std::string_view text);
  void open_group(const std::string& attrs);
  void close_group();
  void line(Point a, Point b, const std::string& attrs);
  // One <path> through the points, coordinates rounded to 0.1 ("M x,y l dx,dy dx,dy ...", the
  // steps between rounded points); nothing for fewer than 2 points.
  void path(const std::vector<Point>& points, const std::string& attrs);
  // A <path> with path data written by the caller (e.g. disjoint "M..V.." segments).
  void path_data(std::string_view d, const std::string& attrs);
  void circle(Point c, double r, const std::string& attrs);
  void rect(Rect r, const std::string& attrs);
  // `anchor`: start, middle or end. `rotate` in degrees about the anchor point.
  void text(Point p, std::string_view text, const std::string& attrs, std::string_view anchor = "start",
            double rotate = 0.0);
  // The complete document.
  std::string finish() const;

 private:
  double width_, height_, font_size_;
  std::string body_;
};

// A plot panel: data ranges mapped onto a pixel rectangle, y upwards.
class Axes {
 public:
  Axes(Rect area, Range x, Range y);
  double px(double x) const { return area_.x + (x - x_.lo) / (x_.hi - x_.lo) * area_.w; }
  double py(double y) const { return area_.y + area_.h - (y - y_.lo) / (y_.hi - y_.lo) * area_.h; }
  Point at(double x, double y) const { return {px(x), py(y)}; }
  const Rect& area() const { return area_; }
  Range x_range() const { return x_; }
  Range y_range() const { return y_; }

  // Light grid at the ticks, the two axis lines (class "axis x-axis" and "axis y-axis"), tick
  // marks, tick labels and the axis labels (class "label"; put the unit in the label).
  void draw(Document& doc, const std::string& x_label, const std::string& y_label, int x_ticks = 8,
            int y_ticks = 6) const;
  // The same with the ticks given: where (in data units) and what they say, e.g. a log axis
  // drawn over log10 of its values with the values as labels.
  struct Tick {
    double at;
    std::string label;
  };
  void draw(Document& doc, const std::string& x_label, const std::string& y_label, const std::vector<Tick>& x_ticks,
            const std::vector<Tick>& y_ticks) const;

 private:
  Rect area_;
  Range x_, y_;
};

struct LegendEntry {
  std::string label;
  std::string colour;    // stroke colour of the sample line
  bool marker = false;   // also a dot on the sample line
  double stroke_width = 2.0;
};
// Estimated width of `text` at `font_size` px: there are no font metrics here, so 0.62 em per
// character (0.68 bold), more than DejaVu Sans's average, so that a layout that reserves this
// much room does not clip (tools/tests/svg_bounds_test.cpp checks the figures with it).
double text_width(std::string_view text, double font_size = 12.0, bool bold = false);
// `text` cut to at most `max_chars` characters by an ellipsis in its middle: a file name keeps
// its start and its end (".bvh").
std::string elide_middle(std::string_view text, size_t max_chars);
// Estimated width of a legend row (text_width at the document's 12 px).
double legend_width(const std::vector<LegendEntry>& entries);
// One row of entries starting at (x, y) (y: text baseline), left to right; class "legend".
void legend(Document& doc, Point at, const std::vector<LegendEntry>& entries);

}  // namespace keyanim::svg
