// Building the runtime image (image.h) from a clip's decoded keys. Two passes over every curve:
// the first sizes each record (its widths depend on the values in its window), the second
// writes it at its place in the block-major payload.
#include <algorithm>
#include <atomic>
#include <bit>
#include <cstring>
#include <limits>
#include <utility>

#include "runtime/image.h"
#include "runtime/rig_cache_access.h"

namespace keyanim::internal {
namespace {

uint32_t bit_width(uint64_t x) noexcept { return static_cast<uint32_t>(std::bit_width(x)); }
uint64_t zigzag(int64_t d) noexcept { return (static_cast<uint64_t>(d) << 1) ^ static_cast<uint64_t>(d >> 63); }

// A curve's keys (n >= 2), extended on both sides by virtual keys that repeat the end values at
// the end segments' spacing: index i < 0 or i >= n is such a key.
struct Keys {
  const uint32_t* k;
  const int64_t* q;
  int64_t n;
  int64_t frame(int64_t i) const noexcept {
    if (i < 0) return int64_t(k[0]) + (int64_t(k[1]) - int64_t(k[0])) * i;
    if (i >= n) return int64_t(k[n - 1]) + (int64_t(k[n - 1]) - int64_t(k[n - 2])) * (i - n + 1);
    return k[i];
  }
  int64_t value(int64_t i) const noexcept { return q[std::clamp<int64_t>(i, 0, n - 1)]; }
};

// One record's window: keys first - 2 .. last + 1, where [first, last) are the block's keys.
struct RecordPlan {
  int64_t first = 0, last = 0;
  uint64_t base = 0;      // smallest value in the window, minus q_base
  uint32_t value_bits = 0, context_bits = 0;
  uint64_t size_bytes = 0;
};

RecordPlan plan_record(const Keys& keys, int64_t first, int64_t last, int64_t start, int64_t q_base,
                       uint32_t base_bits) {
  RecordPlan r;
  r.first = first;
  r.last = last;
  // The window's values: the keys first - 2 .. last + 1 clamped to the curve (virtual keys
  // repeat the end values).
  const int64_t* q = keys.q + std::max<int64_t>(first - 2, 0);
  const int64_t* q_end = keys.q + std::min(last + 1, keys.n - 1) + 1;
  int64_t lo = *q, hi = *q;
  for (; q < q_end; ++q) lo = std::min(lo, *q), hi = std::max(hi, *q);
  r.base = static_cast<uint64_t>(lo - q_base);
  r.value_bits = bit_width(static_cast<uint64_t>(hi - lo));
  const int64_t end = start + kBlockFrames;
  const uint64_t context = zigzag(keys.frame(first - 2) - start) | zigzag(keys.frame(first - 1) - start) |
                           zigzag(keys.frame(last) - end) | zigzag(keys.frame(last + 1) - end);
  r.context_bits = bit_width(context);
  const uint64_t bits = kRecordBitsAt + kContextKeys * uint64_t(r.context_bits) + base_bits +
                        uint64_t(last - first + kContextKeys) * r.value_bits;
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

void write_record(uint8_t* out, const Keys& keys, const RecordPlan& r, int64_t start, int64_t q_base,
                  uint32_t base_bits) {
  uint64_t mask = 0;
  for (int64_t i = r.first; i < r.last; ++i) mask |= uint64_t(1) << (keys.k[i] - start);
  std::memcpy(out, &mask, 8);
  out[8] = static_cast<uint8_t>(r.value_bits);
  out[9] = static_cast<uint8_t>(r.context_bits);
  BitWriter w(out + kRecordBitsAt / 8);
  const int64_t end = start + kBlockFrames;
  w.put(zigzag(keys.frame(r.first - 2) - start), r.context_bits);
  w.put(zigzag(keys.frame(r.first - 1) - start), r.context_bits);
  w.put(zigzag(keys.frame(r.last) - end), r.context_bits);
  w.put(zigzag(keys.frame(r.last + 1) - end), r.context_bits);
  w.put(r.base, base_bits);
  const uint64_t low = static_cast<uint64_t>(q_base) + r.base;
  const int64_t inner_first = std::max<int64_t>(r.first - 2, 0), inner_last = std::min(r.last + 1, keys.n - 1);
  for (int64_t i = r.first - 2; i < inner_first; ++i) w.put(static_cast<uint64_t>(keys.value(i)) - low, r.value_bits);
  for (int64_t i = inner_first; i <= inner_last; ++i) w.put(static_cast<uint64_t>(keys.q[i]) - low, r.value_bits);
  for (int64_t i = std::max(inner_last + 1, r.first - 2); i <= r.last + 1; ++i)
    w.put(static_cast<uint64_t>(keys.value(i)) - low, r.value_bits);
}

// The arrays were grown by push_back: give back what they reserved beyond their size (up to
// half of each), since a loaded clip lives long.
void shrink(Image& img) {
  img.fixed_channels.shrink_to_fit();
  img.curves.shrink_to_fit();
  img.lists.shrink_to_fit();
  img.list_frames.shrink_to_fit();
  img.list_values.shrink_to_fit();
  for (auto* v : {&img.curve_s, &img.first_frame, &img.last_frame, &img.first_value, &img.last_value})
    v->shrink_to_fit();
  img.curve_linear.shrink_to_fit();
  img.curve_channel.shrink_to_fit();
  img.notes.shrink_to_fit();
}

}  // namespace

// The motion: keys, per-channel and per-curve facts, records, notes, and the image itself.
size_t Image::animation_bytes() const noexcept {
  size_t n = sizeof(Image) + notes.capacity();
  n += interp.capacity() * sizeof(Interpolation) + tension.capacity() * sizeof(float);
  n += key_count.capacity() * sizeof(uint32_t) + curve_of.capacity() * sizeof(uint32_t);
  n += fixed_frame.capacity() * sizeof(uint32_t) + fixed_value.capacity() * sizeof(float) + fixed_channels.capacity() * sizeof(uint32_t);
  n += curve_s.capacity() * sizeof(float) + first_frame.capacity() * sizeof(float) +
       last_frame.capacity() * sizeof(float) + first_value.capacity() * sizeof(float) +
       last_value.capacity() * sizeof(float) + curve_linear.capacity() * sizeof(uint32_t) +
       curve_channel.capacity() * sizeof(uint32_t);
  n += lists.capacity() * sizeof(ListSpan) + list_frames.capacity() * sizeof(uint32_t) +
       list_values.capacity() * sizeof(float);
  n += curves.capacity() * sizeof(Curve) + record_offset.capacity() * sizeof(uint32_t) + payload.capacity();
  return n;
}

std::shared_ptr<const Image> build_image(ClipSource&& src, RigCache* rigs) {
  auto img = std::make_shared<Image>();
  img->version_major = src.version_major;
  img->version_minor = src.version_minor;
  img->frame_count = src.frame_count;
  img->frame_time = src.frame_time;
  img->rule = src.rule;
  img->rig = rigs != nullptr ? RigCacheAccess::intern(*rigs, std::move(src.skeleton)) : make_rig(std::move(src.skeleton));
  img->notes = std::move(src.notes);
  img->total_keys = src.frames.size();
  static std::atomic<uint64_t> next_id{1};
  img->id = next_id.fetch_add(1, std::memory_order_relaxed);

  const size_t channels = src.channels.size();
  img->interp.resize(channels);
  img->tension.resize(channels);
  img->key_count.resize(channels);
  img->curve_of.assign(channels, kNoCurve);
  img->fixed_value.assign(channels, 0.0f);
  img->fixed_frame.assign(channels, 0);
  const uint64_t blocks = (uint64_t(src.frame_count) + kBlockFrames - 1) / kBlockFrames;
  // Block curves first, then list curves (two passes over the channels).
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t c = 0; c < channels; ++c) {
      const SourceChannel& sc = src.channels[c];
      if (pass == 0) {
        img->interp[c] = sc.interp;
        img->tension[c] = sc.tension;
        img->key_count[c] = sc.key_count;
      }
      if (sc.key_count < 2) {
        if (pass == 1) continue;
        if (sc.key_count == 1) {
          img->fixed_value[c] = dequantize(src.q[sc.first_key], sc.step);
          img->fixed_frame[c] = src.frames[sc.first_key];
        }
        img->fixed_channels.push_back(static_cast<uint32_t>(c));
        continue;
      }
      const uint32_t n = sc.key_count;
      if (is_list_curve(n, blocks) != (pass == 1)) continue;
      const int64_t* q = src.q.data() + sc.first_key;
      const uint32_t* k = src.frames.data() + sc.first_key;
      Curve cv;
      cv.step = sc.step;
      const auto [lo, hi] = std::minmax_element(q, q + n);
      cv.q_base = *lo;
      cv.base_bits = bit_width(static_cast<uint64_t>(*hi - *lo));
      if (pass == 1) {
        img->lists.push_back({static_cast<uint32_t>(img->list_frames.size()), n});
        img->list_frames.insert(img->list_frames.end(), k, k + n);
        for (uint32_t i = 0; i < n; ++i) img->list_values.push_back(dequantize(q[i], sc.step));
      }
      img->curve_s.push_back(tension_to_s(sc.tension));
      img->first_frame.push_back(static_cast<float>(k[0]));
      img->last_frame.push_back(static_cast<float>(k[n - 1]));
      img->first_value.push_back(dequantize(q[0], sc.step));
      img->last_value.push_back(dequantize(q[n - 1], sc.step));
      img->curve_linear.push_back(sc.interp == Interpolation::linear ? ~0u : 0u);
      img->curve_of[c] = static_cast<uint32_t>(img->curves.size());
      img->curves.push_back(cv);
      img->curve_channel.push_back(static_cast<uint32_t>(c));
    }
    if (pass == 0) img->block_curves = static_cast<uint32_t>(img->curves.size());
  }

