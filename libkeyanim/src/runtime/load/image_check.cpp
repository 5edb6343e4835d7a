// IMAG, the runtime profile's image (spec/FORMAT.md sections 9.2 to 9.4): every structure rule,
// in time proportional to the channels, curves, list keys and records (not the keys), after
// which the sampler may read the bytes in place.
#include <algorithm>
#include <cmath>
#include <limits>
#include <cstring>
#include <string>
#include <vector>

#include "internal/byte_reader.h"
#include "internal/format.h"
#include "keyanim/cardinal.h"
#include "runtime/image.h"
#include "keyanim/version.h"
#include "runtime/load/loader.h"

namespace keyanim::internal {
namespace {

using L = ImageLayout;

template <class T>
T at_index(const Content& c, const ImageLayout& lay, L::Array a, uint64_t i) noexcept {
  T v;
  std::memcpy(&v, c.data + lay.at[a] + i * sizeof(T), sizeof(T));
  return v;
}

uint32_t float_bits(float f) noexcept {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

bool same_bits(float a, float b) noexcept { return float_bits(a) == float_bits(b); }

const char* const kArrayNames[L::kArrays] = {
    "Interpolation", "Tension", "Key_Count", "Curve_Of", "Fixed_Value", "Fixed_Frame", "Fixed_Channels",
    "Curves", "Curve_S", "First_Frame", "Last_Frame", "First_Value", "Last_Value", "Curve_Linear",
    "Curve_Channel", "Quat_Node", "Quat_Column", "Quat_Reference", "Lists", "List_Frames", "List_Values",
    "List_Q", "Record_Offset", "Payload"};

}  // namespace

// The checks, in section 9.2's order (`entry` names an array's entry i, `where` gives its byte offset). `skeleton`: SKEL's
// (parsed, or a cached rig's), which the quaternion nodes are checked against.
Status Loader::check_image(const Content& c, const ClipSource& parts, const Skeleton& skeleton) {
  const uint64_t frames = parts.frame_count, channels = channel_count_;
  if (c.size < kImageHeaderBytes) return fail_in(Status::corrupt, c, 0, "IMAG is shorter than its 32-byte header");
  uint32_t h[8];
  std::memcpy(h, c.data, sizeof h);
  if (h[0] != kBlockShift) return fail_in(Status::corrupt, c, 0, "Block_Shift must be 6, not " + std::to_string(h[0]));
  if (major_ < kQuatFormatVersionMajor && (h[6] != 0 || h[7] != 0))
    return fail_in(Status::reserved_bits_set, c, 24, "Image_Reserved is not 0");
  const ImageCounts n = image_counts({c.data, c.size}, static_cast<uint32_t>(channels));
  if (n.curves > channels)
    return fail_in(Status::corrupt, c, 4, "Curve_Count " + std::to_string(n.curves) + " is above Channel_Count");
  if (n.block_curves > n.curves) return fail_in(Status::corrupt, c, 8, "Block_Curve_Count is above Curve_Count");
  if (n.quat_nodes > skeleton.joints.size())
    return fail_in(Status::corrupt, c, 24, "Quat_Count " + std::to_string(n.quat_nodes) + " is above Node_Count");
  if (n.quat_tracks > n.quat_nodes || 3 * n.quat_tracks > n.block_curves)
    return fail_in(Status::corrupt, c, 28, "Quat_Track_Count is above Quat_Count, or its curves above Block_Curve_Count");
  const uint64_t blocks_of_clip = (frames + kBlockFrames - 1) / kBlockFrames;
  if (n.blocks != (n.curves > 0 ? blocks_of_clip : 0))
    return fail_in(Status::corrupt, c, 12, "Block_Count must be " + std::to_string(n.curves > 0 ? blocks_of_clip : 0));
  const ImageLayout lay(n);
  if (c.size != lay.end())
    return fail_in(Status::corrupt, c, 0,
                   "IMAG is " + std::to_string(c.size) + " bytes; its counts make " + std::to_string(lay.end()));
  for (uint32_t a = 0; a < L::kArrays; ++a)
    for (uint64_t p = lay.at[a] + lay.used[a]; p < lay.at[a + 1]; ++p)
      if (c.data[p] != 0) return fail_in(Status::corrupt, c, p, std::string(kArrayNames[a]) + "'s padding is not zero");
  auto where = [&](L::Array a, uint64_t i, uint64_t width) { return lay.at[a] + i * width; };
  auto entry = [&](L::Array a, uint64_t i) { return std::string(kArrayNames[a]) + "[" + std::to_string(i) + "]"; };

  // Channels.
  uint64_t keys = 0, fixed = 0;
  for (uint64_t ch = 0; ch < channels; ++ch) {
    const uint8_t interp = c.data[lay.at[L::interpolation] + ch];
    if (interp > kMaxInterpolation)
      return fail_in(Status::reserved_bits_set, c, where(L::interpolation, ch, 1), entry(L::interpolation, ch) + " is reserved");
    const float t = at_index<float>(c, lay, L::tension, ch);
    if (!std::isfinite(t) || t < -1.0f || t > 1.0f)
      return fail_in(Status::corrupt, c, where(L::tension, ch, 4), entry(L::tension, ch) + " is not in [-1, 1]");
    const uint32_t k = at_index<uint32_t>(c, lay, L::key_count, ch);
    if (k > frames) return fail_in(Status::corrupt, c, where(L::key_count, ch, 4), entry(L::key_count, ch) + " is above Frame_Count");
    keys += k;
    const uint32_t curve = at_index<uint32_t>(c, lay, L::curve_of, ch);
    const float fv = at_index<float>(c, lay, L::fixed_value, ch);
    const uint32_t ff = at_index<uint32_t>(c, lay, L::fixed_frame, ch);
    const bool ok = k >= 2 ? curve < n.curves && at_index<uint32_t>(c, lay, L::curve_channel, curve) == ch && float_bits(fv) == 0 && ff == 0
                    : k == 1 ? curve == kNoCurve && std::isfinite(fv) && ff < frames
                             : curve == kNoCurve && float_bits(fv) == 0 && ff == 0;
    if (!ok)
      return fail_in(Status::corrupt, c, where(L::curve_of, ch, 4),
                     "channel " + std::to_string(ch) + " of " + std::to_string(k) +
                         " keys: its Curve_Of, Fixed_Value and Fixed_Frame break section 9.2's rules");
    if (k < 2) {
      if (fixed >= channels - n.curves || at_index<uint32_t>(c, lay, L::fixed_channels, fixed) != ch)
        return fail_in(Status::corrupt, c, where(L::fixed_channels, std::min(fixed, channels - n.curves), 4),
                       "Fixed_Channels must list the channels of fewer than 2 keys, in order");
      ++fixed;
    }
  }
  if (keys != key_count_) return fail_in(Status::corrupt, c, lay.at[L::key_count], "the channels' Key_Count do not sum to CLIP's");
  if (fixed != channels - n.curves)
    return fail_in(Status::corrupt, c, lay.at[L::fixed_channels], "Fixed_Channels must list the channels of fewer than 2 keys");
  if (Status s = check_image_curves(c, lay, n, parts); s != Status::ok) return s;
  if (Status s = check_image_quats(c, lay, n, parts, skeleton); s != Status::ok) return s;
  return check_image_records(c, lay, n, parts);
}

// Version 5: the quaternion nodes (section 4.7's rules on the skeleton and the channels), their
// order (the tracks first), and the tracks' curves at the head of the curves (9.2).
Status Loader::check_image_quats(const Content& c, const ImageLayout& lay, const ImageCounts& n,
                                 const ClipSource& parts, const Skeleton& skeleton) {
  const uint64_t blocks_of_clip = (uint64_t(parts.frame_count) + kBlockFrames - 1) / kBlockFrames;
  const uint64_t lanes = L::lanes(n.quat_nodes), T = n.quat_tracks;
  struct Listed {
    uint32_t node, column;
  };
  std::vector<Listed> nodes(n.quat_nodes);
  for (uint64_t i = 0; i < lanes; ++i) {
    float ref[4];
    for (uint64_t k = 0; k < 4; ++k) ref[k] = at_index<float>(c, lay, L::quat_reference, k * lanes + i);
    const uint64_t ref_at = lay.at[L::quat_reference] + 4 * i;
    if (i >= n.quat_nodes) {
      if (float_bits(ref[0]) != 0 || float_bits(ref[1]) != 0 || float_bits(ref[2]) != 0 || ref[3] != 1.0f)
        return fail_in(Status::corrupt, c, ref_at, "quaternion lane " + std::to_string(i) + " is padding, and must be (0, 0, 0, 1)");
      continue;
    }
    const uint32_t node = at_index<uint32_t>(c, lay, L::quat_node, i);
    const uint64_t node_at = lay.at[L::quat_node] + 4 * i;
    // The tracks (nodes whose curves are block curves) first, then the others, each increasing.
    const bool ordered = i == 0 || i == T || node > nodes[i - 1].node;
    uint32_t first = 0;
    if (node >= skeleton.joints.size() || !ordered || !quaternion_capable(skeleton.joints[node], &first))
      return fail_in(Status::corrupt, c, node_at, "Quat_Node[" + std::to_string(i) + "] must be a node with three consecutive rotation channels about three axes, the tracks' first, each group increasing");
    const uint32_t column = skeleton.joints[node].first_channel + first;
    if (at_index<uint32_t>(c, lay, L::quat_column, i) != column)
      return fail_in(Status::corrupt, c, lay.at[L::quat_column] + 4 * i, "Quat_Column[" + std::to_string(i) + "] is not its node's first rotation channel");
    const uint32_t keys = at_index<uint32_t>(c, lay, L::key_count, column);
    if ((keys >= 2 && !is_list_curve(keys, blocks_of_clip)) != (i < T))
      return fail_in(Status::corrupt, c, node_at, "Quat_Node[" + std::to_string(i) + "]: the first Quat_Track_Count nodes must be those whose curves are block curves");
    for (uint32_t k = 0; i < T && k < kTrackCurves; ++k)
      if (at_index<uint32_t>(c, lay, L::curve_channel, i + k * T) != column + k)
        return fail_in(Status::corrupt, c, lay.at[L::curve_channel] + 4 * (i + k * T), "quaternion track " + std::to_string(i) + "'s curves must be t, T + t, 2T + t");
    nodes[i] = {node, column};
    QuatNode q;
    if (!reference_from_floats(ref, q))
      return fail_in(Status::corrupt, c, ref_at, "Quat_Reference " + std::to_string(i) + " is not a reference's binary32 quaternion (section 9.2)");
  }
  // No node twice. Sorted by node (then place), a repeat follows its node's first entry; the
  // one reported is the first entry of Quat_Node that repeats an earlier one.
  std::vector<uint32_t> order(n.quat_nodes);
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return nodes[a].node < nodes[b].node || (nodes[a].node == nodes[b].node && a < b); });
  uint64_t repeat = n.quat_nodes;
  for (size_t j = 1; j < order.size(); ++j)
    if (nodes[order[j]].node == nodes[order[j - 1]].node) repeat = std::min<uint64_t>(repeat, order[j]);
  if (repeat < n.quat_nodes)
    return fail_in(Status::corrupt, c, lay.at[L::quat_node] + 4 * repeat, "Quat_Node lists node " + std::to_string(nodes[repeat].node) + " twice");
  // Each node's y and z (channels column + 1, + 2) against its x, in channel order.
  for (const uint32_t i : order) {
    const uint64_t x = nodes[i].column;
    for (uint64_t ch = x + 1; ch <= x + 2; ++ch) {
      if (c.data[lay.at[L::interpolation] + ch] != c.data[lay.at[L::interpolation] + x] ||
          at_index<uint32_t>(c, lay, L::tension, ch) != at_index<uint32_t>(c, lay, L::tension, x) ||
          at_index<uint32_t>(c, lay, L::key_count, ch) != at_index<uint32_t>(c, lay, L::key_count, x))
        return fail_in(Status::corrupt, c, lay.at[L::key_count] + 4 * ch, "channel " + std::to_string(ch) + ": a quaternion node's y and z must have its x's Interpolation, Tension and Key_Count");
      if (Status s = check_shared_frames(c, lay, n, ch, x); s != Status::ok) return s;
    }
  }
  return Status::ok;
}

