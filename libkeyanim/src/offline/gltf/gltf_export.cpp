// export_gltf (keyanim/offline/gltf.h): options and the frame window, translations mapped,
// rotations fitted or resampled, the result checked and written.
#include <cfloat>
#include <cmath>
#include <functional>
#include <sstream>

#include "gltf_curves.h"
#include "gltf_fit.h"
#include "gltf_skin.h"
#include "gltf_verify.h"
#include "gltf_writer.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/gltf.h"
#include "keyanim/offline/metrics.h"
#include "keyanim/offline/notes.h"
#include "keyanim/offline/number_text.h"

namespace keyanim::offline {
namespace {

using namespace gltf;

constexpr double kDefaultTolerancePercent = 0.05;  // the encoder's default
// Working memory (per frame of the window: reference points, rotation targets) and output
// keys beyond these are refused rather than allocated.
constexpr double kMaxWorkingBytes = double(1u << 30);
constexpr double kMaxResampledKeys = double(1u << 24);
constexpr double kRoundingMargin = 1e-6;  // of the skeleton size

[[noreturn]] void invalid(const std::string& why) { throw Error(ErrorKind::invalid_argument, why); }

// glTF key times are float32 seconds and must increase strictly (glTF 2.0, 3.11: an animation
// sampler's input). A frame time too large overflows float32 (1e308 s: every frame after the
// first at infinity), one too small rounds neighbours to one time; either is said as the cause
// here, before a fit that could only fail for it. `time(i)` is key i's time in seconds and
// `name` how a message calls key i ("frame 12", "key 3").
void check_key_times(size_t count, const std::function<double(size_t)>& time,
                     const std::function<std::string(size_t)>& name, double frame_time) {
  const std::string source = " (the clip's frame time is " + general_text(frame_time, 9) + " s)";
  float previous = 0.0f;
  for (size_t i = 0; i < count; ++i) {
    const double t = time(i);
    const float f = float(t);
    if (!std::isfinite(f))
      throw Error(ErrorKind::limit, "glTF holds key times as float32 seconds: " + name(i) + " is at " + general_text(t) +
                                        " s, beyond float32's largest, " + general_text(FLT_MAX) + source);
    if (i > 0 && !(f > previous))
      throw Error(ErrorKind::limit, "glTF holds key times as float32 seconds, which must increase: " + name(i - 1) +
                                        " and " + name(i) + " (at " + general_text(time(i - 1), 9) + " and " +
                                        general_text(t, 9) + " s) are the same float32 time" + source);
    previous = f;
  }
}

// The frame window of the options; throws Error (invalid_argument) for options that make no
// sense, and (limit) for frame times glTF cannot hold (check_key_times).
Window check_options(const Clip& clip, const GltfOptions& o) {
  if (!(o.fps >= 0.0) || !std::isfinite(o.fps)) invalid("fps must be positive and finite");
  if (!(o.tolerance >= 0.0) || !std::isfinite(o.tolerance) || (o.tolerance_in_percent && o.tolerance > 100.0))
    invalid("tolerance must be positive and finite (at most 100 in percent)");
  if (!std::isfinite(o.shell_percent)) invalid("shell distance must be finite");
  Window w;
  const uint32_t frames = clip.frame_count();
  if (frames == 0) {
    if (o.first_frame != 0 || o.last_frame != UINT32_MAX) invalid("the clip has no frames");
    return w;
  }
  w.first = o.first_frame;
  w.last = o.last_frame == UINT32_MAX ? frames - 1 : o.last_frame;
  w.frame_time = clip.frame_time();
  if (w.first > w.last || w.last >= frames)
    invalid("frame range " + std::to_string(w.first) + ":" + std::to_string(w.last) + " is not within 0:" +
            std::to_string(frames - 1));
  if (w.last > w.first && !(w.frame_time > 0.0)) invalid("the clip's frame time is not positive");
  if (o.fps == 0.0)  // the keys are the frames (with --fps, resample_positions checks its keys)
    check_key_times(
        w.frames(), [&](size_t i) { return w.time(w.first + uint32_t(i)); },
        [&](size_t i) { return "frame " + std::to_string(w.first + i); }, w.frame_time);
  return w;
}

// Frame positions and player times of the --fps keys: decode_motion's frames at that rate
// (decode.h's RateMap), and the range's end.
void resample_positions(const Window& w, double fps, std::vector<double>& positions, std::vector<double>& times) {
  const double duration = double(w.last - w.first) * w.frame_time;
  const RateMap rate = rate_map(w.last - w.first, w.frame_time, fps);
  if (!(double(rate.count) <= kMaxResampledKeys))
    throw Error(ErrorKind::limit, "--fps " + json_number(fps) + " over " + json_number(duration) + " s makes too many keys");
  for (uint32_t i = 0; i < uint32_t(rate.count); ++i) {
    // A rate snapped to the clip's own (or a multiple or divisor) keeps the source timeline, so
    // that its last key lands on the range's end.
    times.push_back(rate.per || rate.every ? rate.position(i) * w.frame_time : double(i) / fps);
    positions.push_back(double(w.first) + rate.position(i));
  }
  // Unlike BVH frames, glTF keys need not be evenly spaced: a last key at the range's end keeps
  // the animation as long as the clip.
  if (float(times.back()) < float(duration)) {
    times.push_back(duration);
    positions.push_back(double(w.last));
  }
  check_key_times(
      times.size(), [&](size_t i) { return times[i]; }, [](size_t i) { return "key " + std::to_string(i); },
      w.frame_time);
}

// What percentages are of, as the encoder measures it (encode.h's reference_size): a
// skeleton without extent (a lone root) falls back to the box its nodes sweep over the clip.
double reference_size(const Clip& clip) {
  const double size = skeleton_size(clip.skeleton());
  const double decoded_bytes = double(clip.frame_count()) * double(clip.channel_count()) * sizeof(double);
  if (size > 0.0 || !(decoded_bytes <= kMaxWorkingBytes)) return size;
  return offline::reference_size(decode_motion(clip));
}

// The source's frame rate and the exported range, as "key":value pairs: glTF keeps only seconds,
// and importers that count frames (Blender) need the rate to land keys on the source frames.
std::string timing_members(const Clip& clip, const Window& w) {
  const uint32_t frames = clip.frame_count() == 0 ? 0 : w.frames();
  std::string o = "\"source_frame_time\":" + json_number(clip.frame_time());
  if (clip.frame_time() > 0.0) o += ",\"fps\":" + json_number(1.0 / clip.frame_time());
  o += ",\"frame_count\":" + std::to_string(frames);
  if (frames > 0) o += ",\"first_frame\":" + std::to_string(w.first) + ",\"last_frame\":" + std::to_string(w.last);
  return o;
}

// asset.extras: what the fit reached and the timing; `resample_fps` the --fps option (0: none).
std::string extras(const GltfReport& r, const std::string& timing, double resample_fps) {
  std::string o = "{\"keyanim\":{\"tolerance\":" + json_number(r.tolerance) +
                  ",\"shell_distance\":" + json_number(r.shell_distance) + ",\"max_error\":" + json_number(r.max_error) +
                  "," + timing;
  if (resample_fps > 0.0) o += ",\"resample_fps\":" + json_number(resample_fps);
  return o + "}}";
}

// The tolerance in length units: the option, else the clip's own, else the encoder's default.
double tolerance_units(const Clip& clip, const GltfOptions& o, double size) {
  double tol = o.tolerance_in_percent ? o.tolerance / 100.0 * size : o.tolerance;
  if (!(tol > 0.0)) tol = note_number(clip.encoder_notes(), "tolerance_units").value_or(0.0);
  if (!(tol > 0.0)) tol = kDefaultTolerancePercent / 100.0 * size;
  return tol;
}

// The shell distance in length units: the option, else the clip's own, else the default.
double shell_units(const Clip& clip, const GltfOptions& o, double size) {
  if (o.shell_percent >= 0.0) return o.shell_percent / 100.0 * size;
  const double noted = note_number(clip.encoder_notes(), "shell_units").value_or(-1.0);
  return noted >= 0.0 ? noted : kDefaultShellPercent / 100.0 * size;
}

// The animation: resampled (--fps) or exact translations and fitted keys; then what a player
// reaches against the clip.
void animate(const Clip& clip, const GltfOptions& options, const Window& w, double size, Model& model,
             GltfReport& report) {
  const Skeleton& sk = model.skeleton;
  std::vector<ChannelCurve> curves;
  for (uint32_t c = 0; c < clip.channel_count(); ++c) curves.emplace_back(clip, c);
  std::vector<NodeCurves> nodes;
  for (const Joint& j : sk.joints) nodes.push_back(node_curves(j));
  const Reference reference(sk, curves, w, report.shell_distance);
  if (options.fps > 0.0) {
    std::vector<double> positions, times;
    resample_positions(w, options.fps, positions, times);
    for (size_t j = 0; j < sk.joints.size(); ++j) {
      if (!translation_at_rest(nodes[j], curves))
        model.nodes[j].translation = resampled_translation(nodes[j], curves, positions, times);
      if (!nodes[j].rotation.empty() && !rotation_at_rest(nodes[j], curves))
        model.nodes[j].rotation = resampled_rotation(nodes[j], curves, positions, times);
    }
  } else {
    if (!options.linear_only)
      for (size_t j = 0; j < sk.joints.size(); ++j)
        if (!translation_at_rest(nodes[j], curves)) model.nodes[j].translation = translation_sampler(nodes[j], curves, w);
    const double fit_tol = report.tolerance - kRoundingMargin * size;
    report.rounds = fit_keys(model, nodes, curves, reference, fit_tol, options.linear_only, options.progress);
  }
  // Every export carries one animation spanning the range, even if nothing moves.
  bool animated = false;
  for (const NodeAnimation& n : model.nodes) animated = animated || n.translation || n.rotation;
  if (!animated && !sk.joints.empty()) model.nodes[0].translation = translation_sampler(nodes[0], curves, w);

  const CheckResult check = check_model(model, reference, report.tolerance, [&](double f) {
    if (options.progress) options.progress(EncodeStage::measuring, f);
  });
  report.max_error = check.max_error;
  report.worst_node = reference.owner(check.worst_point);
  report.worst_axis = reference.moved_by_owner(check.worst_point) ? int(check.worst_point - report.nodes) % 3 : -1;
  report.worst_frame = w.first + check.worst_frame_index;
}

void count_tracks(const Model& model, GltfReport& report) {
  for (const NodeAnimation& n : model.nodes) {
    if (n.translation) ++report.translation_tracks, report.translation_keys += uint32_t(n.translation->key_count());
    if (n.rotation) {
      ++(n.rotation->interp == Interp::cubic ? report.cubic_rotation_tracks : report.linear_rotation_tracks);
      report.rotation_keys += uint32_t(n.rotation->key_count());
    }
  }
}

}  // namespace

GltfOutput export_gltf(const Clip& clip, const GltfOptions& options) {
  GltfOutput out;
  GltfReport& report = out.report;
  const Window w = check_options(clip, options);
  Model model;
  model.skeleton = clip.skeleton();
  model.animation_name = options.name;
  model.nodes.resize(model.skeleton.joints.size());
  report.nodes = uint32_t(model.nodes.size());
  // Per frame and node of the window: reference points, fit targets.
  const double working = double(w.frames()) * double(report.nodes) * (4 * sizeof(Vec3) + 96);
  if (!(working <= kMaxWorkingBytes))
    throw Error(ErrorKind::limit, "the clip is too long for one glTF export (" + std::to_string(w.frames()) +
                                      " frames of " + std::to_string(report.nodes) + " nodes): export it in frame ranges");
  const double size = reference_size(clip);
  report.tolerance = tolerance_units(clip, options, size);
  report.shell_distance = shell_units(clip, options, size);
  // Players differ in rounding (float32 or binary64 arithmetic, normalising slerp's result or
  // not): the fit keeps a margin of a few float32 ulps of the skeleton's extent.
  if (clip.frame_count() > 0 && options.fps == 0.0 && !(report.tolerance > kRoundingMargin * size)) {
    if (report.tolerance > 0.0)
      throw Error(ErrorKind::limit, "float32 glTF keys cannot hold the tolerance " + json_number(report.tolerance) +
                                        ": rounding alone reaches " + json_number(kRoundingMargin * size) +
                                        " (use a larger --error)");
    invalid("the tolerance is 0 (the skeleton has no extent): give one in length units with --error");
  }
  if (clip.frame_count() > 0) animate(clip, options, w, size, model, report);
  count_tracks(model, report);
  const std::string timing = timing_members(clip, w);
  model.extras_json = extras(report, timing, options.fps);
  model.timing_json = "{\"keyanim\":{" + timing + "}}";
  model.skin = make_skin(model.skeleton);
  if (!options.bone_mesh) model.skin.positions.clear(), model.skin.joints.clear(), model.skin.indices.clear();
  if (options.bin_uri.empty()) out.main = write_glb(model);
  else write_gltf(model, options.bin_uri, out.main, out.bin);
  if (out.main.size() + out.bin.size() >= (uint64_t(1) << 32))  // GLB and glTF lengths are u32
    throw Error(ErrorKind::limit, "the glTF asset would exceed 4 GiB: export it in frame ranges");
  return out;
}

}  // namespace keyanim::offline
