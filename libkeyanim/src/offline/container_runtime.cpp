// The runtime profile (spec/FORMAT.md section 9): a loaded clip's image written as a file, and
// a clip's keys taken back for the archive profile's writer.
#include <utility>

#include "internal/byte_writer.h"
#include "internal/format.h"
#include "internal/xxh64.h"
#include "keyanim/offline/container.h"
#include "keyanim/version.h"
#include "offline/container_parts.h"
#include "runtime/clip_access.h"

namespace keyanim::offline {

std::vector<Section> runtime_sections(const Clip& clip) {
  const internal::Image& img = ClipAccess::image(clip);
  std::vector<Section> sections;
  auto add = [&](uint32_t tag, uint32_t flags, std::vector<uint8_t> bytes) {
    const uint64_t n = bytes.size();
    sections.push_back({tag, flags, n, std::move(bytes)});
  };
  add(internal::kTagClip, 0,
      clip_section(img.frame_count, clip.skeleton(), img.interp.size(), img.rule, img.frame_time, img.total_keys));
  add(internal::kTagImag, 0, {img.imag.begin(), img.imag.end()});
  add(internal::kTagSkel, 0, skel_section(clip.skeleton()));
  if (!img.notes.empty()) add(internal::kTagNote, internal::kSectionAncillary, {img.notes.begin(), img.notes.end()});
  return sections;
}

uint16_t runtime_version_major(const Clip& clip) {
  return clip.quat_node_count() > 0 ? kQuatFormatVersionMajor : kRuntimeFormatVersionMajor;
}

std::vector<uint8_t> write_kanim_runtime(const Clip& clip) {
  std::vector<uint8_t> out = assemble(runtime_sections(clip), runtime_version_major(clip), 0,
                                      internal::kHeaderRuntime, internal::kRuntimeChecksumSize);
  internal::put_le<uint64_t>(out, internal::xxh64_of(out.data(), out.size()));
  return out;
}

EncodedClip encoded_clip(const Clip& clip) {
  const internal::ClipSource src = internal::image_keys(ClipAccess::image(clip));
  EncodedClip out;
  out.skeleton = src.skeleton;
  out.frame_count = src.frame_count;
  out.frame_time = src.frame_time;
  out.tangent_rule = src.rule;
  out.quat_nodes = src.quat_nodes;
  out.notes = src.notes;
  out.channels.resize(src.channels.size());
  for (size_t c = 0; c < src.channels.size(); ++c) {
    const internal::SourceChannel& sc = src.channels[c];
    EncodedChannel& ch = out.channels[c];
    ch.interp = sc.interp;
    ch.tension = sc.tension;
    ch.step = sc.step;
    ch.frames.assign(src.frames.begin() + sc.first_key, src.frames.begin() + sc.first_key + sc.key_count);
    ch.q.assign(src.q.begin() + sc.first_key, src.q.begin() + sc.first_key + sc.key_count);
  }
  return out;
}

}  // namespace keyanim::offline
