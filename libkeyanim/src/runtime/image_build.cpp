// Building the runtime image (image.h) from a clip's decoded keys. Two passes over every curve:
// the first sizes each record (its widths depend on the values in its window), the second
// writes it at its place in the block-major payload.
#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <utility>

#include "internal/quat_layout.h"
#include "runtime/image.h"
#include "runtime/rig_cache_access.h"

namespace keyanim::internal {
namespace {

uint32_t bit_width(uint64_t x) noexcept { return static_cast<uint32_t>(std::bit_width(x)); }
uint64_t zigzag(int64_t d) noexcept { return (static_cast<uint64_t>(d) << 1) ^ static_cast<uint64_t>(d >> 63); }

// A curve's keys (n >= 2), extended on both sides by virtual keys that repeat the end values at
// the end segments' spacing: index i < 0 or i >= n is such a key.
struct Keys {
  const uint32_t* k = nullptr;
  const int64_t* q = nullptr;
  int64_t n = 0;
  int64_t frame(int64_t i) const noexcept {
    if (i < 0) return int64_t(k[0]) + (int64_t(k[1]) - int64_t(k[0])) * i;
    if (i >= n) return int64_t(k[n - 1]) + (int64_t(k[n - 1]) - int64_t(k[n - 2])) * (i - n + 1);
    return k[i];
  }
  int64_t value(int64_t i) const noexcept { return q[std::clamp<int64_t>(i, 0, n - 1)]; }
};

// One record's window: keys first - 2 .. last + 1, where [first, last) are the block's keys;
// for a quaternion track, of each of its three curves (which share their key frames).
struct RecordPlan {
  int64_t first = 0, last = 0;
  uint32_t curves = 1;
  uint64_t base[kTrackCurves] = {};  // per curve, the smallest value in the window, minus q_base
  uint32_t value_bits[kTrackCurves] = {}, context_bits = 0;
  uint64_t size_bytes = 0;
};

// A track's curves: `curves` of them from `keys` and `cv` (their Keys and Curve facts).
RecordPlan plan_record(const Keys* keys, const Curve* cv, uint32_t curves, int64_t first, int64_t last, int64_t start) {
  RecordPlan r;
  r.first = first;
  r.last = last;
  r.curves = curves;
  uint64_t bits = (curves == 1 ? kRecordBitsAt : kTrackRecordBitsAt);
  for (uint32_t k = 0; k < curves; ++k) {
    // The window's values: the keys first - 2 .. last + 1 clamped to the curve (virtual keys
    // repeat the end values).
    const int64_t* q = keys[k].q + std::max<int64_t>(first - 2, 0);
    const int64_t* q_end = keys[k].q + std::min(last + 1, keys[k].n - 1) + 1;
    int64_t lo = *q, hi = *q;
    for (; q < q_end; ++q) lo = std::min(lo, *q), hi = std::max(hi, *q);
    r.base[k] = static_cast<uint64_t>(lo - cv[k].q_base);
    r.value_bits[k] = bit_width(static_cast<uint64_t>(hi - lo));
    bits += cv[k].base_bits + uint64_t(last - first + kContextKeys) * r.value_bits[k];
  }
  const Keys& f = keys[0];  // the curves' frames are the same
  const int64_t end = start + kBlockFrames;
  const uint64_t context = zigzag(f.frame(first - 2) - start) | zigzag(f.frame(first - 1) - start) |
                           zigzag(f.frame(last) - end) | zigzag(f.frame(last + 1) - end);
  r.context_bits = bit_width(context);
  bits += kContextKeys * uint64_t(r.context_bits);
  r.size_bytes = (bits + 7) / 8;
  return r;
}

// Writes bits least significant first into zeroed bytes, a 64-bit word at a time (the payload
// has kPayloadPadding bytes after the last record, so a word never runs past it).
class BitWriter {
 public:
  explicit BitWriter(uint8_t* p) : p_(p) {}
  void put(uint64_t v, uint32_t width) {  // width <= 57, v < 2^width
    uint64_t x;
    std::memcpy(&x, p_ + (bit_ >> 3), 8);
    x |= v << (bit_ & 7);
    std::memcpy(p_ + (bit_ >> 3), &x, 8);
    bit_ += width;
  }

