// The keys an image holds (spec/FORMAT.md section 9.3, "The keys of a curve"), as the integers
// a file stores: for the runtime profile's content check (rebuild and compare) and for
// converting a runtime-profile clip back to the archive profile.
#include <cmath>
#include <cstring>
#include <limits>

#include "internal/quat_layout.h"
#include "runtime/image.h"

namespace keyanim::internal {
namespace {

// A single key's value as q x step, exactly: the image keeps only the value of a channel's
// single key, and any (q, step) that dequantizes to it bit for bit is that key.
void single_key(float v, int64_t& q, double& step) noexcept {
  if (v == 0.0f) {
    q = std::signbit(v) ? -1 : 0;  // -0.0: -1 x the smallest step rounds to -0.0
    step = std::signbit(v) ? std::numeric_limits<double>::denorm_min() : 1.0;
    return;
  }
  q = v > 0.0f ? 1 : -1;
  step = std::fabs(static_cast<double>(v));
}

void block_curve_keys(const Image& img, uint32_t curve, ClipSource& out) {
  const Curve& cv = img.curves[curve];
  for (uint32_t b = 0; b < img.block_count; ++b) {
    CurveFields f;
    const uint8_t* rec = curve_record(img, b, curve, f);
    const int64_t low = cv.q_base + static_cast<int64_t>(read_bits(rec, f.base_at, cv.base_bits));
    uint64_t at = f.values_at + 2ull * f.value_bits;  // Values[2]: the block's first key
    for (uint64_t mask = f.mask; mask != 0; mask &= mask - 1, at += f.value_bits) {
      out.frames.push_back((b << kBlockShift) + static_cast<uint32_t>(low_bit(mask)));
      out.q.push_back(low + static_cast<int64_t>(read_bits(rec, at, f.value_bits)));
    }
  }
}

}  // namespace

ClipSource image_keys(const Image& img) {
  ClipSource src;
  src.version_major = img.version_major;
  src.version_minor = img.version_minor;
  src.frame_count = img.frame_count;
  src.frame_time = img.frame_time;
  src.rule = img.rule;
  src.skeleton = img.rig->skeleton;
  src.notes = img.notes;
  src.quat_nodes.resize(img.quat_node.size());  // in node order, as QUAT lists them
  for (uint32_t i = 0; i < src.quat_nodes.size(); ++i) {
    const uint32_t j = quat_in_node_order(img, i);
    src.quat_nodes[i].node = img.quat_node[j];
    float ref[4];
    for (size_t k = 0; k < 4; ++k) ref[k] = img.quat_reference[k * img.quat_lanes + j];
    reference_from_floats(ref, src.quat_nodes[i]);  // checked when the image was
  }
  src.channels.resize(img.interp.size());
  src.frames.reserve(static_cast<size_t>(img.total_keys));
  src.q.reserve(static_cast<size_t>(img.total_keys));
  for (size_t c = 0; c < img.interp.size(); ++c) {
    SourceChannel& sc = src.channels[c];
    sc.interp = img.interp[c];
    sc.tension = img.tension[c];
    sc.first_key = src.frames.size();
    sc.key_count = img.key_count[c];
    const uint32_t curve = img.curve_of[c];
    if (curve == kNoCurve) {
      if (sc.key_count == 1) {
        int64_t q;
        single_key(img.fixed_value[c], q, sc.step);
        src.frames.push_back(img.fixed_frame[c]);
        src.q.push_back(q);
      }
      continue;
    }
    sc.step = img.curves[curve].step;
    if (curve < img.block_curves) {
      block_curve_keys(img, curve, src);
    } else {
      const ListSpan list = img.lists[curve - img.block_curves];
      src.frames.insert(src.frames.end(), img.list_frames.begin() + list.first, img.list_frames.begin() + list.first + list.count);
      src.q.insert(src.q.end(), img.list_q.begin() + list.first, img.list_q.begin() + list.first + list.count);
    }
  }
  return src;
}

}  // namespace keyanim::internal
