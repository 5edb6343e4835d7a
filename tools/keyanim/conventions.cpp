#include "conventions.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "keyanim/offline/fk.h"

namespace keyanim::cli {

namespace {
constexpr double kAmbiguousRatio = 1.5;  // as viewer/src/upaxis.js's AMBIGUOUS_RATIO
}  // namespace

UpGuess detect_up_axis(const Skeleton& skeleton) {
  // The rest pose: every Offset, no channel (what offline::skeleton_size measures).
  std::vector<std::array<double, 3>> p(skeleton.joints.size());
  std::array<double, 3> lo, hi;
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < skeleton.joints.size(); ++i) {
    const Joint& j = skeleton.joints[i];
    for (int a = 0; a < 3; ++a) {
      const int32_t parent = j.parent;
      p[i][a] = j.offset[a] + (parent >= 0 && size_t(parent) < i ? p[size_t(parent)][a] : 0.0);
      lo[a] = std::min(lo[a], p[i][a]), hi[a] = std::max(hi[a], p[i][a]);
    }
  }
  UpGuess g;
  for (int a = 0; a < 3; ++a) g.extents[size_t(a)] = hi[a] >= lo[a] && std::isfinite(hi[a] - lo[a]) ? hi[a] - lo[a] : 0.0;
  const double y = g.extents[1], z = g.extents[2];
  g.ambiguous = !(y > kAmbiguousRatio * z || z > kAmbiguousRatio * y);
  g.axis = !g.ambiguous && z > y ? UpAxis::z : UpAxis::y;
  return g;
}

RigidBones rigid_bones(const offline::Motion& motion, uint32_t frame) {
  RigidBones out;
  if (frame >= motion.frame_count) return out;
  const double* row = motion.frame(frame);
  for (const Joint& j : motion.skeleton.joints) {
    if (j.parent < 0) continue;
    std::array<double, 3> replaced = j.offset, added = j.offset;
    bool positions = false;
    for (size_t k = 0; k < j.channels.size(); ++k) {
      if (is_rotation(j.channels[k])) continue;
      const size_t axis = static_cast<size_t>(j.channels[k]);
      const double v = row[j.first_channel + k];
      replaced[axis] = v, added[axis] = j.offset[axis] + v, positions = true;
    }
    const double length = std::hypot(j.offset[0], j.offset[1], j.offset[2]);
    if (!positions || !(length > 0.0)) continue;
    ++out.nodes;
    auto kept = [&](const std::array<double, 3>& t) { return std::abs(std::hypot(t[0], t[1], t[2]) - length) <= 0.05 * length; };
    out.kept[size_t(PositionReading::replace)] += kept(replaced);
    out.kept[size_t(PositionReading::add)] += kept(added);
  }
  return out;
}

std::optional<PositionReading> rigid_reading(const offline::Motion& motion, uint32_t frame) {
  const RigidBones b = rigid_bones(motion, frame);
  const uint32_t r = b.kept[size_t(PositionReading::replace)], a = b.kept[size_t(PositionReading::add)];
  if (2 * r >= b.nodes && r > 3 * a && r > 0) return PositionReading::replace;
  if (2 * a >= b.nodes && a > 3 * r && a > 0) return PositionReading::add;
  return std::nullopt;
}

}  // namespace keyanim::cli
