// The clip's channels as curves for the glTF export: values as the decoder computes them,
// one-sided slopes from the Cardinal segments' Hermite form (spec/FORMAT.md, appendix A), a
// joint's translation mapped exactly onto one glTF sampler, and a joint's Euler curves as a
// quaternion curve with its time derivative.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "gltf_model.h"
#include "keyanim/clip.h"

namespace keyanim::offline::gltf {

// One channel of a clip (the clip must outlive it).
class ChannelCurve {
 public:
  ChannelCurve(const Clip& clip, uint32_t channel);
  // The decoder's value at a frame position (Clip::sample_channel: bit for bit).
  float value(double frame_position) const noexcept;
  // d value / d frame just before (from_left) or just after source frame f: the derivative of
  // the Hermite segment on that side, 0 where the curve is clamped (before the first key,
  // after the last). Binary64 arithmetic on the segment's binary32 operands.
  double slope(uint32_t f, bool from_left) const noexcept;
  const std::vector<uint32_t>& key_frames() const noexcept { return frames_; }
  // Straight between its keys: linear interpolation, or fewer than two keys.
  bool piecewise_linear() const noexcept { return interp_ == Interpolation::linear || frames_.size() < 2; }
  // Equal to v at every frame: every key is v (a channel without keys is 0).
  bool constant_at(double v) const noexcept;

 private:
  const Clip* clip_;
  uint32_t channel_;
  Interpolation interp_;
  float s_;
  TangentRule rule_;
  std::vector<uint32_t> frames_;
  std::vector<float> values_;
};

// The curves of one node, indexes into a vector of ChannelCurve (one per clip channel).
struct NodeCurves {
  std::array<int32_t, 3> translation{-1, -1, -1};  // channel per axis, -1: OFFSET component
  std::array<double, 3> offset{};
  std::vector<std::array<int32_t, 2>> rotation;    // (axis, channel) in CHANNELS order
};
NodeCurves node_curves(const Joint& joint);

// The node's translation never leaves its OFFSET / its rotation is always the identity.
bool translation_at_rest(const NodeCurves& node, const std::vector<ChannelCurve>& curves);
bool rotation_at_rest(const NodeCurves& node, const std::vector<ChannelCurve>& curves);

// The node's translation at a frame position: its channels' values, its OFFSET elsewhere
// (float32, as samplers store it).
std::array<float, 3> translation_at(const NodeCurves& node, const std::vector<ChannelCurve>& curves,
                                    double frame_position);

// The exact translation sampler over the window: keys at the window's ends and at every key of
// every axis inside it; CUBICSPLINE with one-sided tangents, or LINEAR when every axis is
// piecewise linear.
Sampler translation_sampler(const NodeCurves& node, const std::vector<ChannelCurve>& curves, const Window& window);

// LINEAR samplers with keys at `times` (seconds, player time) = frame positions `positions`.
Sampler resampled_translation(const NodeCurves& node, const std::vector<ChannelCurve>& curves,
                              const std::vector<double>& positions, const std::vector<double>& times);
Sampler resampled_rotation(const NodeCurves& node, const std::vector<ChannelCurve>& curves,
                           const std::vector<double>& positions, const std::vector<double>& times);

// The node's local rotation at a frame position, and its derivative per second just before
// (from_left) or after source frame f. Unit quaternions, sign as the Euler product gives it.
Quat rotation_at(const NodeCurves& node, const std::vector<ChannelCurve>& curves, double frame_position);
Quat rotation_rate(const NodeCurves& node, const std::vector<ChannelCurve>& curves, uint32_t f, bool from_left,
                   double frame_time);

}  // namespace keyanim::offline::gltf
