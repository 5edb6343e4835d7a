#include "keyanim/skeleton.h"

namespace keyanim {

const char* channel_name(ChannelType t) noexcept {
  switch (t) {
    case ChannelType::x_position: return "Xposition";
    case ChannelType::y_position: return "Yposition";
    case ChannelType::z_position: return "Zposition";
    case ChannelType::x_rotation: return "Xrotation";
    case ChannelType::y_rotation: return "Yrotation";
    case ChannelType::z_rotation: return "Zrotation";
  }
  return "?";
}

uint32_t Skeleton::channel_count() const noexcept {
  size_t n = 0;
  for (const Joint& j : joints) n += j.channels.size();
  return static_cast<uint32_t>(n);
}

uint32_t Skeleton::assign_channel_columns() noexcept {
  uint32_t next = 0;
  for (Joint& j : joints) {
    j.first_channel = next;
    next += static_cast<uint32_t>(j.channels.size());
  }
  return next;
}

uint32_t Skeleton::joint_of_channel(uint32_t c) const noexcept {
  for (uint32_t i = 0; i < joints.size(); ++i) {
    const Joint& j = joints[i];
    if (c >= j.first_channel && c < j.first_channel + j.channels.size()) return i;
  }
  return static_cast<uint32_t>(joints.size());
}

}  // namespace keyanim
