// CLIP, SKEL, CHAN and KTIM: the clip's facts, the skeleton, the channel table and the key
// frames, each checked against what came before it.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "internal/byte_reader.h"
#include "internal/format.h"
#include "internal/varint.h"
#include "keyanim/version.h"
#include "runtime/load/loader.h"

namespace keyanim::internal {

Status Loader::parse_clip(const Content& c, ClipSource& parts) {
  if (c.size != internal::kClipSize)
    return fail_in(Status::corrupt, c, 0, "CLIP must be 32 bytes, not " + std::to_string(c.size));
  ByteReader r(c.data, c.size);
  uint32_t frames = 0;
  uint8_t rule = 0, flags = 0;
  uint16_t reserved = 0;
  double frame_time = 0;
  r.read(frames);
  r.read(node_count_);
  r.read(channel_count_);
  r.read(rule);
  r.read(flags);
  r.read(reserved);
  r.read(frame_time);
  r.read(key_count_);
  if (major_ >= 3 && frames > internal::kMaxFrames)
    return fail_in(Status::corrupt, c, 0, "Frame_Count " + std::to_string(frames) + " is above 2^24");
  if (frames > std::min(limits_.max_frames, internal::kMaxFrames))
    return fail_in(Status::limit_exceeded, c, 0, "Frame_Count " + std::to_string(frames) + " exceeds the limit");
  if (node_count_ > limits_.max_joints)
    return fail_in(Status::limit_exceeded, c, 4, "Node_Count " + std::to_string(node_count_) + " exceeds the limit");
  if (channel_count_ > limits_.max_channels)
    return fail_in(Status::limit_exceeded, c, 8, "Channel_Count " + std::to_string(channel_count_) + " exceeds the limit");
  if (rule > internal::kMaxTangentRule)
    return fail_in(Status::reserved_bits_set, c, 12, "reserved Tangent_Rule " + std::to_string(rule));
  if (flags != 0) return fail_in(Status::reserved_bits_set, c, 13, "reserved Clip_Flags bits are set");
  if (reserved != 0) return fail_in(Status::reserved_bits_set, c, 14, "Clip_Reserved is not 0");
  if (!std::isfinite(frame_time) || frame_time < 0.0 || (frames > 1 && !(frame_time > 0.0)))
    return fail_in(Status::corrupt, c, 16, "Frame_Time must be finite, >= 0, and > 0 when Frame_Count > 1");
  if (key_count_ > limits_.max_keys)
    return fail_in(Status::limit_exceeded, c, 24, "Key_Count " + std::to_string(key_count_) + " exceeds the limit");
  // A key takes a byte of KTIM at least (a third of one from 5.0, where a quaternion node's
  // three curves share their key frames), and zstd makes at most kMaxZstdExpansion of each.
  const uint64_t per_byte = major_ >= kQuatFormatVersionMajor ? internal::kMaxKeysPerFileByteV5 : internal::kMaxKeysPerFileByte;
  if (key_count_ > per_byte * uint64_t(bytes_.size()))
    return fail_in(Status::corrupt, c, 24,
                   "Key_Count " + std::to_string(key_count_) + " is more than a file of " + std::to_string(bytes_.size()) +
                       " bytes can hold (at most " + std::to_string(per_byte) + " keys a byte: a key takes " +
                       (major_ >= kQuatFormatVersionMajor ? "a third of a byte" : "a byte") +
                       " of KTIM at least, and zstd makes at most " + std::to_string(internal::kMaxZstdExpansion) +
                       " bytes of each)");
  if (key_count_ > UINT32_MAX)
    return fail_in(Status::limit_exceeded, c, 24, "this decoder holds fewer than 2^32 keys");
  if (key_count_ > uint64_t(channel_count_) * frames)
    return fail_in(Status::corrupt, c, 24, "Key_Count exceeds Channel_Count x Frame_Count");
  time_count_ = key_count_;  // until QUAT and CHAN say which curves share their key frames
  parts.frame_count = frames;
  parts.frame_time = frame_time;
  parts.rule = static_cast<TangentRule>(rule);
  return Status::ok;
}

Status Loader::parse_skel(const Content& c, ClipSource& parts) {
  if (node_count_ > c.size / internal::kNodeFixedBytes)
    return fail_in(Status::corrupt, c, 0,
                   "SKEL is too short for " + std::to_string(node_count_) + " nodes");
  auto& joints = parts.skeleton.joints;
  joints.resize(node_count_);
  ByteReader r(c.data, c.size);
  uint64_t channel_sum = 0;
  for (uint32_t i = 0; i < node_count_; ++i) {
    Joint& j = joints[i];
    auto node = [i] { return "node " + std::to_string(i) + ": "; };  // built only for a message
    const size_t start = r.pos();
    uint32_t name_len = 0;
    const uint8_t* name = nullptr;
    if (!r.read(name_len) || !r.bytes(name_len, name))
      return fail_in(Status::corrupt, c, start, node() + "the name runs past the end of SKEL");
    j.name.assign(reinterpret_cast<const char*>(name), name_len);
    const size_t fixed = r.pos();
    if (r.remaining() < internal::kNodeFixedBytes - 4)
      return fail_in(Status::corrupt, c, fixed, node() + "the record runs past the end of SKEL");
    uint8_t flags = 0, count = 0;
    r.read(j.parent);
    for (double& o : j.offset) r.read(o);
    r.read(flags);
    r.read(count);
    if (j.parent < -1 || (j.parent >= 0 && static_cast<uint32_t>(j.parent) >= i))
      return fail_in(Status::corrupt, c, fixed, node() + "Parent must be -1 or an earlier node");
    if (j.parent >= 0 && joints[static_cast<size_t>(j.parent)].end_site)
      return fail_in(Status::corrupt, c, fixed, node() + "the parent is an End Site");
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(j.offset[static_cast<size_t>(k)]))
        return fail_in(Status::corrupt, c, fixed + 4 + 8 * static_cast<size_t>(k), node() + "Offset is not finite");
    if (flags & internal::kNodeReservedMask)
      return fail_in(Status::reserved_bits_set, c, fixed + 28, node() + "reserved Node_Flags bits are set");
    j.end_site = (flags & internal::kNodeEndSite) != 0;
    if (j.end_site && j.parent < 0) return fail_in(Status::corrupt, c, fixed, node() + "an End Site must have a parent");
    if (count > internal::kMaxNodeChannels)
      return fail_in(Status::corrupt, c, fixed + 29, node() + "more than 6 channels");
    if (j.end_site && count != 0) return fail_in(Status::corrupt, c, fixed + 29, node() + "an End Site has channels");
    const uint8_t* types = nullptr;
    if (!r.bytes(count, types))
      return fail_in(Status::corrupt, c, fixed + 30, node() + "the channel list runs past the end of SKEL");
    j.channels.resize(count);
    for (uint32_t k = 0; k < count; ++k) {
      if (types[k] > internal::kMaxChannelType)
        return fail_in(Status::reserved_bits_set, c, fixed + 30 + k,
                       node() + "reserved channel type " + std::to_string(types[k]));
      j.channels[k] = static_cast<ChannelType>(types[k]);
    }
    channel_sum += count;
  }
  if (!r.at_end()) return fail_in(Status::corrupt, c, r.pos(), "bytes after the last node record");
  if (channel_sum != channel_count_)
    return fail_in(Status::corrupt, c, 0,
                   "the nodes have " + std::to_string(channel_sum) + " channels, CLIP says " + std::to_string(channel_count_));
  parts.skeleton.assign_channel_columns();
  return Status::ok;
}

