// Issue 28, item 15: every text of the figures stays inside the canvas. There are no font
// metrics here, so a text's width is estimated conservatively from its font size and its
// characters: 0.62 em per character (0.68 bold), wider than DejaVu Sans's average (its digits are
// 0.64 em, lower case letters about 0.6); its height from 0.8 em above the baseline to 0.25 em
// below. The font size and weight are the text's own, else its groups', else the document's;
// text-anchor and rotate() are applied. Figures: eval's rate-distortion plot with a corpus
// file's long name (the legend was clipped at "..._Rep1.b"), `render --against` with the names
// of a Bandai file's .kanim and .bvh in its title (cut off), `plot` with a long file name.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <regex>
#include <string>
#include <vector>

#include "figures.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/encode.h"
#include "rd_plot.h"

using namespace keyanim;
using namespace keyanim::offline;

namespace {

struct Style {
  double font_size = 16.0;  // SVG's initial value
  bool bold = false;
};

std::string attribute(const std::string& attrs, const std::string& name) {
  std::smatch m;
  if (std::regex_search(attrs, m, std::regex("(^|\\s)" + name + "=\"([^\"]*)\""))) return m[2];
  return "";
}

Style styled(Style s, const std::string& attrs) {
  if (const std::string fs = attribute(attrs, "font-size"); !fs.empty()) s.font_size = std::stod(fs);
  if (const std::string fw = attribute(attrs, "font-weight"); !fw.empty()) s.bold = fw == "bold";
  return s;
}

// Characters of XML text: entities count as one, UTF-8 continuation bytes as none.
size_t characters(const std::string& xml) {
  size_t n = 0;
  for (size_t i = 0; i < xml.size(); ++i) {
    if (xml[i] == '&') i = xml.find(';', i);
    if ((static_cast<unsigned char>(xml[i]) & 0xC0) != 0x80) ++n;
  }
  return n;
}

struct Overflow {
  std::string text;
  double x0, y0, x1, y1;
};

// Texts whose estimated box leaves [0, width] x [0, height] of the <svg> element.
std::vector<Overflow> texts_outside(const std::string& svg) {
  std::vector<Overflow> out;
  std::vector<Style> stack{Style{}};
  double width = 0, height = 0;
  const std::regex tag("<(/?)(svg|g|text)\\b([^>]*)>([^<]*)");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), tag); it != std::sregex_iterator(); ++it) {
    const std::string close = (*it)[1], name = (*it)[2], attrs = (*it)[3], content = (*it)[4];
    if (close == "/") {
      if (name == "g" && stack.size() > 1) stack.pop_back();
      continue;
    }
    if (name == "svg") {
      width = std::stod(attribute(attrs, "width")), height = std::stod(attribute(attrs, "height"));
      stack.back() = styled(stack.back(), attrs);
      continue;
    }
    if (name == "g") {
      if (attrs.empty() || attrs.back() != '/') stack.push_back(styled(stack.back(), attrs));
      continue;
    }
    const Style s = styled(stack.back(), attrs);
    const double x = std::stod(attribute(attrs, "x")), y = std::stod(attribute(attrs, "y"));
    const double w = double(characters(content)) * s.font_size * (s.bold ? 0.68 : 0.62);
    const std::string anchor = attribute(attrs, "text-anchor");
    const double left = anchor == "middle" ? x - w / 2 : anchor == "end" ? x - w : x;
    double xs[4] = {left, left + w, left + w, left}, ys[4] = {y - 0.8 * s.font_size, y - 0.8 * s.font_size,
                                                              y + 0.25 * s.font_size, y + 0.25 * s.font_size};
    std::smatch r;
    const std::string transform = attribute(attrs, "transform");
    if (std::regex_search(transform, r, std::regex("rotate\\(([-0-9.]+) ([-0-9.]+) ([-0-9.]+)\\)"))) {
      const double a = std::stod(r[1]) * M_PI / 180, cx = std::stod(r[2]), cy = std::stod(r[3]);
      for (int k = 0; k < 4; ++k) {
        const double dx = xs[k] - cx, dy = ys[k] - cy;
        xs[k] = cx + dx * std::cos(a) - dy * std::sin(a), ys[k] = cy + dx * std::sin(a) + dy * std::cos(a);
      }
    }
    const Overflow box{content, *std::min_element(xs, xs + 4), *std::min_element(ys, ys + 4),
                       *std::max_element(xs, xs + 4), *std::max_element(ys, ys + 4)};
    if (box.x0 < 0 || box.y0 < 0 || box.x1 > width || box.y1 > height) out.push_back(box);
  }
  REQUIRE(width > 0);
  return out;
}