// A quaternion node's y or z (channel ch) keys the frames its x (channel x) keys (4.3, 4.4): the
// same Fixed_Frame, or the same List_Frames (a block track's record has one mask for the three).
// Called once the curves and lists are checked, with equal Key_Count.
Status Loader::check_shared_frames(const Content& c, const ImageLayout& lay, const ImageCounts& n, uint64_t ch,
                                   uint64_t x) {
  const uint32_t keys = at_index<uint32_t>(c, lay, L::key_count, ch);
  if (keys == 1 && at_index<uint32_t>(c, lay, L::fixed_frame, ch) != at_index<uint32_t>(c, lay, L::fixed_frame, x))
    return fail_in(Status::corrupt, c, lay.at[L::fixed_frame] + 4 * ch, "channel " + std::to_string(ch) + ": a quaternion node's y and z must have its x's Fixed_Frame");
  const uint32_t curve = at_index<uint32_t>(c, lay, L::curve_of, ch), xcurve = at_index<uint32_t>(c, lay, L::curve_of, x);
  if (keys < 2 || curve < n.block_curves) return Status::ok;
  const uint64_t j = curve - n.block_curves, xj = xcurve - n.block_curves;
  const uint32_t first = at_index<uint32_t>(c, lay, L::lists, 2 * j), xfirst = at_index<uint32_t>(c, lay, L::lists, 2 * xj);
  for (uint32_t e = 0; e < keys; ++e)
    if (at_index<uint32_t>(c, lay, L::list_frames, first + e) != at_index<uint32_t>(c, lay, L::list_frames, xfirst + e))
      return fail_in(Status::corrupt, c, lay.at[L::list_frames] + 4 * (uint64_t(first) + e), "channel " + std::to_string(ch) + ": a quaternion node's y and z must have its x's List_Frames");
  return Status::ok;
}