Status Loader::parse_quat(const Content& c, ClipSource& parts) {
  uint32_t count = 0;
  ByteReader r(c.data, c.size);
  if (!r.read(count) || count > node_count_ || c.size != internal::kQuatHeaderBytes + uint64_t(count) * internal::kQuatEntryBytes)
    return fail_in(Status::corrupt, c, 0, "QUAT must be 4 + 10 x Quat_Count bytes, Quat_Count at most Node_Count");
  parts.quat_nodes.resize(count);
  for (uint32_t i = 0; i < count; ++i) {
    QuatNode& n = parts.quat_nodes[i];
    const size_t at = r.pos();
    r.read(n.node);
    for (int16_t& x : n.reference) r.read(x);
    const std::string entry = "QUAT entry " + std::to_string(i) + ": ";
    if (n.node >= node_count_ || (i > 0 && n.node <= parts.quat_nodes[i - 1].node))
      return fail_in(Status::corrupt, c, at, entry + "Node must be a node, in increasing order");
    if (!quaternion_capable(parts.skeleton.joints[n.node]))
      return fail_in(Status::corrupt, c, at, entry + "the node must have three consecutive rotation channels about three axes");
    if (!internal::valid_reference(n.reference))
      return fail_in(Status::corrupt, c, at + 4, entry + "Reference's x^2 + y^2 + z^2 must be at most 2^30");
  }
  return Status::ok;
}

