// The skeleton: joints, End Sites and the channel layout of a frame. Shared by the runtime
// (a loaded .kanim carries it) and by the offline tools (BVH reading and writing).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace keyanim {

// The six BVH channel names. Values are stored in .kanim files: append-only.
enum class ChannelType : uint8_t {
  x_position = 0,
  y_position = 1,
  z_position = 2,
  x_rotation = 3,
  y_rotation = 4,
  z_rotation = 5,
};

inline bool is_rotation(ChannelType t) noexcept { return static_cast<uint8_t>(t) >= 3; }
// 0, 1 or 2 for X, Y or Z.
inline int channel_axis(ChannelType t) noexcept { return static_cast<uint8_t>(t) % 3; }
// "Xposition" ... "Zrotation", as BVH spells them.
const char* channel_name(ChannelType t) noexcept;

// One node of the hierarchy: a ROOT, a JOINT or an End Site. Nodes are stored parents first
// (parent < own index), in the order they appear in the BVH file.
struct Joint {
  std::string name;                 // exact bytes after ROOT/JOINT (or after "End Site", usually empty)
  int32_t parent = -1;              // -1 for a root
  std::array<double, 3> offset{};   // OFFSET, bit-exact as read
  std::vector<ChannelType> channels;  // in CHANNELS order; always empty for an End Site
  bool end_site = false;
  uint32_t first_channel = 0;       // column of channels[0] in a frame row
};

struct Skeleton {
  std::vector<Joint> joints;

  // Number of values in one frame (sum of every joint's channel count).
  uint32_t channel_count() const noexcept;
  // Recomputes first_channel of every joint from the channel lists; returns channel_count().
  uint32_t assign_channel_columns() noexcept;
  // The joint that owns frame column c, and which of its channels it is.
  uint32_t joint_of_channel(uint32_t c) const noexcept;
};

}  // namespace keyanim
