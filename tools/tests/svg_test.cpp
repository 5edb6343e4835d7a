// The SVG figures of `keyanim plot` and `keyanim render`: the writer's number formatting and
// ticks (hand-computed), and figure contents checked against what the encoder and the error
// metrics report on their own (one key marker per key, at the key's frame, on the curve).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <regex>
#include <string>
#include <vector>

#include "escape.h"
#include "figures.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/report.h"
#include "svg.h"

using namespace keyanim;
using namespace keyanim::offline;

namespace {

Motion walk() { return read_bvh_file(KEYANIM_REPO_DATA_DIR "/cmu_02_01_walk.bvh"); }

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

// The vertices of the <path> of the given class: "Mx,y l dx,dy dx,dy ..." summed up.
std::vector<svg::Point> path_points(const std::string& doc, const std::string& cls) {
  const std::regex re("<path d=\"([^\"]*)\" class=\"" + cls + "\"");
  std::smatch m;
  REQUIRE(std::regex_search(doc, m, re));
  const std::string d = m[1];
  REQUIRE(d.size() > 1);
  REQUIRE(d[0] == 'M');
  std::vector<double> nums;
  const char* p = d.c_str() + 1;
  bool relative = false;
  while (*p) {
    if (*p == 'l') relative = true;
    if (*p == ',' || *p == ' ' || *p == 'l') {
      ++p;
      continue;
    }
    char* end = nullptr;
    nums.push_back(std::strtod(p, &end));
    REQUIRE(end != p);
    p = end;
  }
  REQUIRE(relative);
  REQUIRE(nums.size() % 2 == 0);
  std::vector<svg::Point> pts;
  for (size_t i = 0; i < nums.size(); i += 2) {
    svg::Point q{nums[i], nums[i + 1]};
    if (!pts.empty()) q.x += pts.back().x, q.y += pts.back().y;
    pts.push_back(q);
  }
  return pts;
}

std::vector<svg::Point> key_markers(const std::string& doc) {
  const std::regex re("<circle cx=\"([-0-9.]+)\" cy=\"([-0-9.]+)\" r=\"[0-9.]+\" class=\"key\"/>");
  std::vector<svg::Point> out;
  for (auto it = std::sregex_iterator(doc.begin(), doc.end(), re); it != std::sregex_iterator(); ++it)
    out.push_back({std::stod((*it)[1]), std::stod((*it)[2])});
  return out;
}

// For every marker: the frame whose original-curve vertex has its x (frames are 2.5 px apart
// in the walk's plot, coordinates are rounded to 0.1 px), and the reconstruction's vertex there.
void check_markers_on_keys(const std::string& doc, const std::vector<uint32_t>& key_frames, uint32_t first_frame) {
  const std::vector<svg::Point> original = path_points(doc, "series original");
  const std::vector<svg::Point> recon = path_points(doc, "series reconstructed");
  const std::vector<svg::Point> markers = key_markers(doc);
  REQUIRE(markers.size() == key_frames.size());
  for (size_t k = 0; k < markers.size(); ++k) {
    const auto nearest = [&](const std::vector<svg::Point>& v) {
      return std::min_element(v.begin(), v.end(), [&](const svg::Point& a, const svg::Point& b) {
               return std::abs(a.x - markers[k].x) < std::abs(b.x - markers[k].x);
             }) - v.begin();
    };
    const auto f = nearest(original);
    CHECK(std::abs(original[size_t(f)].x - markers[k].x) < 0.11);
    CHECK(uint32_t(f) + first_frame == key_frames[k]);
    // The spline passes through its keys: the marker sits on the reconstructed curve.
    const auto r = nearest(recon);
    CHECK(std::abs(recon[size_t(r)].x - markers[k].x) < 0.11);
    CHECK(std::abs(recon[size_t(r)].y - markers[k].y) < 0.21);
  }
}

}  // namespace

