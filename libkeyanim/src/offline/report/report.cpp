#include "keyanim/offline/report.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <set>

#include "keyanim/offline/fk.h"
#include "keyanim/offline/metrics.h"
#include "keyanim/offline/notes.h"
#include "keyanim/offline/number_text.h"

namespace keyanim::offline {

std::string node_name(const Skeleton& s, uint32_t node) { return offline::point_name(s, node, 0); }

const char* reading_name(PositionReading r) { return r == PositionReading::add ? "add" : "replace"; }

nlohmann::json error_json(const Skeleton& s, const offline::ErrorReport& e) {
  nlohmann::json j = {{"max", e.max_error},
                      {"rms", e.rms_error},
                      {"worst_joint", node_name(s, e.worst_joint)},
                      {"worst_point", offline::point_name(s, e.worst_joint, e.worst_point)},
                      {"worst_shell_axis", nullptr},
                      {"worst_frame", e.worst_frame},
                      {"shell", e.shell},
                      {"readings", e.both_readings ? nlohmann::json{"replace", "add"} : nlohmann::json{"replace"}}};
  if (e.worst_point >= 1 && e.worst_point <= 3) j["worst_shell_axis"] = std::string(1, char('x' + e.worst_point - 1));
  if (e.both_readings) {
    j["worst_reading"] = reading_name(e.worst_reading);
    j["max_by_reading"] = {{"replace", e.reading_max[size_t(PositionReading::replace)]},
                           {"add", e.reading_max[size_t(PositionReading::add)]}};
  }
  return j;
}

std::string error_text(const Skeleton& s, const offline::ErrorReport& e) {
  return "max " + offline::general_text(e.max_error) + " (" + offline::point_name(s, e.worst_joint, e.worst_point) +
         ", frame " + std::to_string(e.worst_frame) +
         (!e.both_readings ? "" : e.worst_reading == PositionReading::add ? ", add reading" : ", replace reading") +
         "), rms " + offline::general_text(e.rms_error, 3);
}
std::string tolerance_warning(const offline::EncodeSettings& s, double tolerance_units, double max_error) {
  if (s.key_mode == offline::KeyMode::error || max_error <= tolerance_units) return {};
  const std::string mode = s.key_mode == offline::KeyMode::uniform ? "uniform:" + std::to_string(s.uniform_interval)
                           : s.key_mode == offline::KeyMode::manual  ? "manual"
                                                                     : "curvature";
  return "error max " + offline::general_text(max_error) + " exceeds --error " + offline::general_text(s.tolerance) +
         (s.tolerance_in_percent ? "%" : "") + " (" + offline::general_text(tolerance_units) + " units), which --keys " +
         mode + " does not enforce";
}

nlohmann::json encode_summary(const std::string& input, const std::string& output, const offline::Motion& motion,
                              uint64_t bvh_bytes, const offline::EncodeSettings& settings,
                              const offline::EncodeResult& result, uint64_t kanim_bytes, double encode_ms) {
  const double raw = 4.0 * motion.frame_count * motion.channel_count();
  nlohmann::json j = {
      {"input", input},
      {"output", output},
      {"frames", motion.frame_count},
      {"channels", motion.channel_count()},
      {"frame_time", motion.frame_time},
      {"keys", result.total_keys},
      {"bvh_bytes", bvh_bytes},
      {"raw_f32_bytes", static_cast<uint64_t>(raw)},
      {"kanim_bytes", kanim_bytes},
      {"ratio_raw_f32", raw / double(kanim_bytes)},
      {"error", error_json(motion.skeleton, result.error)},
      {"encode_ms", encode_ms},
  };
  // Only error mode applies the tolerance; the other modes say whether --error held.
  if (settings.key_mode == offline::KeyMode::error) {
    j["tolerance"] = result.tolerance_units;
  } else {
    j["error_limit"] = result.tolerance_units;
    j["error_limit_met"] = result.error.max_error <= result.tolerance_units;
  }
  return j;
}

namespace {

// Skeleton facts common to both kinds of file.
nlohmann::json skeleton_json(const Skeleton& s) {
  uint32_t joints = 0, end_sites = 0, roots = 0;
  std::set<std::string> orders;
  for (const Joint& j : s.joints) {
    (j.end_site ? end_sites : joints) += 1;
    roots += j.parent < 0;
    std::string order;
    for (ChannelType t : j.channels)
      if (is_rotation(t)) order += char('X' + channel_axis(t));
    if (!order.empty()) orders.insert(order);
  }
  return {{"joints", joints},
          {"end_sites", end_sites},
          {"roots", roots},
          {"channels", s.channel_count()},
          {"size", offline::skeleton_size(s)},
          {"rotation_orders", std::vector<std::string>(orders.begin(), orders.end())}};
}

// What the encoder notes say was guaranteed (empty for a file without such notes).
nlohmann::json guarantee_json(const std::string& notes) {
  nlohmann::json j = nlohmann::json::object();
  for (const char* key : {"tolerance_units", "shell_units", "max_error"})
    if (auto v = offline::note_number(notes, key)) j[key] = *v;
  if (auto r = offline::note(notes, "readings")) {
    j["readings"] = nlohmann::json::array();
    for (size_t at = 0; at <= r->size();) {
      const size_t comma = std::min(r->find(',', at), r->size());
      j["readings"].push_back(r->substr(at, comma - at));
      at = comma + 1;
    }
  }
  for (const char* key : {"worst_point", "worst_reading"})
    if (auto v = offline::note(notes, key)) j[key] = *v;
  if (auto v = offline::note_number(notes, "worst_frame"); v && *v >= 0.0 && *v <= 4294967295.0 && *v == std::floor(*v))
    j["worst_frame"] = uint32_t(*v);  // notes come from the file: only a frame number is taken as one
  return j;
}

}  // namespace

nlohmann::json bvh_info(const std::string& file, uint64_t bytes, const offline::Motion& motion) {
  nlohmann::json j = {{"file", file}, {"format", "bvh"}, {"bytes", bytes}};
  j.update(skeleton_json(motion.skeleton));
  j["frames"] = motion.frame_count;
  j["frame_time"] = motion.frame_time;
  return j;
}

namespace {

// The notes as an object, key -> value: a value that is a whole finite number (max_error=0.013,
// rounds=21) as a number, any other as its text (tolerance=0.05%, worst_point=...).
nlohmann::json notes_json(const std::string& notes) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [key, value] : offline::note_lines(notes)) {
    int64_t whole = 0;
    const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), whole);
    if (ec == std::errc() && end == value.data() + value.size() && !value.empty()) {
      out[key] = whole;
      continue;
    }
    const std::string line = key + "=" + value;
    const std::optional<double> number = offline::note_number(line, key);
    out[key] = number ? nlohmann::json(*number) : nlohmann::json(value);
  }
  return out;
}

}  // namespace