// Curve facts, padding lanes and lists.
Status Loader::check_image_curves(const Content& c, const ImageLayout& lay, const ImageCounts& n, const ClipSource& parts) {
  const uint64_t frames = parts.frame_count;
  const uint64_t blocks_of_clip = (frames + kBlockFrames - 1) / kBlockFrames;
  const float inf = std::numeric_limits<float>::infinity();
  uint64_t list_first = 0;
  for (uint64_t i = 0; i < L::lanes(n.curves); ++i) {
    const float s = at_index<float>(c, lay, L::curve_s, i), f0 = at_index<float>(c, lay, L::first_frame, i),
                f1 = at_index<float>(c, lay, L::last_frame, i), v0 = at_index<float>(c, lay, L::first_value, i),
                v1 = at_index<float>(c, lay, L::last_value, i);
    const uint32_t lin = at_index<uint32_t>(c, lay, L::curve_linear, i);
    const uint64_t at = lay.at[L::curve_s] + 4 * i;
    if (i >= n.curves) {
      if (float_bits(s) != 0 || f0 != inf || f1 != inf || float_bits(v0) != 0 || float_bits(v1) != 0 || lin != 0)
        return fail_in(Status::corrupt, c, at, "curve lane " + std::to_string(i) + " is padding, and must be 0 (frames +inf)");
      continue;
    }
    const uint32_t ch = at_index<uint32_t>(c, lay, L::curve_channel, i);
    const uint64_t ch_at = lay.at[L::curve_channel] + 4 * i;
    if (ch >= channel_count_ || at_index<uint32_t>(c, lay, L::curve_of, ch) != i)
      return fail_in(Status::corrupt, c, ch_at, "Curve_Channel[" + std::to_string(i) + "] is not a channel whose Curve_Of is it");
    // (The quaternion tracks' curves, [0, 3T), are checked with the quaternion nodes.)
    const bool first_of_kind = i <= 3 * n.quat_tracks || i == n.block_curves;
    if (!first_of_kind && at_index<uint32_t>(c, lay, L::curve_channel, i - 1) >= ch)
      return fail_in(Status::corrupt, c, ch_at, "curves must be in increasing channel order (the quaternion tracks', then block curves, then list curves)");
    const uint32_t k = at_index<uint32_t>(c, lay, L::key_count, ch);
    if (is_list_curve(k, blocks_of_clip) != (i >= n.block_curves))
      return fail_in(Status::corrupt, c, ch_at, "curve " + std::to_string(i) + " is a list curve exactly when 4 x its keys < the blocks");
    const uint64_t cv_at = lay.at[L::curves] + uint64_t(kCurveBytes) * i;
    int64_t q_base;
    double step;
    uint32_t base_bits, reserved;
    std::memcpy(&q_base, c.data + cv_at, 8);
    std::memcpy(&step, c.data + cv_at + 8, 8);
    std::memcpy(&base_bits, c.data + cv_at + 16, 4);
    std::memcpy(&reserved, c.data + cv_at + 20, 4);
    if (reserved != 0) return fail_in(Status::reserved_bits_set, c, cv_at + 20, "Curve_Reserved is not 0");
    if (q_base > kMaxAbsQ || q_base < -kMaxAbsQ || !std::isfinite(step) || !(step > 0.0) || base_bits > kMaxValueBits)
      return fail_in(Status::corrupt, c, cv_at, "curve " + std::to_string(i) + ": Q_Base, Step or Base_Bits out of range");
    const bool linear = c.data[lay.at[L::interpolation] + ch] == uint8_t(Interpolation::linear);
    if (!same_bits(s, tension_to_s(at_index<float>(c, lay, L::tension, ch))) || lin != (linear ? ~0u : 0u))
      return fail_in(Status::corrupt, c, at, "curve " + std::to_string(i) + ": Curve_S or Curve_Linear disagrees with its channel");
    if (!(f0 >= 0.0f && f0 < f1 && f1 < float(frames)) || f0 != std::floor(f0) || f1 != std::floor(f1) ||
        !std::isfinite(v0) || !std::isfinite(v1))
      return fail_in(Status::corrupt, c, lay.at[L::first_frame] + 4 * i, "curve " + std::to_string(i) + ": First_Frame, Last_Frame, First_Value or Last_Value out of range");
    if (i < n.block_curves) continue;
    // A list: its span, then its keys (O(list keys)).
    const uint64_t j = i - n.block_curves, span_at = lay.at[L::lists] + 8 * j;
    const uint32_t first = at_index<uint32_t>(c, lay, L::lists, 2 * j), count = at_index<uint32_t>(c, lay, L::lists, 2 * j + 1);
    if (first != list_first || count != k || uint64_t(count) > n.list_keys - list_first)
      return fail_in(Status::corrupt, c, span_at, "Lists[" + std::to_string(j) + "] must follow the previous list and hold its channel's keys");
    list_first += count;
    for (uint64_t e = first; e < list_first; ++e) {
      const uint32_t fr = at_index<uint32_t>(c, lay, L::list_frames, e);
      const int64_t q = at_index<int64_t>(c, lay, L::list_q, e);
      const float v = at_index<float>(c, lay, L::list_values, e);
      if (fr >= frames || (e > first && fr <= at_index<uint32_t>(c, lay, L::list_frames, e - 1)))
        return fail_in(Status::corrupt, c, lay.at[L::list_frames] + 4 * e, "List_Frames[" + std::to_string(e) + "] is not increasing, or not below Frame_Count");
      if (q > kMaxAbsQ || q < -kMaxAbsQ || !std::isfinite(v) || !same_bits(v, dequantize(q, step)))
        return fail_in(Status::corrupt, c, lay.at[L::list_q] + 8 * e, "List_Q[" + std::to_string(e) + "] or its List_Values is out of range or disagrees");
    }
    const uint64_t last = list_first - 1;
    if (f0 != float(at_index<uint32_t>(c, lay, L::list_frames, first)) || f1 != float(at_index<uint32_t>(c, lay, L::list_frames, last)) ||
        !same_bits(v0, at_index<float>(c, lay, L::list_values, first)) || !same_bits(v1, at_index<float>(c, lay, L::list_values, last)))
      return fail_in(Status::corrupt, c, lay.at[L::first_frame] + 4 * i, "curve " + std::to_string(i) + ": its first or last key disagrees with its list");
  }
  if (list_first != n.list_keys) return fail_in(Status::corrupt, c, lay.at[L::lists], "the lists' counts do not sum to List_Key_Count");
  return Status::ok;
}