Status Loader::parse_chan(const Content& c, ClipSource& parts) {
  const uint64_t channels = channel_count_;
  const size_t per_channel = major_ >= 3   ? internal::kChanBytesPerChannel
                             : major_ == 2 ? internal::kChanBytesPerChannelV2
                                           : internal::kChanBytesPerChannelV1;
  if (c.size != channels * per_channel)
    return fail_in(Status::corrupt, c, 0, "CHAN must be " + std::to_string(per_channel) + " x Channel_Count bytes");
  const uint8_t* p = c.data;
  parts.channels.resize(channels);
  codings_.assign(channels, internal::ValueCoding::delta);
  residual_bytes_.assign(channels, 0);
  uint64_t key_sum = 0;
  for (uint64_t i = 0; i < channels; ++i) {
    const std::string ch = "channel " + std::to_string(i) + ": ";
    const size_t at_interp = i, at_tension = channels + 4 * i, at_step = 5 * channels + 8 * i,
                 at_count = 13 * channels + 4 * i;
    const uint8_t interp = p[at_interp];
    const float tension = internal::load_le<float>(p + at_tension);
    const double step = internal::load_le<double>(p + at_step);
    const uint32_t count = internal::load_le<uint32_t>(p + at_count);
    if (interp > internal::kMaxInterpolation)
      return fail_in(Status::reserved_bits_set, c, at_interp, ch + "reserved Interpolation " + std::to_string(interp));
    if (!std::isfinite(tension) || tension < -1.0f || tension > 1.0f)
      return fail_in(Status::corrupt, c, at_tension, ch + "Tension must be finite and in [-1, 1]");
    if (!std::isfinite(step) || !(step > 0.0))
      return fail_in(Status::corrupt, c, at_step, ch + "Step must be finite and > 0");
    if (count > parts.frame_count)
      return fail_in(Status::corrupt, c, at_count, ch + "more keys than frames");
    if (major_ >= 2) {
      const size_t at_coding = 17 * channels + i;
      if (p[at_coding] > internal::kMaxValueCoding)
        return fail_in(Status::reserved_bits_set, c, at_coding, ch + "reserved Value_Coding " + std::to_string(p[at_coding]));
      codings_[i] = static_cast<internal::ValueCoding>(p[at_coding]);
    }
    if (major_ >= 3) {
      const size_t at_bytes = 18 * channels + i;
      residual_bytes_[i] = p[at_bytes];
      if (residual_bytes_[i] > internal::kMaxResidualBytes || (count == 0 && residual_bytes_[i] != 0))
        return fail_in(Status::corrupt, c, at_bytes, ch + "Residual_Bytes must be at most 8, and 0 without keys");
    }
    internal::SourceChannel& t = parts.channels[i];
    t.first_key = key_sum;
    t.key_count = count;
    t.interp = static_cast<Interpolation>(interp);
    t.tension = tension;
    t.step = step;
    key_sum += count;
    if (key_sum > key_count_)
      return fail_in(Status::corrupt, c, at_count, ch + "the channels' Key_Count add up to more than CLIP's");
  }
  if (key_sum != key_count_)
    return fail_in(Status::corrupt, c, 13 * channels, "the channels' Key_Count add up to less than CLIP's");
  // A quaternion node's x, y and z: one interpolation, tension and key count (section 4.7).
  kinds_ = internal::stored_kinds(parts.skeleton, parts.quat_nodes);
  for (uint64_t i = 0; i < channels; ++i) {
    if (kinds_[i] != internal::Stored::quat_y && kinds_[i] != internal::Stored::quat_z) continue;
    const SourceChannel& x = parts.channels[i - (kinds_[i] == internal::Stored::quat_y ? 1 : 2)];
    const SourceChannel& t = parts.channels[i];
    if (t.interp != x.interp || std::memcmp(&t.tension, &x.tension, sizeof(float)) != 0 || t.key_count != x.key_count)
      return fail_in(Status::corrupt, c, i, "channel " + std::to_string(i) +
                                                ": a quaternion node's y and z must have its x's Interpolation, Tension and Key_Count");
    time_count_ -= t.key_count;
  }
  return Status::ok;
}

