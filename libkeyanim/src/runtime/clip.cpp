// Clip and Cursor: the public face of the runtime image (image.h), its sampler (sampler.h) and
// poses (pose.h).
#include "keyanim/clip.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>
#include <vector>

#include "internal/quat_layout.h"
#include "internal/simd.h"
#include "runtime/clip_access.h"
#include "runtime/cursor_state.h"
#include "runtime/pose.h"
#include "runtime/quat_tracks.h"
#include "runtime/sampler.h"

namespace keyanim {

using internal::Image;

namespace {

// An empty clip's image, with an empty rig that nothing allocates (an aliasing pointer with no
// owner): the accessors below never throw.
const Image& empty_image() {
  static const Image* const kEmpty = [] {  // made in place: neither an Image nor a Rig is copied
    static internal::Rig r;
    r.hash = internal::rig_hash(r.skeleton);
    static Image i;
    i.rig = std::shared_ptr<const internal::Rig>(std::shared_ptr<const internal::Rig>(), &r);
    i.euler = &r.euler;
    return &i;
  }();
  return *kEmpty;
}

}  // namespace

Clip ClipAccess::make(std::shared_ptr<const Image> image) {
  Clip c;
  c.image_ = std::move(image);
  return c;
}

const Image& ClipAccess::image(const Clip& clip) { return clip.image_ ? *clip.image_ : empty_image(); }

Clip::Clip() = default;
Clip::~Clip() = default;
Clip::Clip(const Clip&) = default;
Clip& Clip::operator=(const Clip&) = default;
Clip::Clip(Clip&&) noexcept = default;
Clip& Clip::operator=(Clip&&) noexcept = default;

#define KEYANIM_IMG (image_ ? *image_ : empty_image())

uint16_t Clip::version_major() const noexcept { return KEYANIM_IMG.version_major; }
bool Clip::runtime_profile() const noexcept { return KEYANIM_IMG.runtime_profile; }
uint16_t Clip::version_minor() const noexcept { return KEYANIM_IMG.version_minor; }
uint32_t Clip::frame_count() const noexcept { return KEYANIM_IMG.frame_count; }
double Clip::frame_time() const noexcept { return KEYANIM_IMG.frame_time; }
uint32_t Clip::channel_count() const noexcept { return static_cast<uint32_t>(KEYANIM_IMG.interp.size()); }
TangentRule Clip::tangent_rule() const noexcept { return KEYANIM_IMG.rule; }
const Skeleton& Clip::skeleton() const noexcept { return KEYANIM_IMG.rig->skeleton; }
uint64_t Clip::total_keys() const noexcept { return KEYANIM_IMG.total_keys; }
const std::string& Clip::encoder_notes() const noexcept { return KEYANIM_IMG.notes; }
size_t Clip::memory_bytes() const noexcept { return image_ ? image_->memory_bytes() : 0; }
size_t Clip::skeleton_bytes() const noexcept { return image_ ? image_->skeleton_bytes() : 0; }
size_t Clip::animation_bytes() const noexcept { return image_ ? image_->animation_bytes() : 0; }
uint64_t Clip::rig_hash() const noexcept { return KEYANIM_IMG.rig->hash; }
bool Clip::shares_rig(const Clip& other) const noexcept { return KEYANIM_IMG.rig == ClipAccess::image(other).rig; }

double Clip::duration() const noexcept {
  const Image& img = KEYANIM_IMG;
  return img.frame_count == 0 ? 0.0 : static_cast<double>(img.frame_count - 1) * img.frame_time;
}

namespace {

// The quaternion node (index into the image's) whose rotation channels hold channel c, and
// which of them c is (0 x, 1 y, 2 z); false for a channel of its own values. The image lists
// the quaternion tracks, then the other quaternion nodes, each group in node order (so in
// column order): a search in each.
bool quat_of_channel(const Image& img, uint32_t c, uint32_t& quat, uint32_t& component) noexcept {
  const uint32_t* col = img.quat_column.data();
  const uint32_t groups[3] = {0, img.quat_tracks, static_cast<uint32_t>(img.quat_column.size())};
  for (int g = 0; g < 2; ++g) {
    const uint32_t* it = std::upper_bound(col + groups[g], col + groups[g + 1], c);
    if (it == col + groups[g] || c - *(it - 1) >= 3) continue;
    quat = static_cast<uint32_t>(it - col) - 1;
    component = c - *(it - 1);
    return true;
  }
  return false;
}

// Quaternion node i's Euler angles (degrees, its rotation channels' order) from its stored x,
// y, z: Appendix B, in binary64.
void quat_euler(const Image& img, uint32_t i, const float (&xyz)[3], float (&out)[3]) noexcept {
  QuatNode n;
  n.node = img.quat_node[i];
  // The image's reference floats are X x 2^-15 exactly (checked when it was made or loaded):
  // times 2^15 they are the integers themselves, without reference_from_floats' checks.
  for (uint32_t k = 0; k < 3; ++k)
    n.reference[k] = static_cast<int16_t>(img.quat_reference[k * img.quat_lanes + i] * (1.0f / float(kReferenceUnit)));
  double q[4], deg[3];
  stored_rotation(n, xyz[0], xyz[1], xyz[2], q);
  const Joint& j = img.rig->skeleton.joints[img.quat_node[i]];
  const uint32_t first = img.quat_column[i] - j.first_channel;
  const uint8_t axes[3] = {static_cast<uint8_t>(channel_axis(j.channels[first])),
                           static_cast<uint8_t>(channel_axis(j.channels[first + 1])),
                           static_cast<uint8_t>(channel_axis(j.channels[first + 2]))};
  euler_from_quaternion(q, axes, deg);
  for (int k = 0; k < 3; ++k) out[k] = static_cast<float>(deg[k]);
}

// Every quaternion node's rotation channels of a whole row of stored values, in place.
void euler_in_place(const Image& img, float* row) noexcept {
  for (uint32_t i = 0; i < img.quat_node.size(); ++i) {
    float* at = row + img.quat_column[i];
    const float xyz[3] = {at[0], at[1], at[2]};
    float deg[3];
    quat_euler(img, i, xyz, deg);
    std::copy(deg, deg + 3, at);
  }
}

// Channel c's value at f, given that it is component `component` of quaternion node `quat`.
float quat_channel(const Image& img, uint32_t quat, uint32_t component, float f) noexcept {
  const uint32_t column = img.quat_column[quat];
  const uint32_t columns[3] = {column, column + 1, column + 2};
  float xyz[3], deg[3];
  internal::sample_listed(img, f, columns, 3, xyz);
  quat_euler(img, quat, xyz, deg);
  return deg[component];
}

}  // namespace

ChannelInfo Clip::channel(uint32_t c) const noexcept {
  const Image& img = KEYANIM_IMG;
  if (c >= img.interp.size()) return {};
  uint32_t quat = 0, component = 0;
  const StoredAs stored = quat_of_channel(img, c, quat, component) ? static_cast<StoredAs>(component + 1) : StoredAs::value;
  return {img.interp[c], img.tension[c], img.key_count[c], stored};
}

uint32_t Clip::quat_node_count() const noexcept { return static_cast<uint32_t>(KEYANIM_IMG.quat_node.size()); }

QuatNode Clip::quat_node(uint32_t i) const noexcept {
  const Image& img = KEYANIM_IMG;
  QuatNode n;
  if (i >= img.quat_node.size()) return n;
  i = internal::quat_in_node_order(img, i);
  n.node = img.quat_node[i];
  float ref[4];
  for (uint32_t k = 0; k < 4; ++k) ref[k] = img.quat_reference[k * img.quat_lanes + i];
  internal::reference_from_floats(ref, n);
  return n;
}

Status Clip::channel_keys(uint32_t c, std::span<uint32_t> frames, std::span<float> values) const noexcept {
  const Image& img = KEYANIM_IMG;
  if (c >= img.interp.size()) return Status::invalid_argument;
  const uint32_t n = img.key_count[c];
  if (frames.size() < n || values.size() < n) return Status::output_too_small;
  if (n == 0) return Status::ok;
  const uint32_t curve = img.curve_of[c];
  if (curve == internal::kNoCurve) {
    frames[0] = img.fixed_frame[c];
    values[0] = img.fixed_value[c];
    return Status::ok;
  }
  const internal::Curve& cv = img.curves[curve];
  if (curve >= img.block_curves) {  // a list curve
    const internal::ListSpan list = img.lists[curve - img.block_curves];
    std::copy_n(img.list_frames.data() + list.first, n, frames.data());
    std::copy_n(img.list_values.data() + list.first, n, values.data());
    return Status::ok;
  }
  // Walk the records block by block: each lists its block's keys in its mask.
  uint32_t k = 0;
  for (uint32_t b = 0; b < img.block_count && k < n; ++b) {
    internal::CurveFields f;
    const uint8_t* rec = internal::curve_record(img, b, curve, f);
    const uint64_t base = internal::read_bits(rec, f.base_at, cv.base_bits);
    uint64_t at = f.values_at + 2ull * f.value_bits;  // the block's first key follows two context keys
    for (uint64_t mask = f.mask; mask != 0 && k < n; mask &= mask - 1, at += f.value_bits, ++k) {
      frames[k] = (b << internal::kBlockShift) + static_cast<uint32_t>(internal::low_bit(mask));
      values[k] = dequantize(cv.q_base + static_cast<int64_t>(base + internal::read_bits(rec, at, f.value_bits)), cv.step);
    }
  }
  return k == n ? Status::ok : Status::invalid_argument;  // k < n cannot happen for a loaded clip
}

Status Clip::sample_channel(uint32_t c, float frame_position, float& out) const noexcept {
  const Image& img = KEYANIM_IMG;
  if (c >= img.interp.size() || std::isnan(frame_position)) return Status::invalid_argument;
  uint32_t quat = 0, component = 0;
  if (quat_of_channel(img, c, quat, component))
    out = quat_channel(img, quat, component, frame_position);
  else
    internal::sample_listed(img, frame_position, &c, 1, &out);
  return Status::ok;
}

// ---- Sampling

Status Clip::sample(double frame_position, std::span<float> out, Cursor* cursor) const noexcept {
  const Status s = sample_stored(frame_position, out, cursor);
  if (s == Status::ok) euler_in_place(KEYANIM_IMG, out.data());
  return s;
}

Status Clip::sample_stored(double frame_position, std::span<float> out, Cursor* cursor) const noexcept {
  if (std::isnan(frame_position)) return Status::invalid_argument;
  const Image& img = KEYANIM_IMG;
  if (out.size() < img.interp.size()) return Status::output_too_small;
  const float f = static_cast<float>(frame_position);
  if (cursor != nullptr) {
    if (!cursor->prepared_for(*this)) return Status::invalid_argument;
    internal::sample_playback(img, *cursor->state_, f, out.data());
  } else {
    internal::sample_all(img, f, out.data());
  }
  return Status::ok;
}

Status Clip::sample_time(double seconds, std::span<float> out, Cursor* cursor) const noexcept {
  if (std::isnan(seconds)) return Status::invalid_argument;
  const double ft = KEYANIM_IMG.frame_time;
  return sample(ft > 0.0 ? seconds / ft : 0.0, out, cursor);
}

Status Clip::sample_channels(double frame_position, std::span<const uint32_t> channels,
                             std::span<float> out) const noexcept {
  if (std::isnan(frame_position)) return Status::invalid_argument;
  if (out.size() < channels.size()) return Status::output_too_small;
  const Image& img = KEYANIM_IMG;
  if (channels.size() > UINT32_MAX) return Status::invalid_argument;
  for (uint32_t c : channels)
    if (c >= img.interp.size()) return Status::invalid_argument;
  const float f = static_cast<float>(frame_position);
  internal::sample_listed(img, f, channels.data(), static_cast<uint32_t>(channels.size()), out.data());
  uint32_t quat = 0, component = 0;
  for (size_t i = 0; i < channels.size(); ++i)  // a quaternion node's angle needs its x, y and z
    if (quat_of_channel(img, channels[i], quat, component)) out[i] = quat_channel(img, quat, component, f);
  return Status::ok;
}

Status Clip::sample_local(double frame_position, std::span<Transform> out, Cursor* cursor,
                          PositionReading reading) const noexcept {
  if (std::isnan(frame_position)) return Status::invalid_argument;
  const Image& img = KEYANIM_IMG;
  const uint32_t nodes = static_cast<uint32_t>(img.rig->skeleton.joints.size());
  if (out.size() < nodes) return Status::output_too_small;
  const float f = static_cast<float>(frame_position);
  if (cursor != nullptr) {
    if (!cursor->prepared_for(*this)) return Status::invalid_argument;
    float* values = cursor->state_->channels.data();
    internal::sample_playback(img, *cursor->state_, f, values, out.data());  // the tracks' rotations too
    internal::local_transforms(img, 0, nodes, values, reading, out.data(), true);
    return Status::ok;
  }
  // Without a cursor, the whole pose in a stack buffer when it fits (the usual skeleton), else
  // node by node in batches whose channels fit it.
  constexpr uint32_t kBatch = 2048;
  float values[kBatch];
  if (img.interp.size() <= kBatch) {
    // The quaternion tracks' rotations come straight from their records (quat_tracks.h).
    internal::prefetch_pose_tables(img, out.data(), nodes);
    internal::sample_all_but_quat_tracks(img, f, values);
    internal::local_transforms(img, 0, nodes, values, reading, out.data(), true);
    internal::quat_track_rotations(img, f, out.data());
    return Status::ok;
  }
  const auto& joints = img.rig->skeleton.joints;
  for (uint32_t first = 0; first < nodes;) {
    uint32_t last = first;
    const uint32_t column = joints[first].first_channel;
    uint32_t count = 0;
    while (last < nodes && count + joints[last].channels.size() <= kBatch) count += uint32_t(joints[last++].channels.size());
    internal::sample_range(img, f, column, count, values);
    internal::local_transforms(img, first, last, values, reading, out.data() + first);
    first = last;
  }
  return Status::ok;
}

Status Clip::sample_model(double frame_position, std::span<Transform> out, Cursor* cursor,
                          PositionReading reading) const noexcept {
  const Status s = sample_local(frame_position, out, cursor, reading);
  if (s == Status::ok) internal::compose_model(KEYANIM_IMG, out.data());
  return s;
}

}  // namespace keyanim