TEST_SUITE("svg") {

TEST_CASE("svg numbers are short fixed point") {
  CHECK(svg::number(3.0) == "3");
  CHECK(svg::number(2.50, 2) == "2.5");
  CHECK(svg::number(-0.04, 1) == "0");  // no "-0"
  CHECK(svg::number(123.456, 1) == "123.5");
  CHECK(svg::number(-7.25, 3) == "-7.25");
  CHECK(svg::compact(0.5) == ".5");
  CHECK(svg::compact(-0.25, 2) == "-.25");
  CHECK(svg::compact(12.5) == "12.5");
  CHECK(svg::escape("a<b & \"c\">") == "a&lt;b &amp; &quot;c&quot;&gt;");
  CHECK(svg::attr("class", "x\"y") == " class=\"x&quot;y\"");
  // What XML cannot hold becomes visible escapes (expected strings written by hand).
  CHECK(svg::escape("<\xff\x1b>") == "&lt;\\xff\\x1b&gt;");
  CHECK(svg::escape("\xef\xbf\xbe") == "\\ufffe");  // U+FFFE is not an XML character
}

TEST_CASE("printable keeps UTF-8 text and escapes what could act on a terminal") {
  using cli::printable;
  CHECK(printable("Hips h\xc3\xbc" "fte \xe6\xad\xa9") == "Hips h\xc3\xbc" "fte \xe6\xad\xa9");  // ü, 歩
  CHECK(printable("a\x1b[31mb") == "a\\x1b[31mb");
  CHECK(printable("x\ny\tz\x7f") == "x\\x0ay\\x09z\\x7f");
  CHECK(printable("\xc2\x9b") == "\\u009b");                 // C1 CSI
  CHECK(printable("\xe2\x80\xae" "evil") == "\\u202e" "evil");      // right-to-left override
  CHECK(printable("\xff\xfe") == "\\xff\\xfe");             // not UTF-8
  CHECK(printable("\xc0\xaf") == "\\xc0\\xaf");             // overlong '/'
  CHECK(printable("\xed\xa0\x80") == "\\xed\\xa0\\x80");     // a surrogate
  CHECK(printable("\xe2\x80") == "\\xe2\\x80");             // cut short
  CHECK(printable("\xf4\x90\x80\x80") == "\\xf4\\x90\\x80\\x80");  // above U+10FFFF
  CHECK(printable("\xf0\x9f\x98\x80") == "\xf0\x9f\x98\x80");   // U+1F600 stays
}

TEST_CASE("json_text is dump() for UTF-8 and keeps other bytes as \\udcHH") {
  const nlohmann::json ok = {{"name", "h\xc3\xbc" "fte \"q\" \\ \n\x01"}, {"n", 1.5}, {"list", {1, 2, nullptr, true}}, {"o", {{"a", "b"}}}};
  CHECK(cli::json_text(ok) == ok.dump());
  const nlohmann::json bad = {{"j", "r\xff\x1b[31m\xe2\x80"}};
  CHECK(cli::json_text(bad) == "{\"j\":\"r\\udcff\\u001b[31m\\udce2\\udc80\"}");
  CHECK_THROWS(bad.dump());  // what the tool used to do
}

TEST_CASE("svg ticks use 1 2 5 steps") {
  // 0..4510 in about 10 steps: 451 -> 500.
  const std::vector<double> t = svg::nice_ticks({0, 4510}, 10);
  REQUIRE(t.size() == 10);
  CHECK(t.front() == 0.0);
  CHECK(t.back() == 4500.0);
  // -105.3..455.2 in about 6 steps: 93.4 -> 100, widened to -200..500.
  const svg::Range r = svg::nice_range({-105.3, 455.2}, 6);
  CHECK(r.lo == -200.0);
  CHECK(r.hi == 500.0);
  // 0.013..0.061 in about 4: 0.012 -> 0.01 steps: 0.02 .. 0.06.
  const std::vector<double> s = svg::nice_ticks({0.013, 0.061}, 4);
  REQUIRE(s.size() == 5);
  CHECK(s.front() == doctest::Approx(0.02));
  CHECK(s.back() == doctest::Approx(0.06));
  // A single value is widened, never divided by zero.
  const svg::Range z = svg::nice_range({5, 5}, 4);
  CHECK(z.lo < 5.0);
  CHECK(z.hi > 5.0);
}

TEST_CASE("plot channel names are parsed with clear errors") {
  const Motion m = walk();
  std::string error;
  const auto c = cli::find_channel(m.skeleton, "RightArm:Zrotation", error);
  REQUIRE(c.has_value());
  const uint32_t j = m.skeleton.joint_of_channel(*c);
  CHECK(m.skeleton.joints[j].name == "RightArm");
  CHECK(m.skeleton.joints[j].channels[*c - m.skeleton.joints[j].first_channel] == ChannelType::z_rotation);
  CHECK_FALSE(cli::find_channel(m.skeleton, "RightArm:Wrotation", error));
  CHECK(error.find("unknown channel 'Wrotation'") != std::string::npos);
  CHECK_FALSE(cli::find_channel(m.skeleton, "Nobody:Xrotation", error));
  CHECK(error.find("no joint named 'Nobody'") != std::string::npos);
  CHECK_FALSE(cli::find_channel(m.skeleton, "RightArm:Xposition", error));
  CHECK(error.find("has no Xposition") != std::string::npos);
  CHECK_FALSE(cli::find_channel(m.skeleton, "RightArm", error));
}

TEST_CASE("plot marks exactly the encoder's keys on the reconstructed curve") {
  const Motion m = walk();
  std::string error;
  for (const char* spec : {"RightArm:Zrotation", "Hips:Yposition"}) {
    for (const KeyMode mode : {KeyMode::error, KeyMode::curvature}) {
      CAPTURE(spec);
      CAPTURE(int(mode));
      EncodeSettings s;
      s.key_mode = mode;
      const uint32_t c = *cli::find_channel(m.skeleton, spec, error);
      cli::ChannelPlot plot;
      REQUIRE(cli::plot_channel(m, s, c, "walk.bvh", plot, error));
      // The keys as the encoder chose them, from an encode of our own.
      const EncodeResult r = encode(m, s);
      const std::vector<uint32_t>& frames = r.clip.channels[c].frames;
      REQUIRE(frames.size() > 2);
      CHECK(plot.key_count == frames.size());
      CHECK(count(plot.svg, "class=\"key\"") == frames.size());
      CHECK(plot.max_channel_error == r.error.channel_max[c]);
      check_markers_on_keys(plot.svg, frames, 0);
      // Structure: two axes, one path per series, axis labels with units, the legend.
      CHECK(count(plot.svg, "class=\"axis ") == 2);
      CHECK(count(plot.svg, "class=\"series ") == 2);
      CHECK(path_points(plot.svg, "series original").size() == m.frame_count);
      CHECK(plot.svg.find(">frame</text>") != std::string::npos);
      const bool rotation = std::string(spec).find("rotation") != std::string::npos;
      CHECK(plot.svg.find(rotation ? ">Zrotation (degrees)</text>" : ">Yposition (file units)</text>") != std::string::npos);
      CHECK(plot.svg.find(">original</text>") != std::string::npos);
      CHECK(plot.svg.find(">reconstructed (" + std::to_string(frames.size()) + " keys)</text>") != std::string::npos);
    }
  }
}

TEST_CASE("plot of a frame range marks only the keys inside it") {
  const Motion m = walk();
  std::string error;
  EncodeSettings s;
  s.key_mode = KeyMode::curvature;
  const uint32_t c = *cli::find_channel(m.skeleton, "LeftUpLeg:Xrotation", error);
  cli::ChannelPlot plot;
  REQUIRE(cli::plot_channel(m, s, c, "walk.bvh", plot, error, {100, 200}));
  const EncodeResult r = encode(m, s);
  std::vector<uint32_t> inside;
  for (const uint32_t f : r.clip.channels[c].frames)
    if (f >= 100 && f <= 200) inside.push_back(f);
  REQUIRE(!inside.empty());
  CHECK(plot.key_count == inside.size());
  CHECK(plot.channel_keys == r.clip.channels[c].frames.size());
  CHECK(path_points(plot.svg, "series original").size() == 101);
  // 101 frames on 856 px: 8.6 px per frame, so the spline is also sampled between frames.
  CHECK(path_points(plot.svg, "series reconstructed").size() > 101);
  const std::vector<svg::Point> original = path_points(plot.svg, "series original");
  const std::vector<svg::Point> markers = key_markers(plot.svg);
  REQUIRE(markers.size() == inside.size());
  for (size_t k = 0; k < markers.size(); ++k) CHECK(std::abs(original[inside[k] - 100].x - markers[k].x) < 0.11);
  // Empty and reversed ranges are refused.
  CHECK_FALSE(cli::plot_channel(m, s, c, "walk.bvh", plot, error, {344, 400}));
  CHECK_FALSE(cli::plot_channel(m, s, c, "walk.bvh", plot, error, {20, 10}));
}

TEST_CASE("render labels the node the error metrics name at their worst frame") {
  const Motion m = walk();
  EncodeSettings s;
  s.key_mode = KeyMode::uniform;
  s.uniform_interval = 20;  // coarse on purpose: a visible, unambiguous worst node
  const EncodeResult r = encode(m, s);
  const Motion decoded = decode_motion(to_clip(r.clip));
  const uint32_t frame = r.error.worst_frame;
  const cli::PoseFigure fig =
      cli::render_pose({{&m, "original"}, {&decoded, "reconstruction"}}, frame, "walk.bvh, frame");
  // measure_error's maximum over nodes and frames is reached at its worst frame and node.
  CHECK(fig.worst_node == r.error.worst_joint);
  CHECK(fig.worst_distance == doctest::Approx(r.error.max_error).epsilon(1e-9));
  // Two panels, each with both poses: a bone per node that has a parent, a dot per node.
  size_t bones = 0;
  for (const Joint& j : m.skeleton.joints) bones += j.parent >= 0;
  CHECK(count(fig.svg, "class=\"axis ") == 4);
  CHECK(count(fig.svg, "class=\"bone\"") == 2 * 2 * bones);
  CHECK(count(fig.svg, "class=\"joint\"") == 2 * 2 * m.skeleton.joints.size());
  CHECK(count(fig.svg, "class=\"worst\"") == 2);
  CHECK(fig.svg.find(offline::node_name(m.skeleton, r.error.worst_joint)) != std::string::npos);
  CHECK(fig.svg.find(">x (file units)</text>") != std::string::npos);
  CHECK(fig.svg.find(">z (file units)</text>") != std::string::npos);
  CHECK(count(fig.svg, ">y (file units)</text>") == 2);

  // One pose alone: no comparison, no label.
  const cli::PoseFigure one = cli::render_pose({{&m, "walk.bvh"}}, 0, "walk.bvh, frame 0");
  CHECK(count(one.svg, "class=\"bone\"") == 2 * bones);
  CHECK(count(one.svg, "class=\"worst\"") == 0);
}

TEST_CASE("render keeps an equal aspect ratio in both views") {
  const Motion m = walk();
  const cli::PoseFigure fig = cli::render_pose({{&m, "walk.bvh"}}, 100, "t");
  // Pixels per unit from the tick labels' positions: ticks are text at x (horizontal axis) or
  // y (vertical axis); every panel's step in pixels per unit must agree.
  const std::regex re("<text x=\"([-0-9.]+)\" y=\"([-0-9.]+)\"( text-anchor=\"(middle|end)\")?>(-?[0-9.]+)</text>");
  std::vector<std::pair<double, double>> horizontal, vertical;  // (pixel, value)
  for (auto it = std::sregex_iterator(fig.svg.begin(), fig.svg.end(), re); it != std::sregex_iterator(); ++it) {
    const std::string anchor = (*it)[4];
    const double value = std::stod((*it)[5]);
    if (anchor == "middle") horizontal.push_back({std::stod((*it)[1]), value});
    else if (anchor == "end") vertical.push_back({std::stod((*it)[2]), value});
  }
  REQUIRE(horizontal.size() >= 4);
  REQUIRE(vertical.size() >= 4);
  const double sx = (horizontal[1].first - horizontal[0].first) / (horizontal[1].second - horizontal[0].second);
  const double sy = -(vertical[1].first - vertical[0].first) / (vertical[1].second - vertical[0].second);
  CHECK(sx == doctest::Approx(sy).epsilon(0.01));
  const double sz = (horizontal.back().first - horizontal[horizontal.size() - 2].first) /
                    (horizontal.back().second - horizontal[horizontal.size() - 2].second);
  CHECK(sz == doctest::Approx(sy).epsilon(0.01));
}

}  // TEST_SUITE
