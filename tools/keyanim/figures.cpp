#include "figures.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "keyanim/clip.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/fk.h"
#include "keyanim/offline/metrics.h"
#include "keyanim/offline/report.h"
#include "escape.h"
#include "suggest.h"
#include "svg.h"

namespace keyanim::cli {

using svg::attr;
using svg::number;

namespace {

// Colours: a light, wide original under a thin, dark reconstruction, so that where they agree
// both stay visible.
constexpr const char* kOriginalColour = "#7aa6d8";
constexpr const char* kReconColour = "#c0392b";
constexpr const char* kPoseColours[2] = {"#1f4e9c", "#e8681e"};

// Three significant digits, no exponent for the magnitudes a figure shows.
std::string short_number(double v) {
  const double a = std::abs(v);
  const int decimals = a >= 100 ? 1 : a >= 10 ? 2 : a >= 1 ? 3 : a >= 0.01 ? 4 : 6;
  return number(v, decimals);
}

}  // namespace

std::optional<uint32_t> find_channel(const Skeleton& skeleton, const std::string& spec, std::string& error) {
  // The last colon splits: a joint name may contain one, a channel name never does.
  const size_t colon = spec.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == spec.size()) {
    error = "--channel expects JOINT:CHANNEL (e.g. RightArm:Zrotation), got '" + spec + "'";
    return std::nullopt;
  }
  const std::string joint = spec.substr(0, colon), channel = spec.substr(colon + 1);
  std::optional<ChannelType> type;
  for (uint8_t t = 0; t < 6; ++t)
    if (channel == channel_name(static_cast<ChannelType>(t))) type = static_cast<ChannelType>(t);
  if (!type) {
    error = "unknown channel '" + channel + "' (expected Xposition, Yposition, Zposition, Xrotation, Yrotation or Zrotation)";
    return std::nullopt;
  }
  for (const Joint& j : skeleton.joints) {
    if (j.end_site || j.name != joint) continue;
    for (size_t k = 0; k < j.channels.size(); ++k)
      if (j.channels[k] == *type) return j.first_channel + static_cast<uint32_t>(k);
    std::string has;
    for (const ChannelType t : j.channels) has += std::string(has.empty() ? "" : " ") + channel_name(t);
    error = "joint '" + joint + "' has no " + channel + " channel (it has: " + (has.empty() ? "none" : has) + ")";
    return std::nullopt;
  }
  error = no_joint_message(skeleton, joint);
  return std::nullopt;
}

std::string settings_text(const offline::EncodeSettings& s, double tolerance_units) {
  std::string t;
  switch (s.key_mode) {
    case offline::KeyMode::error:
      t = "error \xE2\x89\xA4 " + number(s.tolerance, 6) + (s.tolerance_in_percent ? "%" : " units");
      if (s.tolerance_in_percent) t += " (" + short_number(tolerance_units) + " units)";
      break;
    case offline::KeyMode::uniform: t = "uniform:" + std::to_string(s.uniform_interval); break;
    case offline::KeyMode::manual: t = "manual (" + std::to_string(s.manual_frames.size()) + " frames)"; break;
    case offline::KeyMode::curvature: t = "curvature"; break;
  }
  if (s.fit_tension) t += ", tension fit";
  else if (s.tension != 0.0f) t += ", tension " + number(s.tension, 3);
  return t;
}

namespace {

// The original with `channel` alone replaced by the clip's reconstruction, measured as every
// error is (metrics.h): what this one curve costs in world space.
offline::ErrorReport channel_alone_error(const offline::Motion& motion, const Clip& clip, uint32_t channel, double shell) {
  offline::Motion mixed = motion;
  const size_t stride = motion.channel_count();
  for (uint32_t f = 0; f < motion.frame_count; ++f) {
    float v = 0.0f;
    (void)clip.sample_channel(channel, static_cast<float>(f), v);  // the channel exists, f is finite
    mixed.values[size_t(f) * stride + channel] = double(v);
  }
  return offline::measure_error(motion, mixed, shell);
}

}  // namespace