  const size_t nc = img->curves.size();
  // The per-curve arrays are read 4 curves at a time: pad them to whole lanes (never "in" a
  // segment: the padding lanes are clamped constants).
  const size_t lanes = (nc + 3) & ~size_t(3);
  img->curve_s.resize(lanes, 0.0f);
  img->first_frame.resize(lanes, std::numeric_limits<float>::infinity());
  img->last_frame.resize(lanes, std::numeric_limits<float>::infinity());
  img->first_value.resize(lanes, 0.0f);
  img->last_value.resize(lanes, 0.0f);
  img->curve_linear.resize(lanes, 0u);
  img->block_count = nc == 0 ? 0 : static_cast<uint32_t>(blocks);
  const size_t nb = img->block_curves;  // records: at most 4 per key of a block curve
  const size_t records = size_t(img->block_count) * nb;
  std::vector<RecordPlan> plans(records);
  for (size_t i = 0; i < nb; ++i) {
    const Curve& cv = img->curves[i];
    const SourceChannel& sc = src.channels[img->curve_channel[i]];
    const Keys keys{src.frames.data() + sc.first_key, src.q.data() + sc.first_key, sc.key_count};
    int64_t first = 0, last = 0;  // the block's keys: [first, last)
    for (uint32_t b = 0; b < img->block_count; ++b) {
      const int64_t start = int64_t(b) << kBlockShift;
      while (first < keys.n && int64_t(keys.k[first]) < start) ++first;
      last = std::max(last, first);
      while (last < keys.n && int64_t(keys.k[last]) < start + kBlockFrames) ++last;
      plans[size_t(b) * nb + i] = plan_record(keys, first, last, start, cv.q_base, cv.base_bits);
      first = last;  // the next block's keys start where this block's end
    }
  }
  // Offsets in block-major order; u32 offsets bound the payload (checked: 2^32 bytes is far
  // beyond any clip the decoder's limits admit, but a too large one must fail, not wrap).
  img->record_offset.resize(records + kPrefetchRecords);
  uint64_t total = 0;
  for (size_t r = 0; r < records; ++r) {
    if (total > UINT32_MAX) throw std::bad_alloc();
    img->record_offset[r] = static_cast<uint32_t>(total);
    total += plans[r].size_bytes;
  }
  img->payload.assign(total + kPayloadPadding, 0);
  for (size_t i = 0; i < nb; ++i) {
    const Curve& cv = img->curves[i];
    const SourceChannel& sc = src.channels[img->curve_channel[i]];
    const Keys keys{src.frames.data() + sc.first_key, src.q.data() + sc.first_key, sc.key_count};
    for (uint32_t b = 0; b < img->block_count; ++b) {
      const size_t r = size_t(b) * nb + i;
      write_record(img->payload.data() + img->record_offset[r], keys, plans[r], int64_t(b) << kBlockShift,
                   cv.q_base, cv.base_bits);
    }
  }
  shrink(*img);
  return img;
}

}  // namespace keyanim::internal
