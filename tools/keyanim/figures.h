// The method's figures as SVG text, apart from the command line so that tests can call them:
// one channel's original curve against its reconstruction with the keys marked (`plot`), and
// one frame of a skeleton as a stick figure, front and side view, optionally two overlaid
// (`render`).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "conventions.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/motion.h"

namespace keyanim::cli {

// Channel column of "JOINT:CHANNEL" (CHANNEL one of Xposition..Zrotation). On failure returns
// nothing and says why in `error` (unknown joint, unknown channel name, channel not present).
std::optional<uint32_t> find_channel(const Skeleton& skeleton, const std::string& spec, std::string& error);

// "error <= 0.05% (0.031 units)", "curvature", "uniform:10", "manual (3 frames)", plus
// ", tension fit" or ", tension T" when not 0.
std::string settings_text(const offline::EncodeSettings& settings, double tolerance_units);

struct ChannelPlot {
  std::string svg;
  uint32_t key_count = 0;          // keys of the channel in the frame range, one marker (class "key") each
  uint32_t channel_keys = 0;       // keys of the channel in the whole clip
  double max_channel_error = 0.0;  // degrees (modulo 360) or file units, at the source frames
  double tolerance_units = 0.0;    // the encoder's tolerance in file length units
  // What this channel's reconstruction alone does in world space (issue 28, item 16): the
  // largest distance any joint, End Site or shell point moves when only this channel is
  // replaced by its reconstruction, where and when (a flat curve that reads as a bias is then
  // seen to be within the tolerance, or not).
  double channel_world_error = 0.0;
  std::string channel_world_point;
  uint32_t channel_world_frame = 0;
};

// Frames first..last, inclusive; `last` is clamped to the clip.
struct FrameRange {
  uint32_t first = 0;
  uint32_t last = UINT32_MAX;
};

// Encodes the whole of `motion` with `settings`, samples the decoder's curve of `channel` at
// every frame of `range` (and between frames when a frame is at least 6 px wide) and draws it
// over the original (a rotation's original unwrapped, the reconstruction shifted by a multiple
// of 360 degrees to start beside it). Every key in the range is a dot on the reconstruction.
// A subtitle line gives the world-space error this channel's reconstruction alone causes,
// against the tolerance.
// `file_label` names the input in the title. Returns false with `error` set if the encoder
// refuses the motion or settings, or the range holds no frame.
bool plot_channel(const offline::Motion& motion, const offline::EncodeSettings& settings, uint32_t channel,
                  const std::string& file_label, ChannelPlot& out, std::string& error, FrameRange range = {});

struct PoseSeries {
  const offline::Motion* motion = nullptr;
  std::string label;  // legend text
};

struct PoseFigure {
  std::string svg;
  // With two series: the node farthest apart between them and that distance (file units).
  uint32_t worst_node = 0;
  double worst_distance = 0.0;
};

// Frame `frame` of one or two motions with the same skeleton (the caller checks both), front
// view and side view at one scale with equal aspect ratio, `up` upwards: x-y and z-y for y-up,
// x-z and y-z for z-up. Bones join every node to its parent (End Sites included); joints are
// dots. With two series the worst node is circled and labelled with its name and distance.
// `title` heads the figure. Poses by forward kinematics under `reading` (keyanim/pose.h).
PoseFigure render_pose(const std::vector<PoseSeries>& series, uint32_t frame, const std::string& title,
                       PositionReading reading = PositionReading::replace, UpAxis up = UpAxis::y);

// True when the two skeletons have the same nodes (count, parents, End Site flags, names) and
// channel layout, so that their poses can be compared node by node.
bool same_skeleton(const Skeleton& a, const Skeleton& b);

}  // namespace keyanim::cli