bool plot_channel(const offline::Motion& motion, const offline::EncodeSettings& settings, uint32_t channel,
                  const std::string& file_label, ChannelPlot& out, std::string& error, FrameRange range) {
  out = {};
  const Skeleton& sk = motion.skeleton;
  if (channel >= motion.channel_count()) {
    error = "channel " + std::to_string(channel) + " out of range";
    return false;
  }
  if (motion.frame_count == 0) {
    error = "the motion has no frames";
    return false;
  }
  if (range.first > range.last || range.first >= motion.frame_count) {
    error = "frame range " + std::to_string(range.first) + ":" + std::to_string(range.last) + " is empty or past the last frame (" +
            std::to_string(motion.frame_count - 1) + ")";
    return false;
  }
  offline::EncodeResult result;
  try {
    result = offline::encode(motion, settings);
  } catch (const offline::Error& e) {
    error = e.what();
    return false;
  }
  // The decoder's own arrays: what a game would sample.
  const Clip clip = offline::to_clip(result.clip);
  auto value_at = [&](double x) {  // the channel exists and x is finite: sample_channel succeeds
    float v = 0.0f;
    (void)clip.sample_channel(channel, static_cast<float>(x), v);
    return double(v);
  };

  const uint32_t joint = sk.joint_of_channel(channel);
  const ChannelType type = sk.joints[joint].channels[channel - sk.joints[joint].first_channel];
  const bool rotation = is_rotation(type);
  const uint32_t n = motion.frame_count, first = range.first, last = std::min(range.last, n - 1);
  std::vector<double> original = motion.channel(channel);
  const uint32_t key_count = clip.channel(channel).key_count;
  std::vector<uint32_t> key_frames(key_count);
  std::vector<float> key_values(key_count);
  clip.channel_keys(channel, key_frames, key_values);
  // A quaternion node's keys hold its x, y, z: the channel's dots are its angle at them.
  const bool stored_quat = clip.channel(channel).stored != StoredAs::value;
  if (stored_quat)
    for (uint32_t k = 0; k < key_count; ++k) key_values[k] = static_cast<float>(value_at(key_frames[k]));
  // An angle and the same angle +-360 are one pose; show both curves on one branch.
  double shift = 0.0;
  if (rotation) {
    offline::unwrap_degrees(original);
    shift = 360.0 * std::round((original[0] - value_at(0.0)) / 360.0);
  }

  // Plot area and the reconstruction's sampling: between frames too when a frame is wide
  // enough for the spline's shape to show (otherwise one sample per frame).
  const svg::Rect area{84, 88, 856, 310};
  const double px_per_frame = last > first ? area.w / double(last - first) : area.w;
  const uint32_t steps = static_cast<uint32_t>(std::clamp(std::floor(px_per_frame / 3.0), 1.0, 8.0));
  std::vector<double> recon_pos, recon;
  for (uint32_t f = first; f <= last; ++f)
    for (uint32_t j = 0; j < (f < last ? steps : 1u); ++j) recon_pos.push_back(f + double(j) / steps);
  for (const double x : recon_pos) recon.push_back(value_at(x) + shift);
  if (stored_quat && rotation) offline::unwrap_degrees(recon);  // angles of a rotation: each in (-180, 180]

  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (uint32_t f = first; f <= last; ++f) lo = std::min(lo, original[f]), hi = std::max(hi, original[f]);
  for (const double v : recon) lo = std::min(lo, v), hi = std::max(hi, v);
  size_t k0 = 0, k1 = 0;  // keys inside the range: [k0, k1)
  while (k0 < key_frames.size() && key_frames[k0] < first) ++k0;
  for (k1 = k0; k1 < key_frames.size() && key_frames[k1] <= last; ++k1)
    lo = std::min(lo, double(key_values[k1]) + shift), hi = std::max(hi, double(key_values[k1]) + shift);
  const double pad = 0.04 * (hi - lo);

  out.key_count = static_cast<uint32_t>(k1 - k0);
  out.channel_keys = static_cast<uint32_t>(key_frames.size());
  out.max_channel_error = result.error.channel_max.size() > channel ? result.error.channel_max[channel] : 0.0;
  out.tolerance_units = result.tolerance_units;
  const offline::ErrorReport alone = channel_alone_error(motion, clip, channel, result.shell_units);
  out.channel_world_error = alone.max_error;
  out.channel_world_point = offline::point_name(sk, alone.worst_joint, alone.worst_point);
  out.channel_world_frame = alone.worst_frame;
  const bool applied = settings.key_mode == offline::KeyMode::error;  // else --error only guided quantization
  const std::string unit = rotation ? "degrees" : "file units";
  const std::string spec = sk.joints[joint].name + ":" + channel_name(type);
  const bool whole = first == 0 && last == n - 1;
  const std::string shown = whole ? "" : " (frames " + std::to_string(first) + "-" + std::to_string(last) + ")";

  const std::string heading =
      file_label + "  " + spec + shown + "  \xE2\x80\x94  keys: " + settings_text(settings, result.tolerance_units);
  const std::string subheading = count_of(out.channel_keys, "key") + " on this channel (" + count_of(n, "frame") + "), " +
                                 std::to_string(result.total_keys) + " in the clip; max channel error " +
                                 short_number(out.max_channel_error) + " " + unit + "; max joint error " +
                                 short_number(result.error.max_error) + " file units";
  const double share = out.tolerance_units > 0.0 ? out.channel_world_error / out.tolerance_units : 0.0;
  const std::string world = "this channel's reconstruction alone moves a point by " +
                            short_number(out.channel_world_error) + " file units at most (" + out.channel_world_point +
                            ", frame " + std::to_string(out.channel_world_frame) + "): " + short_number(share) +
                            "x the " + (applied ? "tolerance " : "--error ") + short_number(out.tolerance_units);
  // Wider than the plot when a heading needs it (a long file name), never clipped.
  const double width = std::max({960.0, area.x + svg::text_width(heading, 14, true) + 24,
                                 area.x + svg::text_width(subheading) + 24, area.x + svg::text_width(world) + 24});
  svg::Document doc(width, 440 + 16);
  const svg::Axes axes(area, {double(first), double(last)}, svg::nice_range({lo - pad, hi + pad}, 6));
  doc.title(file_label + " " + spec + ": original and reconstruction" + shown);
  doc.text({84, 22}, heading, attr("class", "title") + " font-size=\"14\" font-weight=\"bold\"");
  doc.text({84, 40}, subheading, attr("class", "subtitle") + " fill=\"#444\"");
  doc.text({84, 58}, world, attr("class", "subtitle world") + " fill=\"#444\"");
  axes.draw(doc, "frame", std::string(channel_name(type)) + " (" + unit + ")", 10, 6);

  std::vector<svg::Point> pts;
  for (uint32_t f = first; f <= last; ++f) pts.push_back(axes.at(f, original[f]));
  doc.path(pts, attr("class", "series original") + " fill=\"none\"" + attr("stroke", kOriginalColour) +
                    " stroke-width=\"3.5\" stroke-linejoin=\"round\"");
  pts.clear();
  for (size_t i = 0; i < recon.size(); ++i) pts.push_back(axes.at(recon_pos[i], recon[i]));
  doc.path(pts, attr("class", "series reconstructed") + " fill=\"none\"" + attr("stroke", kReconColour) +
                    " stroke-width=\"1.2\" stroke-linejoin=\"round\"");
  // Dense keys get smaller dots without an outline, so that the curve still shows through.
  const double spacing = area.w / std::max<double>(1.0, double(out.key_count));
  const double r = std::clamp(spacing * 0.45, 1.3, 3.0);
  doc.open_group(attr("class", "keys") + attr("fill", kReconColour) +
                 (r >= 2.5 ? " stroke=\"white\" stroke-width=\"0.6\"" : ""));
  for (size_t k = k0; k < k1; ++k)
    doc.circle(axes.at(key_frames[k], double(key_values[k]) + shift), r, attr("class", "key"));
  doc.close_group();
  const std::vector<svg::LegendEntry> entries{
      {"original", kOriginalColour, false, 3.5},
      {"reconstructed (" + count_of(out.key_count, "key") + (whole ? "" : " shown") + ")", kReconColour,
       true, 1.2}};
  svg::legend(doc, {area.x + area.w - svg::legend_width(entries), 76}, entries);
  out.svg = doc.finish();
  return true;
}

