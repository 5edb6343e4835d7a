// The runtime side: a .kanim file loaded, validated once, and sampled at any frame or time.
// Nothing here parses BVH, encodes, or allocates while sampling.
//
// A loaded clip keeps its keys as the file's quantized integers, bit-packed by time block
// (spec/FORMAT.md, Appendix F): its memory is about that of the keys themselves, and it samples
// in place. A Clip is immutable: copies share the same image, and any number of threads may
// sample one clip at once (each with its own Cursor, or none).
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "keyanim/cardinal.h"
#include "keyanim/pose.h"
#include "keyanim/rotation.h"
#include "keyanim/skeleton.h"
#include "keyanim/status.h"

namespace keyanim {

namespace internal {
struct Image;
struct RigCacheAccess;
}

// Upper bounds a loader checks before it allocates anything a file declares.
struct DecodeLimits {
  uint32_t max_joints = 1u << 16;             // Defaults to 65536 nodes (joints + End Sites).
  uint32_t max_channels = 1u << 18;           // Defaults to 262144 channels.
  uint32_t max_frames = 1u << 24;             // Defaults to 16777216 frames, which is also the most any clip may have.
  uint64_t max_keys = 1ull << 28;             // Defaults to 268435456 keys in all.
  uint64_t max_decompressed_bytes = 1ull << 30;  // Defaults to 1 GiB of decompressed sections.
  // Defaults to 16 MiB of NOTE. Notes are informative text (keyanim writes some 400 bytes), and
  // a frame of RLE blocks makes 32768 bytes of each of its own: a 19 KB file may hold a 600 MiB
  // note, which this refuses from the section table.
  uint64_t max_note_bytes = 16ull << 20;
  // Defaults to false. A runtime-profile file (spec/FORMAT.md section 9) is checked for its
  // structure, which makes sampling it in place safe, and by its checksum. True also checks its
  // content (section 9.4: the image is exactly the one its keys make), which costs about as
  // much as loading an archive file; tools that convert or verify files set it.
  bool check_content = false;
};

// What a channel's keys hold (spec/FORMAT.md section 4.7).
enum class StoredAs : uint8_t {
  value = 0,   // the channel's own values (a position, or an Euler angle)
  quat_x = 1,  // x, y or z of its node's rotation relative to the node's reference (QuatNode):
  quat_y = 2,  // the node's three rotation channels hold these, and sample() gives its Euler
  quat_z = 3,  // angles computed from them
};

// What a channel's keys are, independent of how a loaded clip stores them.
struct ChannelInfo {
  Interpolation interp = Interpolation::cardinal;
  float tension = 0.0f;    // T in [-1, 1] (s = (1 - T) / 2); ignored by linear channels
  uint32_t key_count = 0;  // 0: all zeros; 1: constant
  StoredAs stored = StoredAs::value;
};

class Cursor;

// Clips of one rig (the same nodes, names, parents, OFFSETs and channel lists, in the same
// order: a character's clips) loaded through the same RigCache share one skeleton and the pose
// tables made from it, so that an engine holding a thousand clips of one character holds its
// skeleton once; each clip's skeleton_bytes() is then the shared rig's. Thread-safe: clips may
// be loaded through one cache from several threads. The cache holds rigs weakly (a rig lives
// as long as a clip uses it), and may be destroyed before or after the clips.
class RigCache {
 public:
  RigCache();
  ~RigCache();
  RigCache(const RigCache&) = delete;
  RigCache& operator=(const RigCache&) = delete;
  // Rigs in use by at least one clip loaded through this cache.
  size_t rig_count() const noexcept;

 private:
  friend struct internal::RigCacheAccess;
  struct State;
  std::unique_ptr<State> state_;
};

class Clip {
 public:
  Clip();  // empty: no frames, no channels
  ~Clip();
  Clip(const Clip&);
  Clip& operator=(const Clip&);
  Clip(Clip&&) noexcept;
  Clip& operator=(Clip&&) noexcept;

