// Loading a .kanim file: the loader's parts (load/) in the order of spec/FORMAT.md section 7,
// then the image the sampler reads (image_build.cpp). Clip::load and Clip::load_file.
#include <cstdio>
#include <memory>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "keyanim/clip.h"
#include "runtime/clip_access.h"
#include "runtime/image.h"
#include "runtime/load/loader.h"

namespace keyanim {
namespace internal {

Status Loader::run(ClipSource& parts) {
  Status s = read_header_and_table();
  if (s != Status::ok) return s;
  parts.version_major = major_;
  parts.version_minor = minor_;
  // Sections in table order (the critical ones are in order by now); unknown ancillary
  // sections are skipped without being decompressed.
  for (size_t i = 0; i < table_.size(); ++i) {
    const TableEntry& e = table_[i];
    Content c;
    if (static_cast<int>(i) == note_index_) {
      if ((s = get_content(e, "NOTE", c)) != Status::ok) return s;
      parts.notes.assign(reinterpret_cast<const char*>(c.data), c.size);
    } else {
      for (int k = 0; k < 5; ++k) {
        if (critical_index_[k] != static_cast<int>(i)) continue;
        switch (k) {
          case 0: s = get_content(e, "CLIP", c, 0, &parts); if (s == Status::ok) s = parse_clip(c, parts); break;
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

}  // namespace internal

using internal::ClipSource;
using internal::Loader;

Status Clip::load(std::span<const uint8_t> bytes, Clip& out, ErrorInfo* err, const DecodeLimits& limits,
                  RigCache* rigs) {
  out = Clip{};
  if (err != nullptr) *err = ErrorInfo{};
  try {
    ClipSource parts;
    Loader loader(bytes, limits, err);
    const Status s = loader.run(parts);
    if (s != Status::ok) return s;
    out = ClipAccess::make(internal::build_image(std::move(parts), rigs));
  } catch (const std::bad_alloc&) {
    out = Clip{};
    if (err != nullptr) {
      err->status = Status::limit_exceeded;
      err->section = "file";
      err->byte_offset = 0;
      err->detail = "out of memory";
    }
    return Status::limit_exceeded;
  }
  return Status::ok;
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