// Records, block after block (Record_Offset's order), track after track: offsets, sizes, widths,
// zero bits, masks, window order; per curve the popcounts and the first and last key.
Status Loader::check_image_records(const Content& c, const ImageLayout& lay, const ImageCounts& n,
                                   const ClipSource& parts) {
  const uint64_t frames = parts.frame_count, nb = n.block_curves, nt = n.block_tracks(), T = n.quat_tracks;
  const uint8_t* payload = c.data + lay.at[L::payload];
  const uint64_t payload_at = lay.at[L::payload];
  std::vector<uint32_t> seen(nb, 0);        // keys so far
  std::vector<int64_t> last_key(nb, -1);    // the last key's frame so far
  uint64_t running = 0;
  auto curve_at = [&](uint64_t i) { return lay.at[L::curves] + uint64_t(kCurveBytes) * i; };
  for (uint64_t b = 0; b < n.blocks; ++b) {
    const int64_t start = int64_t(b) << kBlockShift;
    const uint64_t beyond = frames - uint64_t(start) >= kBlockFrames ? 0 : ~uint64_t(0) << (frames - uint64_t(start));
    for (uint64_t t = 0; t < nt; ++t) {
      const uint64_t r = b * nt + t;
      const uint32_t curves = t < T ? kTrackCurves : 1;
      uint64_t curve[kTrackCurves] = {t < T ? t : t + 2 * T, T + t, 2 * T + t};  // its x, y, z, or its one
      auto record = [r] { return "record " + std::to_string(r); };  // made only for a message
      const uint64_t off_at = lay.at[L::record_offset] + 4 * r;
      if (at_index<uint32_t>(c, lay, L::record_offset, r) != running)
        return fail_in(Status::corrupt, c, off_at, "Record_Offset[" + std::to_string(r) + "] must be " + std::to_string(running) + ", where the previous record ends");
      const uint32_t header = (curves == 1 ? kRecordBitsAt : kTrackRecordBitsAt) / 8;
      if (n.payload - running < header) return fail_in(Status::corrupt, c, off_at, record() + " starts past the payload's end");
      const uint8_t* rec = payload + running;
      uint64_t mask;
      std::memcpy(&mask, rec, 8);
      const uint32_t kw = rec[header - 1];
      for (uint32_t k = 0; k < curves; ++k)
        if (rec[8 + k] > kMaxValueBits)
          return fail_in(Status::corrupt, c, payload_at + running + 8 + k, record() + ": Value_Bits above 55");
      if (kw > kMaxContextBits)
        return fail_in(Status::corrupt, c, payload_at + running + header - 1, record() + ": Context_Bits above 31");
      if (mask & beyond) return fail_in(Status::corrupt, c, payload_at + running, record() + ": a key at or after Frame_Count");
      uint32_t base_bits[kTrackCurves];
      for (uint32_t k = 0; k < curves; ++k) base_bits[k] = load_le<uint32_t>(c.data + curve_at(curve[k]) + 16);
      const uint64_t bits = curve_fields(rec, 0, curves, base_bits).end;  // the widths read are within the payload
      const uint64_t size = (bits + 7) / 8;
      if (size > n.payload - running) return fail_in(Status::corrupt, c, payload_at + running, record() + " runs past the payload's end");
      if ((bits & 7) != 0 && (rec[size - 1] >> (bits & 7)) != 0)
        return fail_in(Status::corrupt, c, payload_at + running + size - 1, record() + ": the bits after its last field are not zero");
      const uint32_t m = static_cast<uint32_t>(__builtin_popcountll(mask));
      int32_t e[4];
      read_context(rec, header, kw, e);  // relative to the block's start; e[2], e[3] already + 64
      // The window's frames increase: two before the block's keys, its keys, two after them
      // (virtual keys beyond the curve's ends may lie inside the block).
      const int32_t lo = m > 0 ? low_bit(mask) : e[2], hi = m > 0 ? top_bit(mask) : e[1];
      if (!(e[0] < e[1] && e[1] < lo && hi < e[2] && e[2] < e[3]))
        return fail_in(Status::corrupt, c, payload_at + running + header,
                       record() + ": its context frames are not two before and two after the block's keys, increasing");
      for (uint32_t k = 0; k < curves; ++k) {
        const uint64_t i = curve[k];
        const CurveFields f = curve_fields(rec, k, curves, base_bits);
        const int64_t base = static_cast<int64_t>(read_bits(rec, f.base_at, base_bits[k]));
        if (load_le<int64_t>(c.data + curve_at(i)) + base > kMaxAbsQ)
          return fail_in(Status::corrupt, c, payload_at + running + header, record() + ": Q_Base + Base is above 2^53");
        if (m == 0) continue;
        const float f0 = at_index<float>(c, lay, L::first_frame, i);
        if (seen[i] == 0 && f0 != float(start + low_bit(mask)))
          return fail_in(Status::corrupt, c, lay.at[L::first_frame] + 4 * i, "curve " + std::to_string(i) + ": First_Frame is not its first key");
        seen[i] += m;
        last_key[i] = start + top_bit(mask);
      }
      running += size;
    }
  }
  if (running != n.payload) return fail_in(Status::corrupt, c, 20, "the records end at " + std::to_string(running) + ", not at Payload_Size");
  for (uint64_t i = 0; i < nb; ++i) {
    const uint32_t ch = at_index<uint32_t>(c, lay, L::curve_channel, i);
    if (seen[i] != at_index<uint32_t>(c, lay, L::key_count, ch))
      return fail_in(Status::corrupt, c, lay.at[L::key_count] + 4 * ch, "curve " + std::to_string(i) + "'s records hold " + std::to_string(seen[i]) + " keys, not its Key_Count");
    if (at_index<float>(c, lay, L::last_frame, i) != float(last_key[i]))
      return fail_in(Status::corrupt, c, lay.at[L::last_frame] + 4 * i, "curve " + std::to_string(i) + ": Last_Frame is not its last key");
  }
  const uint64_t records = n.blocks * nt;
  for (uint64_t r = records; r < records + kImageTailEntries; ++r)
    if (at_index<uint32_t>(c, lay, L::record_offset, r) != 0)
      return fail_in(Status::corrupt, c, lay.at[L::record_offset] + 4 * r, "Record_Offset's 8 extra entries must be 0");
  for (uint64_t p = n.payload; p < n.payload + kImageTailEntries; ++p)
    if (payload[p] != 0) return fail_in(Status::corrupt, c, payload_at + p, "the payload's 8 extra bytes must be 0");
  return Status::ok;
}

}  // namespace keyanim::internal