  // Validates `bytes` completely (see spec/FORMAT.md, "Decoder obligations") and builds the
  // image: an archive-profile file is decoded, a runtime-profile file (section 9) copied and
  // checked (DecodeLimits::check_content says how deeply). On failure `out` is left empty and `err` (if given) says which section and byte
  // offset: the absolute offset of the offending field, or, inside a zstd-compressed section,
  // the offset of the section's stored bytes (`detail` then gives the offset within the
  // decompressed content). Reads every format version from 1.0 on.
  // With `rigs`, the clip shares the cache's rig when it holds an equal one (RigCache).
  static Status load(std::span<const uint8_t> bytes, Clip& out, ErrorInfo* err = nullptr,
                     const DecodeLimits& limits = {}, RigCache* rigs = nullptr);
  // Samples a runtime-profile file (spec/FORMAT.md section 9) where it lies: checks it as
  // load() does (its structure and checksum, in time proportional to its records, not its
  // keys), then keeps pointers into `bytes` and copies nothing from them. `bytes` must start at
  // an address that is a multiple of 8 (invalid_argument otherwise) and must stay alive and
  // unchanged as long as the clip, its copies, or a Cursor prepared for it are used: memory
  // mapped from a file, or an engine's asset buffer. An archive-profile file is decoded as
  // load() does (the clip then does not use `bytes` after view() returns). The skeleton is
  // built (or found in `rigs`) as load() does.
  static Status view(std::span<const uint8_t> bytes, Clip& out, ErrorInfo* err = nullptr,
                     const DecodeLimits& limits = {}, RigCache* rigs = nullptr);
  // Reads the whole file, then load(). A file larger than limits.max_decompressed_bytes is
  // refused with limit_exceeded before it is read.
  static Status load_file(const std::string& path, Clip& out, ErrorInfo* err = nullptr,
                          const DecodeLimits& limits = {}, RigCache* rigs = nullptr);

  uint16_t version_major() const noexcept;
  // Whether the file was of the runtime profile (spec/FORMAT.md section 9), else the archive's.
  bool runtime_profile() const noexcept;
  // A runtime-profile clip's content rules (section 9.4: its image is exactly the one its keys
  // make), which load() checks only with DecodeLimits::check_content and view() never: ok, or
  // corrupt (with `err` saying so). Costs about an archive file's load. Always ok for a clip
  // built from an archive file's keys. limit_exceeded when out of memory.
  Status check_content(ErrorInfo* err = nullptr) const noexcept;
  uint16_t version_minor() const noexcept;
  uint32_t frame_count() const noexcept;
  double frame_time() const noexcept;
  // (frame_count - 1) * frame_time, or 0 for an empty clip.
  double duration() const noexcept;
  uint32_t channel_count() const noexcept;
  TangentRule tangent_rule() const noexcept;
  const Skeleton& skeleton() const noexcept;
  uint64_t total_keys() const noexcept;
  // Channel c (< channel_count()): interpolation, tension, number of keys, and what they hold.
  ChannelInfo channel(uint32_t c) const noexcept;
  // Nodes whose rotation is stored as quaternion curves (version 5: spec/FORMAT.md section 4.7),
  // in increasing node order; none in older files and in clips encoded with Euler rotations.
  uint32_t quat_node_count() const noexcept;
  QuatNode quat_node(uint32_t i) const noexcept;  // i < quat_node_count(); else a default QuatNode
  // Channel c's keys: frames (strictly increasing) and values, exactly as the sampler uses them
  // (a quaternion node's rotation channels: its stored x, y, z, channel(c).stored).
  // Both spans must hold channel(c).key_count entries (output_too_small); c >= channel_count()
  // is invalid_argument. Reads the image; meant for tools, not for a frame loop.
  Status channel_keys(uint32_t c, std::span<uint32_t> frames, std::span<float> values) const noexcept;
  // Informative encoder notes stored in the file (settings, measured error), as key=value text.
  const std::string& encoder_notes() const noexcept;
  // Bytes held by the clip's image (keys, skeleton, notes, indexes), for memory budgets:
  // skeleton_bytes() + animation_bytes(). The skeleton's part (names, parents, OFFSETs, channel
  // lists and the pose tables made from them) is the same for every clip of one rig, which an
  // engine would hold once; the animation's part (keys, records, per-channel facts, notes) is
  // the clip's own.
  // Clips loaded through one RigCache share that part (shares_rig).
  size_t memory_bytes() const noexcept;
  size_t skeleton_bytes() const noexcept;
  size_t animation_bytes() const noexcept;
  // 64-bit FNV-1a of the rig (each node's name, parent, OFFSET bits, End Site flag and channel
  // list, in node order): equal for clips of one rig, whichever file or cache they came from.
  uint64_t rig_hash() const noexcept;
  // Whether this clip and `other` hold the very same rig (loaded through one RigCache).
  bool shares_rig(const Clip& other) const noexcept;

