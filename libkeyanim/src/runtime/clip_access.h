// The library's own door into Clip: building a clip from an image (the loader, and the
// encoder's to_clip) and reading a clip's image (the Cursor). Internal: a user cannot make a
// clip the loader has not validated.
#pragma once
#include <memory>

#include "keyanim/clip.h"
#include "runtime/image.h"

namespace keyanim {

struct ClipAccess {
  static Clip make(std::shared_ptr<const internal::Image> image);
  static const internal::Image& image(const Clip& clip);
  static const std::shared_ptr<const internal::Image>& shared(const Clip& clip) { return clip.image_; }
};

}  // namespace keyanim