 private:
  uint8_t* p_;
  uint64_t bit_ = 0;
};

void write_record(uint8_t* out, const Keys* keys, const Curve* cv, const RecordPlan& r, int64_t start) {
  const Keys& f = keys[0];
  uint64_t mask = 0;
  for (int64_t i = r.first; i < r.last; ++i) mask |= uint64_t(1) << (f.k[i] - start);
  std::memcpy(out, &mask, 8);
  for (uint32_t k = 0; k < r.curves; ++k) out[8 + k] = static_cast<uint8_t>(r.value_bits[k]);
  const uint32_t header = r.curves == 1 ? kRecordBitsAt : kTrackRecordBitsAt;
  out[header / 8 - 1] = static_cast<uint8_t>(r.context_bits);
  BitWriter w(out + header / 8);
  const int64_t end = start + kBlockFrames;
  w.put(zigzag(f.frame(r.first - 2) - start), r.context_bits);
  w.put(zigzag(f.frame(r.first - 1) - start), r.context_bits);
  w.put(zigzag(f.frame(r.last) - end), r.context_bits);
  w.put(zigzag(f.frame(r.last + 1) - end), r.context_bits);
  for (uint32_t k = 0; k < r.curves; ++k) w.put(r.base[k], cv[k].base_bits);
  for (uint32_t k = 0; k < r.curves; ++k) {
    const Keys& keys_k = keys[k];
    const uint64_t low = static_cast<uint64_t>(cv[k].q_base) + r.base[k];
    const uint32_t vw = r.value_bits[k];
    const int64_t inner_first = std::max<int64_t>(r.first - 2, 0), inner_last = std::min(r.last + 1, keys_k.n - 1);
    for (int64_t i = r.first - 2; i < inner_first; ++i) w.put(static_cast<uint64_t>(keys_k.value(i)) - low, vw);
    for (int64_t i = inner_first; i <= inner_last; ++i) w.put(static_cast<uint64_t>(keys_k.q[i]) - low, vw);
    for (int64_t i = std::max(inner_last + 1, r.first - 2); i <= r.last + 1; ++i)
      w.put(static_cast<uint64_t>(keys_k.value(i)) - low, vw);
  }
}

// The image's arrays as build_image fills them, before they are written as IMAG (Image's
// members, as vectors).
struct Arrays {
  std::vector<Interpolation> interp;
  std::vector<float> tension;
  std::vector<uint32_t> key_count, curve_of;
  std::vector<float> fixed_value;
  std::vector<uint32_t> fixed_frame, fixed_channels;
  std::vector<Curve> curves;
  uint32_t block_curves = 0;
  std::vector<ListSpan> lists;
  std::vector<uint32_t> list_frames;
  std::vector<float> list_values;
  std::vector<int64_t> list_q;
  std::vector<float> curve_s, first_frame, last_frame, first_value, last_value;
  std::vector<uint32_t> curve_linear, curve_channel;
  std::vector<uint32_t> quat_node, quat_column;
  std::vector<float> quat_reference;  // 4 x lanes(Q): x's, y's, z's, w's
  uint32_t quat_tracks = 0;
  uint32_t block_count = 0;
  std::vector<uint32_t> record_offset;
  std::vector<uint8_t> payload;  // records, then kPayloadPadding zero bytes
};

template <class T>
void put_array(uint8_t* imag, const ImageLayout& at, ImageLayout::Array a, const std::vector<T>& v) noexcept {
  if (!v.empty()) std::memcpy(imag + at.at[a], v.data(), v.size() * sizeof(T));
}

// IMAG's bytes (spec section 9.2) in a zeroed, 8-aligned buffer, and the image pointed into it.
void write_imag(const Arrays& a, Image& img) {
  const ImageCounts n{a.interp.size(), a.curves.size(), a.block_curves, a.block_count, a.list_frames.size(),
                      a.payload.size() - kPayloadPadding, a.quat_node.size(), a.quat_tracks};
  const ImageLayout at(n);
  auto words = std::make_shared<uint64_t[]>(at.end() / 8);
  uint8_t* imag = reinterpret_cast<uint8_t*>(words.get());
  // Version 5's Quat_Count and Quat_Track_Count (version 4's Image_Reserved: 0 without
  // quaternion nodes).
  const uint32_t header[8] = {kBlockShift, uint32_t(n.curves), uint32_t(n.block_curves), uint32_t(n.blocks),
                              uint32_t(n.list_keys), uint32_t(n.payload), uint32_t(n.quat_nodes), uint32_t(n.quat_tracks)};
  std::memcpy(imag, header, sizeof header);
  using L = ImageLayout;
  put_array(imag, at, L::interpolation, a.interp);
  put_array(imag, at, L::tension, a.tension);
  put_array(imag, at, L::key_count, a.key_count);
  put_array(imag, at, L::curve_of, a.curve_of);
  put_array(imag, at, L::fixed_value, a.fixed_value);
  put_array(imag, at, L::fixed_frame, a.fixed_frame);
  put_array(imag, at, L::fixed_channels, a.fixed_channels);
  for (size_t i = 0; i < a.curves.size(); ++i) {  // field by field: a Curve's padding is not zero
    uint8_t* p = imag + at.at[L::curves] + size_t(kCurveBytes) * i;
    std::memcpy(p, &a.curves[i].q_base, 8);
    std::memcpy(p + 8, &a.curves[i].step, 8);
    std::memcpy(p + 16, &a.curves[i].base_bits, 4);  // then Curve_Reserved, 0
  }
  put_array(imag, at, L::curve_s, a.curve_s);
  put_array(imag, at, L::first_frame, a.first_frame);
  put_array(imag, at, L::last_frame, a.last_frame);
  put_array(imag, at, L::first_value, a.first_value);
  put_array(imag, at, L::last_value, a.last_value);
  put_array(imag, at, L::curve_linear, a.curve_linear);
  put_array(imag, at, L::curve_channel, a.curve_channel);
  put_array(imag, at, L::quat_node, a.quat_node);
  put_array(imag, at, L::quat_column, a.quat_column);
  put_array(imag, at, L::quat_reference, a.quat_reference);
  put_array(imag, at, L::lists, a.lists);
  put_array(imag, at, L::list_frames, a.list_frames);
  put_array(imag, at, L::list_values, a.list_values);
  put_array(imag, at, L::list_q, a.list_q);
  put_array(imag, at, L::record_offset, a.record_offset);
  put_array(imag, at, L::payload, a.payload);
  img.held_bytes = at.end();
  img.storage = std::move(words);
  attach_image(img, {imag, at.end()}, uint32_t(n.channels));
}

}  // namespace

// The motion: IMAG's bytes (owned, or viewed: the clip needs them resident either way), notes,
// and the image itself.
size_t Image::animation_bytes() const noexcept {
  return sizeof(Image) + notes.capacity() + std::max(held_bytes, imag.size()) + own_euler.bytes();
}

void plan_rotations(Image& img) {
  const Rig& rig = *img.rig;
  if (img.quat_node.empty()) {
    img.euler = &rig.euler;
    return;
  }
  std::vector<uint32_t> set(img.quat_node.begin(), img.quat_node.end());
  std::sort(set.begin(), set.end());
  const std::lock_guard<std::mutex> lock(rig.plans_mutex);
  for (const Rig::QuatPlan& p : rig.plans) {
    if (p.quat_nodes != set) continue;
    img.rig_euler = p.euler;
    img.euler = img.rig_euler.get();
    return;
  }
  std::vector<uint8_t> quat(rig.skeleton.joints.size(), 0);
  for (uint32_t n : set) quat[n] = 1;
  if (rig.plans.size() < Rig::kMaxQuatPlans) {
    img.rig_euler = std::make_shared<const EulerGroups>(euler_groups(rig.skeleton, &quat));
    img.euler = img.rig_euler.get();
    rig.plans.push_back({std::move(set), img.rig_euler});
    return;
  }
  img.own_euler = euler_groups(rig.skeleton, &quat);
  img.euler = &img.own_euler;
}

template <class T>
std::span<const T> array_at(std::span<const uint8_t> imag, const ImageLayout& at, ImageLayout::Array a,
                            uint64_t count) noexcept {
  return {reinterpret_cast<const T*>(imag.data() + at.at[a]), static_cast<size_t>(count)};
}

ImageCounts image_counts(std::span<const uint8_t> imag, uint32_t channels) noexcept {
  uint32_t h[8];
  std::memcpy(h, imag.data(), sizeof h);
  return {channels, h[1], h[2], h[3], h[4], h[5], h[6], h[7]};
}

void attach_image(Image& img, std::span<const uint8_t> imag, uint32_t channels) noexcept {
  const ImageCounts n = image_counts(imag, channels);
  const ImageLayout at(n);
  using L = ImageLayout;
  const uint64_t c = n.channels, lanes = L::lanes(n.curves), lists = n.curves - n.block_curves;
  img.imag = imag;
  img.interp = array_at<Interpolation>(imag, at, L::interpolation, c);
  img.tension = array_at<float>(imag, at, L::tension, c);
  img.key_count = array_at<uint32_t>(imag, at, L::key_count, c);
  img.curve_of = array_at<uint32_t>(imag, at, L::curve_of, c);
  img.fixed_value = array_at<float>(imag, at, L::fixed_value, c);
  img.fixed_frame = array_at<uint32_t>(imag, at, L::fixed_frame, c);
  img.fixed_channels = array_at<uint32_t>(imag, at, L::fixed_channels, c - n.curves);
  img.curves = array_at<Curve>(imag, at, L::curves, n.curves);
  img.block_curves = static_cast<uint32_t>(n.block_curves);
  img.lists = array_at<ListSpan>(imag, at, L::lists, lists);
  img.list_frames = array_at<uint32_t>(imag, at, L::list_frames, n.list_keys);
  img.list_values = array_at<float>(imag, at, L::list_values, n.list_keys);
  img.list_q = array_at<int64_t>(imag, at, L::list_q, n.list_keys);
  img.curve_s = array_at<float>(imag, at, L::curve_s, lanes);
  img.first_frame = array_at<float>(imag, at, L::first_frame, lanes);
  img.last_frame = array_at<float>(imag, at, L::last_frame, lanes);
  img.first_value = array_at<float>(imag, at, L::first_value, lanes);
  img.last_value = array_at<float>(imag, at, L::last_value, lanes);
  img.curve_linear = array_at<uint32_t>(imag, at, L::curve_linear, lanes);
  img.curve_channel = array_at<uint32_t>(imag, at, L::curve_channel, n.curves);
  img.quat_node = array_at<uint32_t>(imag, at, L::quat_node, n.quat_nodes);
  img.quat_column = array_at<uint32_t>(imag, at, L::quat_column, n.quat_nodes);
  img.quat_lanes = static_cast<uint32_t>(L::lanes(n.quat_nodes));
  img.quat_reference = array_at<float>(imag, at, L::quat_reference, 4 * uint64_t(img.quat_lanes));
  img.quat_tracks = static_cast<uint32_t>(n.quat_tracks);
  img.block_tracks = static_cast<uint32_t>(n.block_tracks());
  img.block_count = static_cast<uint32_t>(n.blocks);
  img.record_offset = array_at<uint32_t>(imag, at, L::record_offset, n.blocks * n.block_tracks() + kPrefetchRecords);
  img.payload = array_at<uint8_t>(imag, at, L::payload, n.payload + kPayloadPadding);
}

namespace {

// Whether the quaternion node's curves are block curves: a quaternion track (its three curves
// have one key count: all block curves or none).
bool is_quat_track(const ClipSource& src, const QuatNode& n, uint64_t blocks) {
  const uint32_t keys = src.channels[first_quat_channel(src.skeleton, n.node)].key_count;
  return keys >= 2 && !is_list_curve(keys, blocks);
}

// The channels of the curves in IMAG's order (spec 9.2): the quaternion tracks' x's, then their
// y's, then their z's (node order), the other block curves in channel order, then the list
// curves in channel order. `tracks` gets the number of quaternion tracks.
std::vector<uint32_t> curve_order(const ClipSource& src, uint64_t blocks, uint32_t& tracks) {
  std::vector<uint32_t> order, x;
  for (const QuatNode& n : src.quat_nodes)
    if (is_quat_track(src, n, blocks)) x.push_back(first_quat_channel(src.skeleton, n.node));
  tracks = static_cast<uint32_t>(x.size());
  for (uint32_t k = 0; k < kTrackCurves; ++k)
    for (uint32_t c : x) order.push_back(c + k);
  std::vector<uint8_t> taken(src.channels.size(), 0);
  for (uint32_t c : order) taken[c] = 1;
  for (int list = 0; list < 2; ++list)
    for (uint32_t c = 0; c < src.channels.size(); ++c) {
      const uint32_t n = src.channels[c].key_count;
      if (n >= 2 && !taken[c] && is_list_curve(n, blocks) == (list == 1)) order.push_back(c);
    }
  return order;
}

// Channel c as the next curve (a list curve's keys into the lists too).
void add_curve(const ClipSource& src, uint32_t c, Arrays& a) {
  const SourceChannel& sc = src.channels[c];
  const uint32_t n = sc.key_count;
  const uint64_t blocks = (uint64_t(src.frame_count) + kBlockFrames - 1) / kBlockFrames;
  const int64_t* q = src.q.data() + sc.first_key;
  const uint32_t* k = src.frames.data() + sc.first_key;
  Curve cv;
  cv.step = sc.step;
  const auto [lo, hi] = std::minmax_element(q, q + n);
  cv.q_base = *lo;
  cv.base_bits = bit_width(static_cast<uint64_t>(*hi - *lo));
  if (is_list_curve(n, blocks)) {
    a.lists.push_back({static_cast<uint32_t>(a.list_frames.size()), n});
    a.list_frames.insert(a.list_frames.end(), k, k + n);
    for (uint32_t i = 0; i < n; ++i) a.list_values.push_back(dequantize(q[i], sc.step));
    a.list_q.insert(a.list_q.end(), q, q + n);
  }
  a.curve_s.push_back(tension_to_s(sc.tension));
  a.first_frame.push_back(static_cast<float>(k[0]));
  a.last_frame.push_back(static_cast<float>(k[n - 1]));
  a.first_value.push_back(dequantize(q[0], sc.step));
  a.last_value.push_back(dequantize(q[n - 1], sc.step));
  a.curve_linear.push_back(sc.interp == Interpolation::linear ? ~0u : 0u);
  a.curve_of[c] = static_cast<uint32_t>(a.curves.size());
  a.curves.push_back(cv);
  a.curve_channel.push_back(c);
}

// The quaternion nodes' arrays (node, x's column, references in lanes): the quaternion tracks
// first, in node order, then the others.
void add_quat_arrays(const ClipSource& src, Arrays& a) {
  const size_t q = src.quat_nodes.size();
  const size_t lanes = ImageLayout::lanes(q);
  const uint64_t blocks = (uint64_t(src.frame_count) + kBlockFrames - 1) / kBlockFrames;
  a.quat_reference.assign(4 * lanes, 0.0f);
  for (size_t i = q; i < lanes; ++i) a.quat_reference[3 * lanes + i] = 1.0f;  // the identity
  for (int tracks = 1; tracks >= 0; --tracks)
    for (const QuatNode& n : src.quat_nodes) {
      if (is_quat_track(src, n, blocks) != (tracks == 1)) continue;
      const size_t i = a.quat_node.size();
      a.quat_node.push_back(n.node);
      a.quat_column.push_back(first_quat_channel(src.skeleton, n.node));
      float ref[4];
      reference_of(n, ref);
      for (size_t k = 0; k < 4; ++k) a.quat_reference[k * lanes + i] = ref[k];
    }
}

// Block track t's curves: their Keys and Curve facts.
struct TrackCurves {
  uint32_t curves = 1;
  Keys keys[kTrackCurves];
  Curve cv[kTrackCurves];
};
TrackCurves track_curves(const ClipSource& src, const Arrays& a, uint32_t t) {
  TrackCurves tc;
  const uint32_t T = a.quat_tracks;
  tc.curves = t < T ? kTrackCurves : 1;
  for (uint32_t k = 0; k < tc.curves; ++k) {
    const uint32_t curve = t < T ? t + k * T : t + 2 * T;
    const SourceChannel& sc = src.channels[a.curve_channel[curve]];
    tc.keys[k] = {src.frames.data() + sc.first_key, src.q.data() + sc.first_key, sc.key_count};
    tc.cv[k] = a.curves[curve];
  }
  return tc;
}

// The image's arrays from a source's keys: two passes over every curve, the first sizing each
// record (its widths depend on the values in its window), the second writing it at its place.
Arrays build_arrays(const ClipSource& src) {
  Arrays a;
  const size_t channels = src.channels.size();
  a.interp.resize(channels);
  a.tension.resize(channels);
  a.key_count.resize(channels);
  a.curve_of.assign(channels, kNoCurve);
  a.fixed_value.assign(channels, 0.0f);
  a.fixed_frame.assign(channels, 0);
  const uint64_t blocks = (uint64_t(src.frame_count) + kBlockFrames - 1) / kBlockFrames;
  for (size_t c = 0; c < channels; ++c) {
    const SourceChannel& sc = src.channels[c];
    a.interp[c] = sc.interp;
    a.tension[c] = sc.tension;
    a.key_count[c] = sc.key_count;
    if (sc.key_count >= 2) continue;
    if (sc.key_count == 1) {
      a.fixed_value[c] = dequantize(src.q[sc.first_key], sc.step);
      a.fixed_frame[c] = src.frames[sc.first_key];
    }
    a.fixed_channels.push_back(static_cast<uint32_t>(c));
  }
  for (const uint32_t c : curve_order(src, blocks, a.quat_tracks)) add_curve(src, uint32_t(c), a);
  a.block_curves = static_cast<uint32_t>(a.curves.size() - a.lists.size());
  const size_t nc = a.curves.size();
  // The per-curve arrays are read 4 curves at a time: pad them to whole lanes (never "in" a
  // segment: the padding lanes are clamped constants).
  const size_t lanes = (nc + 3) & ~size_t(3);
  a.curve_s.resize(lanes, 0.0f);
  a.first_frame.resize(lanes, std::numeric_limits<float>::infinity());
  a.last_frame.resize(lanes, std::numeric_limits<float>::infinity());
  a.first_value.resize(lanes, 0.0f);
  a.last_value.resize(lanes, 0.0f);
  a.curve_linear.resize(lanes, 0u);
  a.block_count = nc == 0 ? 0 : static_cast<uint32_t>(blocks);
  add_quat_arrays(src, a);
  const size_t nt = a.block_curves - 2 * size_t(a.quat_tracks);  // block tracks: records at most 4 per key

  const size_t records = size_t(a.block_count) * nt;
  std::vector<RecordPlan> plans(records);
  for (uint32_t t = 0; t < nt; ++t) {
    const TrackCurves tc = track_curves(src, a, t);
    int64_t first = 0, last = 0;  // the block's keys: [first, last)
    const Keys& keys = tc.keys[0];  // the track's key frames
    for (uint32_t b = 0; b < a.block_count; ++b) {
      const int64_t start = int64_t(b) << kBlockShift;
      while (first < keys.n && int64_t(keys.k[first]) < start) ++first;
      last = std::max(last, first);
      while (last < keys.n && int64_t(keys.k[last]) < start + kBlockFrames) ++last;
      plans[size_t(b) * nt + t] = plan_record(tc.keys, tc.cv, tc.curves, first, last, start);
      first = last;  // the next block's keys start where this block's end
    }
  }
  // Offsets in block-major order; u32 offsets bound the payload (checked: 2^32 bytes is far
  // beyond any clip the decoder's limits admit, but a too large one must fail, not wrap).
  a.record_offset.resize(records + kPrefetchRecords);
  uint64_t total = 0;
  for (size_t r = 0; r < records; ++r) {
    if (total > UINT32_MAX) throw std::bad_alloc();
    a.record_offset[r] = static_cast<uint32_t>(total);
    total += plans[r].size_bytes;
  }
  a.payload.assign(total + kPayloadPadding, 0);
  for (uint32_t t = 0; t < nt; ++t) {
    const TrackCurves tc = track_curves(src, a, t);
    for (uint32_t b = 0; b < a.block_count; ++b) {
      const size_t r = size_t(b) * nt + t;
      write_record(a.payload.data() + a.record_offset[r], tc.keys, tc.cv, plans[r], int64_t(b) << kBlockShift);
    }
  }
  return a;
}

// The clip's facts, rig and notes (not its arrays), from a source or a checked file; the rig is
// `rig` if given, else the source's skeleton (interned in `rigs` if given).
std::shared_ptr<Image> image_of(ClipSource& src, RigCache* rigs, std::shared_ptr<const Rig> rig = nullptr) {
  auto img = std::make_shared<Image>();
  img->version_major = src.version_major;
  img->version_minor = src.version_minor;
  img->frame_count = src.frame_count;
  img->frame_time = src.frame_time;
  img->rule = src.rule;
  img->rig = rig != nullptr    ? std::move(rig)
             : rigs != nullptr ? RigCacheAccess::intern(*rigs, std::move(src.skeleton))
                               : make_rig(std::move(src.skeleton));
  img->notes = std::move(src.notes);
  static std::atomic<uint64_t> next_id{1};
  img->id = next_id.fetch_add(1, std::memory_order_relaxed);
  return img;
}

}  // namespace

std::shared_ptr<const Image> build_image(ClipSource&& src, RigCache* rigs) {
  const Arrays a = build_arrays(src);
  const uint64_t keys = src.frames.size();
  std::shared_ptr<Image> img = image_of(src, rigs);
  img->total_keys = keys;
  write_imag(a, *img);
  plan_rotations(*img);
  return img;
}

std::shared_ptr<const Image> view_image(ClipSource&& facts, uint64_t total_keys, std::span<const uint8_t> imag,
                                        std::shared_ptr<const void> storage, size_t held_bytes, RigCache* rigs,
                                        std::shared_ptr<const Rig> rig, std::span<const uint8_t> skel) {
  const bool found = rig != nullptr;
  const uint32_t channels = static_cast<uint32_t>(found ? rig->skeleton.channel_count() : facts.skeleton.channel_count());
  std::shared_ptr<Image> img = image_of(facts, rigs, std::move(rig));
  if (!found && rigs != nullptr) RigCacheAccess::remember_skel(*rigs, img->rig, skel);
  img->total_keys = total_keys;
  img->storage = std::move(storage);
  img->held_bytes = held_bytes;
  img->runtime_profile = true;
  attach_image(*img, imag, channels);
  plan_rotations(*img);
  return img;
}

bool image_content_holds(const Image& img) {
  ClipSource keys = image_keys(img);
  for (size_t c = 0; c < keys.channels.size(); ++c) {
    const SourceChannel& sc = keys.channels[c];
    for (uint64_t i = sc.first_key; i < sc.first_key + sc.key_count; ++i)
      if (keys.q[i] > kMaxAbsQ || keys.q[i] < -kMaxAbsQ || !std::isfinite(dequantize(keys.q[i], sc.step))) return false;
  }
  if (stored_quat_out_of_range(keys) != UINT32_MAX) return false;
  Image rebuilt;
  write_imag(build_arrays(keys), rebuilt);
  return rebuilt.imag.size() == img.imag.size() && std::memcmp(rebuilt.imag.data(), img.imag.data(), img.imag.size()) == 0;
}

}  // namespace keyanim::internal