const char* varint_problem(internal::VarintError e) {
  switch (e) {
    case internal::VarintError::cut: return "a varint runs past the end of the section";
    case internal::VarintError::overlong: return "an over-long varint";
    case internal::VarintError::too_big: return "a varint too large for its field";
    case internal::VarintError::none: break;
  }
  return "";
}

Status Loader::parse_ktim(const Content& c, ClipSource& parts) {
  if (time_count_ > c.size) return fail_in(Status::corrupt, c, 0, "KTIM is too short for its key frames' varints");
  parts.frames.resize(static_cast<size_t>(key_count_));
  uint32_t* out = parts.frames.data();
  const uint64_t frames = parts.frame_count;
  size_t pos = 0;
  for (size_t ch = 0; ch < parts.channels.size(); ++ch) {
    const internal::SourceChannel& t = parts.channels[ch];
    if (kinds_[ch] == internal::Stored::quat_y || kinds_[ch] == internal::Stored::quat_z) {  // x's frames
      const internal::SourceChannel& x = parts.channels[ch - (kinds_[ch] == internal::Stored::quat_y ? 1 : 2)];
      std::copy_n(out + x.first_key, t.key_count, out + t.first_key);
      continue;
    }
    uint64_t frame = 0;
    for (uint32_t i = 0; i < t.key_count; ++i) {
      const size_t at = pos;
      uint64_t v = 0;
      if (pos < c.size && c.data[pos] < 0x80) {
        v = c.data[pos++];  // the usual one-byte gap
      } else {
        const auto e = internal::get_varint(c.data, c.size, pos, internal::kMaxVarint32Bytes, v);
        if (e != internal::VarintError::none) return fail_in(Status::corrupt, c, at, varint_problem(e));
      }
      frame = i == 0 ? v : frame + v + 1;  // < 2^33: no overflow
      if (frame >= frames)
        return fail_in(Status::corrupt, c, at,
                       "channel " + std::to_string(ch) + ": key frame " + std::to_string(frame) + " >= Frame_Count");
      out[t.first_key + i] = static_cast<uint32_t>(frame);
    }
  }
  if (pos != c.size) return fail_in(Status::corrupt, c, pos, "bytes after the last key frame");
  return Status::ok;
}

}  // namespace keyanim::internal
