// The arithmetic of IMAG, the runtime profile's image (spec/FORMAT.md section 9.2), in one
// place: from the counts in its header, where each array starts and how long the section is.
// The image builder writes by it, the viewer checks and reads by it.
#pragma once
#include <cstddef>
#include <cstdint>

namespace keyanim::internal {

inline constexpr uint32_t kImageHeaderBytes = 32;
inline constexpr uint32_t kCurveBytes = 24;     // Q_Base i64, Step f64, Base_Bits u32, reserved u32
inline constexpr uint32_t kImageTailEntries = 8;  // Record_Offset's and Payload's extra entries

// The counts of IMAG's header and CLIP's channel count.
struct ImageCounts {
  uint64_t channels = 0;      // C
  uint64_t curves = 0;        // nc
  uint64_t block_curves = 0;  // nb
  uint64_t blocks = 0;        // B
  uint64_t list_keys = 0;     // M
  uint64_t payload = 0;       // P
  // Version 5: quaternion nodes (Q), of which T quaternion tracks (their three curves are block
  // curves, with one record per block for the three). Version 4 has none: Q = T = 0.
  uint64_t quat_nodes = 0;
  uint64_t quat_tracks = 0;
  // Block tracks, one record each per block: the T quaternion tracks, then every other block
  // curve alone (needs 3 T <= block_curves).
  uint64_t block_tracks() const noexcept { return block_curves - 2 * quat_tracks; }
};

// Byte offsets of the arrays from IMAG's first byte, in section 9.2's order; `end` is Raw_Size.
// Every count is below 2^32, so no sum below overflows 64 bits.
struct ImageLayout {
  enum Array : uint32_t {
    interpolation, tension, key_count, curve_of, fixed_value, fixed_frame, fixed_channels, curves,
    curve_s, first_frame, last_frame, first_value, last_value, curve_linear, curve_channel, quat_node,
    quat_column, quat_reference, lists, list_frames, list_values, list_q, record_offset, payload, kArrays
  };
  uint64_t at[kArrays + 1];  // at[kArrays] is the end
  uint64_t used[kArrays];    // each array's bytes without its padding
  uint64_t end() const noexcept { return at[kArrays]; }

  static uint64_t pad8(uint64_t n) noexcept { return (n + 7) & ~uint64_t(7); }
  static uint64_t lanes(uint64_t curves) noexcept { return (curves + 3) & ~uint64_t(3); }

  // Needs curves <= channels, block_curves <= curves and 3 quat_tracks <= block_curves (version
  // 4: no quaternion node, and the version 5 arrays are empty).
  explicit ImageLayout(const ImageCounts& n) noexcept {
    const uint64_t c = n.channels, l = lanes(n.curves), q = n.quat_nodes;
    const uint64_t bytes[kArrays] = {  // section 9.2's table, row by row
        c,     4 * c, 4 * c,                    4 * c,  4 * c,  4 * c,  4 * (c - n.curves), kCurveBytes * n.curves,
        4 * l, 4 * l, 4 * l,                    4 * l,  4 * l,  4 * l,  4 * n.curves,
        4 * q, 4 * q, 16 * lanes(q),
        8 * (n.curves - n.block_curves),
        4 * n.list_keys, 4 * n.list_keys, 8 * n.list_keys,
        4 * (n.blocks * n.block_tracks() + kImageTailEntries), n.payload + kImageTailEntries};
    at[0] = kImageHeaderBytes;
    for (uint32_t a = 0; a < kArrays; ++a) used[a] = bytes[a], at[a + 1] = at[a] + pad8(bytes[a]);
  }
};

}  // namespace keyanim::internal
