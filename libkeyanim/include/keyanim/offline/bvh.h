// BVH reading and writing. The reader accepts the format as real files use it and reports
// damage as file:line:column; the writer prints the shortest text that reads back bit-exactly.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "keyanim/offline/error.h"
#include "keyanim/offline/motion.h"

namespace keyanim::offline {

struct BvhReadOptions {
  uint32_t max_joints = 1u << 16;  // Defaults to 65536 nodes; more is an error, not an allocation.
  uint32_t max_frames = 1u << 24;  // Defaults to 16777216 frames.
  // Defaults to none. Called every 1024 motion lines with the fraction of the motion text read
  // (0 to 1), and once at its end: a progress display for long files.
  std::function<void(double fraction)> progress;
};

// Parses BVH text into a motion, appending any warnings (e.g. more motion lines than `Frames:`
// declares: all lines are kept) to `warnings`. Throws Error (kind malformed, or limit past
// `options`) at the 1-based line and byte column of the offending token, the message being
// "expected X, found Y". What is accepted:
//  - one or more ROOT blocks (a forest: every root has parent -1); JOINT; End Site, optionally
//    followed by a name (kept in Joint::name); a joint without children or without CHANNELS;
//  - OFFSET and CHANNELS (0..6 distinct channels in any order) before a block's children;
//  - keywords in any case; LF, CRLF, lone CR, mixed; tabs, runs of spaces, blank lines, a UTF-8
//    BOM; a '{' may end the ROOT/JOINT/End Site line;
//  - joint names: the rest of the line after ROOT/JOINT, blanks trimmed at both ends;
//  - numbers: std::from_chars forms plus a leading '+', fully consumed; nan/inf and overflow are
//    errors; a value below the smallest subnormal reads as a signed zero (as strtod rounds it);
//  - one frame per line (trailing blanks allowed). More lines than `Frames:` declares: all are
//    kept, with a warning; fewer: an error naming both numbers. Nothing is allocated from the
//    declared count beyond what the remaining text could hold.
Motion read_bvh(std::string_view text, const std::string& file_name, std::vector<std::string>* warnings = nullptr,
                const BvhReadOptions& options = {});
// Reads a whole file and parses it; a file that cannot be read throws Error (io, with errno).
Motion read_bvh_file(const std::string& path, std::vector<std::string>* warnings = nullptr,
                     const BvhReadOptions& options = {});

// BVH text with LF line endings and tab indentation (at most kMaxIndent tabs, so that the text
// stays linear in the node count however deep the hierarchy: readers do not need indentation);
// numbers in std::to_chars' shortest form, which reads back to the same double, so
// read(write(m)) == m bit for bit. Nodes are written depth-first (children in index order: the
// reader's order) and the frame columns follow. A node whose parent is not an earlier node is
// written as a ROOT; an End Site is written as "End Site" (plus " name" if it has one) only when
// it has no channels and no children, else as a JOINT.
// Writes min(frame_count, values.size() / channel_count) frames.
std::string write_bvh(const Motion& motion);

inline constexpr size_t kMaxIndent = 32;

// The same text written piece by piece, for outputs too large to hold: the hierarchy and the
// MOTION header first, then one frame at a time. Text reaches `sink` in chunks of about 1 MiB
// (the last one at finish()), so memory does not grow with the number of frames.
class BvhWriter {
 public:
  using Sink = std::function<void(std::string_view)>;
  // Writes the hierarchy and "Frames: frame_count". The skeleton must outlive the writer.
  BvhWriter(const Skeleton& skeleton, uint64_t frame_count, double frame_time, Sink sink);
  BvhWriter(const BvhWriter&) = delete;
  BvhWriter& operator=(const BvhWriter&) = delete;
  // One frame: the skeleton's channel_count() values in column order (as Motion::frame()).
  void frame(const double* values);
  // Hands what is left to the sink. Throws Error (invalid_argument) if the frames given differ
  // from the declared count (the text is then not valid BVH).
  void finish();

 private:
  void flush();
  Sink sink_;
  std::string buffer_;
  size_t used_ = 0;
  std::vector<uint32_t> source_;  // source column of each written column
  bool identity_ = true;
  uint64_t declared_ = 0, written_ = 0;
};

}  // namespace keyanim::offline