void check_inside(const std::string& svg, const std::string& figure) {
  for (const Overflow& o : texts_outside(svg))
    FAIL_CHECK(figure << ": '" << o.text << "' spans x " << o.x0 << ".." << o.x1 << ", y " << o.y0 << ".." << o.y1
                      << ", outside the canvas");
}

Motion walk() { return read_bvh_file(KEYANIM_REPO_DATA_DIR "/cmu_02_01_walk.bvh"); }

}  // namespace

TEST_CASE("the checker sees text outside the canvas (left, right, rotated)") {
  auto doc = [](const std::string& body) {
    return "<svg width=\"200\" height=\"100\" font-size=\"12\">" + body + "</svg>";
  };
  CHECK(texts_outside(doc("<text x=\"10\" y=\"50\">twenty characters ok</text>")).empty());  // 149 px
  CHECK(texts_outside(doc("<text x=\"10\" y=\"50\">thirty characters of text, long</text>")).size() == 1);
  CHECK(texts_outside(doc("<text x=\"190\" y=\"50\" text-anchor=\"end\">twenty characters ok</text>")).empty());
  CHECK(texts_outside(doc("<text x=\"100\" y=\"50\" text-anchor=\"middle\">twenty characters ok</text>")).empty());
  CHECK(texts_outside(doc("<text x=\"50\" y=\"50\" text-anchor=\"middle\">twenty characters ok</text>")).size() == 1);
  CHECK(texts_outside(doc("<g font-size=\"24\"><text x=\"10\" y=\"50\">fifteen letters</text></g>")).size() == 1);
  CHECK(texts_outside(doc("<g font-size=\"24\"></g><text x=\"10\" y=\"50\">fifteen letters</text>")).empty());
  CHECK(texts_outside(doc("<text x=\"10\" y=\"50\" font-size=\"13\" font-weight=\"bold\">twenty-two characters!</text>")).size() == 1);
  CHECK(texts_outside(doc("<text x=\"10\" y=\"50\" font-size=\"13\">twenty-two characters!</text>")).empty());
  CHECK(texts_outside(doc("<text x=\"20\" y=\"50\" transform=\"rotate(-90 20 50)\">a label of 20 chars</text>")).size() == 1);
  CHECK(texts_outside(doc("<text x=\"10\" y=\"5\">top</text>")).size() == 1);
}

TEST_CASE("rate-distortion figure: a long corpus name and every other text inside the canvas") {
  const std::vector<cli::RdSeries> series{
      {"misc/PyMO__AV_8Walk_Meredith_HVHA_Rep1.bvh", {{0.0497, 10.78}, {0.497, 31.71}}},
      {"data/cmu_02_01_walk.bvh", {{0.0499, 9.21}, {0.5, 24.33}}},
      {"data/cmu_131_03_hop.bvh", {{0.0462, 16.17}, {0.463, 38.31}}}};
  check_inside(cli::rd_plot(series, "3 files; keys: error (a line per file); raw float32 = frames x channels x 4 bytes"), "rd plot");
  // A name far longer than a legend can hold is shortened in its middle, not clipped.
  const std::string long_name(300, 'n');
  const std::string svg = cli::rd_plot({{long_name + "_end.bvh", {{0.05, 10.0}}}}, "1 file");
  check_inside(svg, "rd plot, 300-character name");
  CHECK(svg.find("_end.bvh</text>") != std::string::npos);
}

TEST_CASE("render --against: the title with a Bandai file's names stays inside the canvas") {
  const Motion m = walk();
  const Motion one = decode_motion(to_clip(encode(m, EncodeSettings{}).clip), [] {
    ResampleOptions o;
    o.first_frame = o.last_frame = 97;
    return o;
  }());
  Motion original = m;
  original.values.assign(m.frame(97), m.frame(97) + m.channel_count());
  original.frame_count = 1;
  const std::string title = "dataset-1_walk_normal_001.kanim, frame 97 against dataset-1_walk_normal_001.bvh";
  const cli::PoseFigure fig =
      cli::render_pose({{&one, "dataset-1_walk_normal_001.kanim"}, {&original, "dataset-1_walk_normal_001.bvh"}}, 0, title);
  check_inside(fig.svg, "render --against");
  CHECK(fig.svg.find(">" + title + "</text>") != std::string::npos);
  const cli::PoseFigure alone = cli::render_pose({{&original, "walk.bvh"}}, 0, "walk.bvh, frame 97");
  check_inside(alone.svg, "render");
}

TEST_CASE("plot: a long file name in the title stays inside the canvas") {
  const Motion m = walk();
  cli::ChannelPlot plot;
  std::string error;
  REQUIRE(cli::plot_channel(m, EncodeSettings{}, 10, "bandai/dataset-2_raise-up-both-hands_normal_001.bvh", plot, error));
  check_inside(plot.svg, "plot");
}
