// Loading a .kanim file: the loader's parts (load/) in the order of spec/FORMAT.md section 7,
// then the image the sampler reads (image_build.cpp). Clip::load and Clip::load_file.
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "internal/byte_reader.h"
#include "internal/format.h"
#include "keyanim/clip.h"
#include "runtime/clip_access.h"
#include "runtime/image.h"
#include "runtime/load/loader.h"
#include "runtime/load/member.h"
#include "runtime/rig_cache_access.h"

namespace keyanim {
namespace internal {

Status Loader::run(ClipSource& parts) {
  Status s = read_header_and_table();
  if (s != Status::ok) return s;
  parts.version_major = major_;
  parts.version_minor = minor_;
  if (runtime_) return run_runtime(parts);
  // Sections in table order (the critical ones are in order by now); unknown ancillary
  // sections are skipped without being decompressed.
  for (size_t i = 0; i < table_.size(); ++i) {
    const TableEntry& e = table_[i];
    Content c;
    if (static_cast<int>(i) == note_index_) {
      if ((s = get_content(e, "NOTE", c)) != Status::ok) return s;
      parts.notes.assign(reinterpret_cast<const char*>(c.data), c.size);
    } else {
      for (int k = 0; k < 6; ++k) {
        if (critical_index_[k] != static_cast<int>(i)) continue;
        switch (k) {
          case internal::kQuatSlot: s = get_content(e, "QUAT", c, k, &parts); if (s == Status::ok) s = parse_quat(c, parts); break;
          case 0:
            s = get_content(e, "CLIP", c, 0, &parts);
            if (s == Status::ok) s = parse_clip(c, parts);
            if (s == Status::ok && member_ != nullptr && (s = get_skel(-1, c)) == Status::ok) s = parse_skel(c, parts);
            break;
          case 1: s = get_content(e, "SKEL", c, 1, &parts); if (s == Status::ok) s = parse_skel(c, parts); break;
          case 2: s = get_content(e, "CHAN", c, 2, &parts); if (s == Status::ok) s = parse_chan(c, parts); break;
          case 3: s = get_content(e, "KTIM", c, 3, &parts); if (s == Status::ok) s = parse_ktim(c, parts); break;
          default:
            s = get_content(e, "KVAL", c, 4, &parts);
            if (s == Status::ok) s = major_ >= 3 ? parse_kval_fixed(c, parts) : parse_kval(c, parts);
            break;
        }
        if (s != Status::ok) return s;
      }
    }
    buffers_.clear();  // a decompressed section is not needed once parsed
  }
  return Status::ok;
}

// CLIP, IMAG, SKEL (entries 0, 1 and a later one, uncompressed), and NOTE. SKEL is read before
// IMAG is checked: IMAG's quaternion nodes are checked against it (version 5).
Status Loader::run_runtime(ClipSource& parts) {
  Content c;
  Status s = get_content(table_[0], "CLIP", c);
  if (s == Status::ok) s = parse_clip(c, parts);
  if (s == Status::ok) s = get_skel(critical_index_[2], skel_);
  if (s == Status::ok && rigs_ != nullptr) rig_ = RigCacheAccess::find_skel(*rigs_, skel());
  // Equal SKEL bytes were parsed and checked once; CLIP's counts must still agree with them.
  if (rig_ != nullptr && (rig_->skeleton.joints.size() != node_count_ || rig_->skeleton.channel_count() != channel_count_))
    rig_ = nullptr;
  if (s == Status::ok && rig_ == nullptr) s = parse_skel(skel_, parts);
  if (s == Status::ok) s = get_content(table_[1], "IMAG", imag_);
  if (s == Status::ok) s = check_image(imag_, parts, rig_ != nullptr ? rig_->skeleton : parts.skeleton);
  if (s == Status::ok && note_index_ >= 0) {
    s = get_content(table_[static_cast<size_t>(note_index_)], "NOTE", c);
    if (s == Status::ok) parts.notes.assign(reinterpret_cast<const char*>(c.data), c.size);
  }
  return s;
}

}  // namespace internal

using internal::ClipSource;
using internal::Loader;

namespace {

Status out_of_memory(Clip& out, ErrorInfo* err) {
  out = Clip{};
  if (err != nullptr) *err = ErrorInfo{Status::limit_exceeded, 0, "file", "out of memory"};
  return Status::limit_exceeded;
}

// Whether the header says the runtime profile (spec section 9: version 4 or later, Runtime set);
// the loader checks everything else.
bool says_runtime(std::span<const uint8_t> bytes) noexcept {
  if (bytes.size() < internal::kHeaderEnd) return false;
  return internal::load_le<uint16_t>(bytes.data() + 8) >= internal::kRuntimeVersionMajor &&
         (internal::load_le<uint32_t>(bytes.data() + 12) & internal::kHeaderRuntime) != 0;
}

// A runtime-profile file whose structure passed: its image over `bytes` (which `storage` owns,
// or the caller), then the content rules if asked for.
// `base`: where `bytes` start in what the caller reports offsets from (a bank's member).
Status runtime_clip(Loader& loader, ClipSource&& parts, std::span<const uint8_t> bytes,
                    std::shared_ptr<const void> storage, const DecodeLimits& limits, RigCache* rigs, Clip& out,
                    ErrorInfo* err, uint64_t base = 0) {
  const uint64_t keys = loader.key_count();
  const std::span<const uint8_t> imag = loader.image();
  // Before the call: an argument list may move `storage` before it reads it (clang does).
  const size_t held = storage ? bytes.size() : 0;
  out = ClipAccess::make(internal::view_image(std::move(parts), keys, imag, std::move(storage), held, rigs,
                                              loader.rig(), loader.skel()));
  if (!limits.check_content) return Status::ok;
  const Status s = out.check_content(err);
  if (s != Status::ok) {
    if (err != nullptr) err->byte_offset = base + static_cast<uint64_t>(imag.data() - bytes.data());
    out = Clip{};
  }
  return s;
}

}  // namespace

namespace internal {

Status load_member(std::span<const uint8_t> bytes, const MemberContext& m, std::shared_ptr<const void> storage,
                   const DecodeLimits& limits, RigCache* rigs, Clip& out, ErrorInfo* err) {
  out = Clip{};
  try {
    ClipSource parts;
    Loader loader(bytes, limits, err);
    loader.use_rigs(rigs);
    loader.use_member(&m);
    const Status s = loader.run(parts);
    if (s != Status::ok) return s;
    if (!loader.runtime()) {
      out = ClipAccess::make(internal::build_image(std::move(parts), rigs));
      return Status::ok;
    }
    return runtime_clip(loader, std::move(parts), bytes, std::move(storage), limits, rigs, out, err, m.member_offset);
  } catch (const std::bad_alloc&) {
    return out_of_memory(out, err);
  }
}

}  // namespace internal

Status Clip::load(std::span<const uint8_t> bytes, Clip& out, ErrorInfo* err, const DecodeLimits& limits,
                  RigCache* rigs) {
  out = Clip{};
  if (err != nullptr) *err = ErrorInfo{};
  try {
    if (!says_runtime(bytes)) {
      ClipSource parts;
      Loader loader(bytes, limits, err);
      const Status s = loader.run(parts);
      if (s != Status::ok) return s;
      out = ClipAccess::make(internal::build_image(std::move(parts), rigs));
      return Status::ok;
    }
    // The runtime profile: the file's bytes copied to 8-aligned memory the clip owns (no more
    // than the caller already holds), then checked and viewed there.
    auto words = std::shared_ptr<uint64_t[]>(new uint64_t[(bytes.size() + 7) / 8]);
    std::memcpy(words.get(), bytes.data(), bytes.size());
    const std::span<const uint8_t> copy(reinterpret_cast<const uint8_t*>(words.get()), bytes.size());
    ClipSource facts;
    Loader loader(copy, limits, err);
    loader.use_rigs(rigs);
    if (const Status c = loader.run(facts); c != Status::ok) return c;
    return runtime_clip(loader, std::move(facts), copy, std::move(words), limits, rigs, out, err);
  } catch (const std::bad_alloc&) {
    return out_of_memory(out, err);
  }
}

Status Clip::check_content(ErrorInfo* err) const noexcept {
  const internal::Image& img = ClipAccess::image(*this);
  if (!img.runtime_profile) return Status::ok;
  try {
    if (internal::image_content_holds(img)) return Status::ok;
    if (err != nullptr)
      *err = ErrorInfo{Status::corrupt, 0, "IMAG", "the image is not the one its keys make (spec section 9.4, content rules)"};
    return Status::corrupt;
  } catch (const std::bad_alloc&) {
    if (err != nullptr) *err = ErrorInfo{Status::limit_exceeded, 0, "IMAG", "out of memory"};
    return Status::limit_exceeded;
  }
}

Status Clip::view(std::span<const uint8_t> bytes, Clip& out, ErrorInfo* err, const DecodeLimits& limits,
                  RigCache* rigs) {
  out = Clip{};
  if (err != nullptr) *err = ErrorInfo{};
  if (reinterpret_cast<uintptr_t>(bytes.data()) % 8 != 0) {
    if (err != nullptr)
      *err = ErrorInfo{Status::invalid_argument, 0, "file", "Clip::view needs the bytes at an address that is a multiple of 8"};
    return Status::invalid_argument;
  }
  try {
    ClipSource parts;
    Loader loader(bytes, limits, err);
    loader.use_rigs(rigs);
    const Status s = loader.run(parts);
    if (s != Status::ok) return s;
    if (!loader.runtime()) {  // an archive file is decoded: the clip then needs `bytes` no more
      out = ClipAccess::make(internal::build_image(std::move(parts), rigs));
      return Status::ok;
    }
    return runtime_clip(loader, std::move(parts), bytes, nullptr, limits, rigs, out, err);
  } catch (const std::bad_alloc&) {
    return out_of_memory(out, err);
  }
}

Status Clip::load_file(const std::string& path, Clip& out, ErrorInfo* err, const DecodeLimits& limits,
                       RigCache* rigs) {
  out = Clip{};
  auto io_fail = [&](Status s, std::string detail) {
    if (err != nullptr) *err = ErrorInfo{s, 0, "file", path + ": " + detail};
    return s;
  };
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) return io_fail(Status::io_error, "cannot open");
  if (std::fseek(f.get(), 0, SEEK_END) != 0) return io_fail(Status::io_error, "cannot seek");
  const long end = std::ftell(f.get());
  if (end < 0 || std::fseek(f.get(), 0, SEEK_SET) != 0) return io_fail(Status::io_error, "cannot tell its size");
  if (static_cast<unsigned long>(end) > limits.max_decompressed_bytes)
    return io_fail(Status::limit_exceeded, "larger than max_decompressed_bytes");
  std::vector<uint8_t> bytes;
  try {
    bytes.resize(static_cast<size_t>(end));
  } catch (const std::bad_alloc&) {
    return io_fail(Status::limit_exceeded, "out of memory");
  }
  if (!bytes.empty() && std::fread(bytes.data(), 1, bytes.size(), f.get()) != bytes.size())
    return io_fail(Status::io_error, "read error");
  return load(bytes, out, err, limits, rigs);
}

}  // namespace keyanim