  // Every channel at frame position f (fractional frames are in-betweens; clamped to the clip),
  // exactly as spec/FORMAT.md Appendix A computes it, with f rounded to binary32. `out` must
  // hold channel_count() values (output_too_small); a NaN position is invalid_argument. With a
  // cursor (Cursor::prepare'd for this clip, else invalid_argument) playback forward is
  // faster; the values are the same. Never allocates. A quaternion node's rotation channels
  // hold the Euler angles of its rotation in their order (Appendix B: computed in binary64
  // from the stored x, y, z, the middle angle in [-90, 90], rounded to binary32).
  Status sample(double frame_position, std::span<float> out, Cursor* cursor = nullptr) const noexcept;
  // The same, but a quaternion node's rotation channels hold its stored x, y, z (what its keys
  // interpolate: Appendix A's values), for converters that compute the angles themselves.
  Status sample_stored(double frame_position, std::span<float> out, Cursor* cursor = nullptr) const noexcept;
  // Same at a time in seconds: frame position = seconds / frame_time (0 if frame_time is 0).
  Status sample_time(double seconds, std::span<float> out, Cursor* cursor = nullptr) const noexcept;
  // Only the listed channels (e.g. one joint's), out[i] for channels[i]. A channel number
  // >= channel_count() is invalid_argument.
  Status sample_channels(double frame_position, std::span<const uint32_t> channels,
                         std::span<float> out) const noexcept;
  // One channel at frame position f into `out`: invalid_argument (and `out` unchanged) for
  // c >= channel_count() or a NaN position.
  Status sample_channel(uint32_t c, float frame_position, float& out) const noexcept;

  // Engine-ready poses (pose.h). Local: one Transform per node of skeleton() (joints and End
  // Sites, in node order): the rotation of the node's Euler channels in their order, and its
  // translation (OFFSET, with position channels replacing components: PositionReading).
  // Model: the same composed from the roots (forward kinematics). `out` must hold
  // skeleton().joints.size() transforms (output_too_small). Never allocate. Quaternions are
  // continuous in time (stored angles are unwrapped), so consecutive frames blend.
  Status sample_local(double frame_position, std::span<Transform> out, Cursor* cursor = nullptr,
                      PositionReading reading = PositionReading::replace) const noexcept;
  Status sample_model(double frame_position, std::span<Transform> out, Cursor* cursor = nullptr,
                      PositionReading reading = PositionReading::replace) const noexcept;

 private:
  friend struct ClipAccess;  // internal: the library builds clips from decoded keys
  std::shared_ptr<const internal::Image> image_;
};

// State for playback: each channel's current segment, prepared so that a position inside the
// same segments costs only the polynomial. Memory is taken by prepare(), never while sampling.
// Correctness never depends on it: sampling a clip the cursor was not prepared for is refused.
class Cursor {
 public:
  Cursor();
  ~Cursor();
  Cursor(Cursor&&) noexcept;
  Cursor& operator=(Cursor&&) noexcept;
  // Allocates the state for `clip` (and forgets any other clip). Fails only for lack of memory
  // (limit_exceeded).
  Status prepare(const Clip& clip) noexcept;
  // True if prepared for `clip` (or a copy of it).
  bool prepared_for(const Clip& clip) const noexcept;

  struct State;  // opaque

 private:
  friend class Clip;
  friend struct ClipAccess;
  std::unique_ptr<State> state_;
};

}  // namespace keyanim