nlohmann::json kanim_info(const std::string& file, uint64_t bytes, const Clip& clip) {
  nlohmann::json j = {{"file", file},
                      {"format", "kanim"},
                      {"version", std::to_string(clip.version_major()) + "." + std::to_string(clip.version_minor())},
                      {"profile", clip.runtime_profile() ? "runtime" : "archive"},  // spec section 9
                      {"bytes", bytes},
                      {"checksum", "ok"}};
  j.update(skeleton_json(clip.skeleton()));
  j["frames"] = clip.frame_count();
  j["frame_time"] = clip.frame_time();
  j["tangent_rule"] = clip.tangent_rule() == TangentRule::step_adjusted ? "step_adjusted" : "uniform";
  std::vector<uint32_t> keys;
  uint32_t zero = 0, constant = 0, linear = 0;
  float t_min = 1.0f, t_max = -1.0f;
  double t_sum = 0.0;
  uint32_t curved = 0;
  for (uint32_t c = 0; c < clip.channel_count(); ++c) {
    const ChannelInfo t = clip.channel(c);
    keys.push_back(t.key_count);
    zero += t.key_count == 0;
    constant += t.key_count == 1;
    if (t.key_count < 2) continue;
    if (t.interp == Interpolation::linear) { ++linear; continue; }
    const float tension = t.tension;
    t_min = std::min(t_min, tension), t_max = std::max(t_max, tension), t_sum += tension, ++curved;
  }
  std::sort(keys.begin(), keys.end());
  j["keys"] = {{"total", clip.total_keys()},
               {"per_channel_min", keys.empty() ? 0 : keys.front()},
               {"per_channel_median", keys.empty() ? 0 : keys[keys.size() / 2]},
               {"per_channel_max", keys.empty() ? 0 : keys.back()},
               {"zero_channels", zero},
               {"constant_channels", constant},
               {"linear_channels", linear},
               {"cardinal_channels", curved}};
  if (curved) j["tension"] = {{"min", t_min}, {"mean", t_sum / curved}, {"max", t_max}};
  j["raw_f32_bytes"] = uint64_t(4) * clip.frame_count() * clip.channel_count();
  j["memory_bytes"] = clip.memory_bytes();
  j["skeleton_bytes"] = clip.skeleton_bytes();  // once per rig in an engine
  j["animation_bytes"] = clip.animation_bytes();
  char hash[19];  // a string: JSON readers keep 53 bits of a number
  std::snprintf(hash, sizeof hash, "0x%016llx", static_cast<unsigned long long>(clip.rig_hash()));
  j["rig_hash"] = hash;  // equal for clips of one rig (Clip::rig_hash)
  j["encoder_notes"] = clip.encoder_notes();
  j["notes"] = notes_json(clip.encoder_notes());
  if (nlohmann::json noted = guarantee_json(clip.encoder_notes()); !noted.empty()) j["guarantee"] = noted;
  return j;
}

}  // namespace keyanim::offline