bool same_skeleton(const Skeleton& a, const Skeleton& b) {
  if (a.joints.size() != b.joints.size()) return false;
  for (size_t i = 0; i < a.joints.size(); ++i) {
    const Joint &x = a.joints[i], &y = b.joints[i];
    if (x.parent != y.parent || x.end_site != y.end_site || x.name != y.name || x.channels != y.channels) return false;
  }
  return true;
}

PoseFigure render_pose(const std::vector<PoseSeries>& series, uint32_t frame, const std::string& title,
                       PositionReading reading, UpAxis up_axis) {
  // The vertical world axis of both views, and the horizontal one of the side view (the front
  // view's is x).
  const int up = static_cast<int>(up_axis), across = up == 1 ? 2 : 1;
  PoseFigure fig;
  std::vector<std::vector<offline::Vec3>> pos(series.size());
  offline::Vec3 lo{}, hi{};
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  for (size_t s = 0; s < series.size(); ++s) {
    const offline::Motion& m = *series[s].motion;
    offline::world_positions(m.skeleton, m.frame(frame), pos[s], reading);
    for (const offline::Vec3& p : pos[s])
      for (int a = 0; a < 3; ++a)
        if (std::isfinite(p[a])) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  }
  for (int a = 0; a < 3; ++a)
    if (!(hi[a] >= lo[a])) lo[a] = hi[a] = 0.0;
  if (series.size() == 2) {
    for (size_t j = 0; j < pos[0].size() && j < pos[1].size(); ++j) {
      const double d = std::hypot(pos[0][j][0] - pos[1][j][0], pos[0][j][1] - pos[1][j][1], pos[0][j][2] - pos[1][j][2]);
      if (d > fig.worst_distance) fig.worst_distance = d, fig.worst_node = static_cast<uint32_t>(j);
    }
  }

  // One scale for both views and both axes (equal aspect); each view centred on the figure.
  const double width_units = std::max(hi[0] - lo[0], hi[across] - lo[across]), height_units = hi[up] - lo[up];
  double pad = 0.08 * std::max(width_units, height_units);
  if (!(pad > 0.0)) pad = 1.0;
  const double wu = width_units + 2 * pad, hu = height_units + 2 * pad;
  const double scale = std::min(440.0 / hu, 380.0 / wu);
  const double panel_w = std::max(260.0, wu * scale), panel_h = std::max(260.0, hu * scale);
  const double left = 78, gap = 96, top = 96, right = 24, bottom = 56;
  std::vector<svg::LegendEntry> entries;
  for (size_t s = 0; s < series.size() && s < 2; ++s) entries.push_back({series[s].label, kPoseColours[s], true, s == 0 ? 3.0 : 1.6});
  const Skeleton& sk = series.front().motion->skeleton;
  const std::string subtitle = series.size() == 2 ? "largest distance: " + offline::node_name(sk, fig.worst_node) + " " +
                                                        short_number(fig.worst_distance) + " file units"
                                                  : "";
  // Wide enough for the two views, and for the title, the legend and the subtitle above them
  // (a title naming two long files was cut off).
  const double width = std::max({left + 2 * panel_w + gap + right, left + svg::text_width(title, 14, true) + right,
                                 left + svg::legend_width(entries) + right, left + svg::text_width(subtitle) + right});
  const double height = top + panel_h + bottom;
  auto centred = [&](int axis, double pixels) {
    const double c = (lo[axis] + hi[axis]) / 2, half = pixels / scale / 2;
    return svg::Range{c - half, c + half};
  };
  const svg::Range yr = centred(up, panel_h);
  const svg::Axes front({left, top, panel_w, panel_h}, centred(0, panel_w), yr);
  const svg::Axes side({left + panel_w + gap, top, panel_w, panel_h}, centred(across, panel_w), yr);

  svg::Document doc(width, height);
  doc.title(title);
  doc.text({left, 22}, title, attr("class", "title") + " font-size=\"14\" font-weight=\"bold\"");
  svg::legend(doc, {left, 44}, entries);
  if (series.size() == 2) doc.text({left, 64}, subtitle, attr("class", "subtitle") + " fill=\"#444\"");

  const std::string u(1, "xyz"[up]), a(1, "xyz"[across]);
  const struct {
    const svg::Axes* axes;
    int h;  // horizontal world axis
    std::string name;
    std::string x_label;
  } views[2] = {{&front, 0, "front view (x-" + u + ")", "x (file units)"},
                {&side, across, "side view (" + a + "-" + u + ")", a + " (file units)"}};
  for (const auto& v : views) {
    const svg::Axes& ax = *v.axes;
    v.axes->draw(doc, v.x_label, u + " (file units)", 5, 6);
    doc.text({ax.area().x + ax.area().w / 2, top - 8}, v.name, attr("class", "view-title") + " font-weight=\"bold\"",
             "middle");
    for (size_t s = 0; s < series.size() && s < 2; ++s) {
      const Skeleton& k = series[s].motion->skeleton;
      auto at = [&](uint32_t j) { return ax.at(pos[s][j][v.h], pos[s][j][up]); };
      doc.open_group(attr("class", "pose pose" + std::to_string(s)) + attr("stroke", kPoseColours[s]) +
                     attr("fill", kPoseColours[s]) + " stroke-linecap=\"round\"" +
                     attr("stroke-width", s == 0 ? "3" : "1.6"));
      for (uint32_t j = 0; j < k.joints.size(); ++j) {
        const int32_t p = k.joints[j].parent;
        if (p >= 0 && static_cast<uint32_t>(p) < j) doc.line(at(uint32_t(p)), at(j), attr("class", "bone"));
      }
      for (uint32_t j = 0; j < k.joints.size(); ++j)
        doc.circle(at(j), s == 0 ? 2.6 : 1.8, attr("class", "joint") + " stroke=\"none\"");
      doc.close_group();
    }
    if (series.size() == 2 && fig.worst_node < pos[0].size()) {
      const svg::Point p = ax.at(pos[0][fig.worst_node][v.h], pos[0][fig.worst_node][up]);
      doc.circle(p, 8.0, attr("class", "worst") + " fill=\"none\" stroke=\"#c00\" stroke-width=\"1.2\"");
      // Beside the circle or in a corner of the view, wherever the label covers least of the
      // figure (joints and points along the bones counted), joined to the circle by a leader line.
      const std::string label = offline::node_name(sk, fig.worst_node) + " " + short_number(fig.worst_distance);
      const svg::Rect& area = ax.area();
      const double tw = 7.0 * static_cast<double>(label.size()) + 4.0, th = 16.0, inset = 6.0;
      const svg::Rect candidates[] = {
          {p.x + 12.0, p.y - 22.0, tw, th}, {p.x - 12.0 - tw, p.y - 22.0, tw, th},
          {p.x + 12.0, p.y + 6.0, tw, th},  {p.x - 12.0 - tw, p.y + 6.0, tw, th},
          {area.x + inset, area.y + inset, tw, th}, {area.x + area.w - inset - tw, area.y + inset, tw, th},
          {area.x + inset, area.y + area.h - inset - th, tw, th},
          {area.x + area.w - inset - tw, area.y + area.h - inset - th, tw, th}};
      auto covered = [&](const svg::Rect& r) {
        auto inside = [&](svg::Point q) {
          return q.x >= r.x - 4 && q.x <= r.x + r.w + 4 && q.y >= r.y - 4 && q.y <= r.y + r.h + 4;
        };
        int n = 0;
        for (size_t s = 0; s < series.size() && s < 2; ++s) {
          const Skeleton& k = series[s].motion->skeleton;
          for (uint32_t j = 0; j < k.joints.size(); ++j) {
            const svg::Point q = ax.at(pos[s][j][v.h], pos[s][j][up]);
            n += inside(q);
            if (const int32_t par = k.joints[j].parent; par >= 0 && static_cast<uint32_t>(par) < j) {
              const svg::Point pq = ax.at(pos[s][uint32_t(par)][v.h], pos[s][uint32_t(par)][up]);
              for (int t = 1; t < 8; ++t) n += inside({q.x + (pq.x - q.x) * t / 8, q.y + (pq.y - q.y) * t / 8});
            }
          }
        }
        return n;
      };
      const svg::Rect* best = nullptr;
      int best_n = 0;
      double best_d = 0.0;
      for (const svg::Rect& r : candidates) {
        if (r.x < area.x || r.x + r.w > area.x + area.w || r.y < area.y || r.y + r.h > area.y + area.h) continue;
        const int n = covered(r);
        const double d = std::hypot(r.x + r.w / 2 - p.x, r.y + r.h / 2 - p.y);
        if (!best || n < best_n || (n == best_n && d < best_d)) best = &r, best_n = n, best_d = d;
      }
      const svg::Rect box = best ? *best : svg::Rect{area.x + inset, area.y + inset, tw, th};
      // Leader: from the box's nearest point to the circle's edge.
      const svg::Point near{std::clamp(p.x, box.x, box.x + box.w), std::clamp(p.y, box.y, box.y + box.h)};
      const double dist = std::hypot(near.x - p.x, near.y - p.y);
      if (dist > 10.0)
        doc.line(near, {p.x + (near.x - p.x) * 8.0 / dist, p.y + (near.y - p.y) * 8.0 / dist},
                 attr("class", "leader") + " stroke=\"#c00\" stroke-width=\"0.8\"");
      doc.rect(box, " fill=\"white\" fill-opacity=\"0.85\"");
      doc.text({box.x + 2.0, box.y + 12.5}, label, attr("class", "worst-label") + " fill=\"#c00\"");
    }
  }
  fig.svg = doc.finish();
  return fig;
}

}  // namespace keyanim::cli
