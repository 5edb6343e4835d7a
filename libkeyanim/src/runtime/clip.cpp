// Clip and Cursor: the public face of the runtime image (image.h), its sampler (sampler.h) and
// poses (pose.h).
#include "keyanim/clip.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>
#include <vector>

#include "internal/simd.h"
#include "runtime/clip_access.h"
#include "runtime/pose.h"
#include "runtime/sampler.h"

namespace keyanim {

using internal::Image;

namespace {

const Image& empty_image() {
  static const Image kEmpty;
  return kEmpty;
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
uint16_t Clip::version_minor() const noexcept { return KEYANIM_IMG.version_minor; }
uint32_t Clip::frame_count() const noexcept { return KEYANIM_IMG.frame_count; }
double Clip::frame_time() const noexcept { return KEYANIM_IMG.frame_time; }
uint32_t Clip::channel_count() const noexcept { return static_cast<uint32_t>(KEYANIM_IMG.interp.size()); }
TangentRule Clip::tangent_rule() const noexcept { return KEYANIM_IMG.rule; }
const Skeleton& Clip::skeleton() const noexcept { return KEYANIM_IMG.skeleton; }
uint64_t Clip::total_keys() const noexcept { return KEYANIM_IMG.total_keys; }
const std::string& Clip::encoder_notes() const noexcept { return KEYANIM_IMG.notes; }
size_t Clip::memory_bytes() const noexcept { return image_ ? image_->memory_bytes() : 0; }

double Clip::duration() const noexcept {
  const Image& img = KEYANIM_IMG;
  return img.frame_count == 0 ? 0.0 : static_cast<double>(img.frame_count - 1) * img.frame_time;
}

ChannelInfo Clip::channel(uint32_t c) const noexcept {
  const Image& img = KEYANIM_IMG;
  if (c >= img.interp.size()) return {};
  return {img.interp[c], img.tension[c], img.key_count[c]};
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
  // Walk the records block by block: each lists its block's keys in its mask.
  const internal::Curve& cv = img.curves[curve];
  uint32_t k = 0;
  for (uint32_t b = 0; b < img.block_count && k < n; ++b) {
    const uint8_t* rec = img.record(b, curve);
    uint64_t mask;
    std::memcpy(&mask, rec, 8);
    const uint64_t widths = internal::read_bits(rec, 64, 11);
    const uint32_t vw = static_cast<uint32_t>(widths & 63), kw = static_cast<uint32_t>(widths >> 6);
    const uint64_t base = internal::read_bits(rec, internal::kRecordFixedBits, cv.base_bits);
    uint64_t at = cv.context_at + 4ull * kw + 2ull * vw;  // the block's first key follows two context keys
    for (; mask != 0 && k < n; mask &= mask - 1, at += vw, ++k) {
      frames[k] = (b << internal::kBlockShift) + static_cast<uint32_t>(internal::low_bit(mask));
      values[k] = dequantize(cv.q_base + static_cast<int64_t>(base + internal::read_bits(rec, at, vw)), cv.step);
    }
  }
  return k == n ? Status::ok : Status::invalid_argument;  // k < n cannot happen for a loaded clip
}

float Clip::sample_channel(uint32_t c, float frame_position) const noexcept {
  const Image& img = KEYANIM_IMG;
  if (c >= img.interp.size() || std::isnan(frame_position)) return 0.0f;
  float v = 0.0f;
  internal::sample_listed(img, frame_position, &c, 1, &v);
  return v;
}

// ---- Cursor

struct Cursor::State {
  std::shared_ptr<const Image> image;
  // Per curve, structure of arrays: the segment state of sampler.h's Segment.
  std::vector<float> lo, hi, k0, k1, p0, d, m0, m1, value;
  std::vector<uint32_t> linear, direct;  // all ones / zeros, for select
  std::vector<float> result;             // per curve, before the scatter to channels
  std::vector<float> channels;           // a whole pose, for sample_local/model
};

Cursor::Cursor() = default;
Cursor::~Cursor() = default;
Cursor::Cursor(Cursor&&) noexcept = default;
Cursor& Cursor::operator=(Cursor&&) noexcept = default;

Status Cursor::prepare(const Clip& clip) noexcept {
  try {
    auto st = std::make_unique<State>();
    st->image = clip.image_;
    const Image& img = ClipAccess::image(clip);
    // Rounded up to whole SIMD lanes; an empty range (lo = +inf) makes every curve refresh.
    const size_t n = (img.curves.size() + 3) & ~size_t(3);
    const float inf = std::numeric_limits<float>::infinity();
    for (auto* v : {&st->lo, &st->hi, &st->k0, &st->p0, &st->d, &st->m0, &st->m1, &st->value, &st->result})
      v->assign(n, 0.0f);
    st->lo.assign(n, inf);
    st->k1.assign(n, 1.0f);
    st->linear.assign(n, 0u);
    st->direct.assign(n, ~0u);
    st->channels.assign(img.interp.size(), 0.0f);
    state_ = std::move(st);
    return Status::ok;
  } catch (const std::bad_alloc&) {
    state_.reset();
    return Status::limit_exceeded;
  }
}

bool Cursor::prepared_for(const Clip& clip) const noexcept {
  return state_ && state_->image && clip.image_ && state_->image->id == clip.image_->id;
}

namespace {

// Playback through a prepared cursor: refresh the curves whose segment f left, then evaluate
// every curve's polynomial 4 at a time (the same building blocks as the sampler).
void sample_cursor(const Image& img, Cursor::State& st, float f, float* out) noexcept {
  const uint32_t n = static_cast<uint32_t>(img.curves.size());
  for (uint32_t i = 0; i < n; ++i) {
    if (st.lo[i] <= f && f < st.hi[i]) continue;
    internal::Segment s;
    internal::locate_segment(img, i, f, s);
    st.lo[i] = s.lo, st.hi[i] = s.hi, st.k0[i] = s.k0, st.k1[i] = s.k1;
    st.p0[i] = s.o.p0, st.d[i] = s.o.d, st.m0[i] = s.o.m0, st.m1[i] = s.o.m1, st.value[i] = s.value;
    st.linear[i] = s.linear ? ~0u : 0u;
    st.direct[i] = s.direct ? ~0u : 0u;
  }
  using internal::F4;
  const F4 fv(f);
  for (uint32_t i = 0; i < n; i += 4) {
    const F4 u = segment_u(fv, F4::load(&st.k0[i]), F4::load(&st.k1[i]));
    const Operands<F4> o{F4::load(&st.p0[i]), F4::load(&st.d[i]), F4::load(&st.m0[i]), F4::load(&st.m1[i])};
    const F4 v = select(&st.linear[i], linear_value(o.p0, o.d, u), hermite(o, u));
    select(&st.direct[i], F4::load(&st.value[i]), v).store(&st.result[i]);
  }
  for (uint32_t i = 0; i < n; ++i) out[img.curves[i].channel] = st.result[i];
  for (uint32_t c : img.fixed_channels) out[c] = img.fixed_value[c];
}

}  // namespace

// ---- Sampling

Status Clip::sample(double frame_position, std::span<float> out, Cursor* cursor) const noexcept {
  if (std::isnan(frame_position)) return Status::invalid_argument;
  const Image& img = KEYANIM_IMG;
  if (out.size() < img.interp.size()) return Status::output_too_small;
  const float f = static_cast<float>(frame_position);
  if (cursor != nullptr) {
    if (!cursor->prepared_for(*this)) return Status::invalid_argument;
    sample_cursor(img, *cursor->state_, f, out.data());
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
  internal::sample_listed(img, static_cast<float>(frame_position), channels.data(),
                          static_cast<uint32_t>(channels.size()), out.data());
  return Status::ok;
}

Status Clip::sample_local(double frame_position, std::span<Transform> out, Cursor* cursor,
                          PositionReading reading) const noexcept {
  if (std::isnan(frame_position)) return Status::invalid_argument;
  const Image& img = KEYANIM_IMG;
  const uint32_t nodes = static_cast<uint32_t>(img.skeleton.joints.size());
  if (out.size() < nodes) return Status::output_too_small;
  const float f = static_cast<float>(frame_position);
  if (cursor != nullptr) {
    if (!cursor->prepared_for(*this)) return Status::invalid_argument;
    float* values = cursor->state_->channels.data();
    sample_cursor(img, *cursor->state_, f, values);
    internal::local_transforms(img, 0, nodes, values, reading, out.data());
    return Status::ok;
  }
  // Without a cursor, node by node in batches whose channels fit a stack buffer.
  constexpr uint32_t kBatch = 256;
  float values[kBatch];
  const auto& joints = img.skeleton.joints;
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
