// sample_dump IN.kanim OUT.bin: every way the runtime samples a clip, written as raw bytes, so
// that two builds of the runtime can be compared bit for bit (scalar_test.sh: the SSE2 build
// against the same sources compiled without SSE2). Positions run from before the first frame
// to after the last, on and between frames; playback goes forward through a Cursor.
#include <algorithm>
#include <cstdio>
#include <vector>

#include "keyanim/clip.h"
#include "keyanim/pose.h"

namespace {

template <class T>
void put(std::FILE* f, const std::vector<T>& v) {
  std::fwrite(v.data(), sizeof(T), v.size(), f);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace keyanim;
  if (argc != 3) return std::fprintf(stderr, "usage: sample_dump IN.kanim OUT.bin\n"), 2;
  Clip clip;
  ErrorInfo err;
  if (Clip::load_file(argv[1], clip, &err) != Status::ok) return std::fprintf(stderr, "%s: cannot load\n", argv[1]), 1;
  std::FILE* out = std::fopen(argv[2], "wb");
  if (!out) return 1;
  std::vector<float> pose(clip.channel_count()), some;
  std::vector<Transform> nodes(clip.skeleton().joints.size());
  std::vector<uint32_t> odd;  // every other channel, backwards: the listed-channel path
  for (uint32_t c = clip.channel_count(); c-- > 0;)
    if (c % 2) odd.push_back(c);
  some.resize(odd.size());
  const double end = double(clip.frame_count()) + 3.0;
  const double step = std::max(0.37, end / 4000.0);  // long clips: a few thousand positions
  for (double f = -3.0; f < end; f += step) {
    if (clip.sample(f, pose) != Status::ok || clip.sample_channels(f, odd, some) != Status::ok) return 1;
    put(out, pose), put(out, some);
    for (PositionReading r : {PositionReading::replace, PositionReading::add}) {
      if (clip.sample_local(f, nodes, nullptr, r) != Status::ok) return 1;
      put(out, nodes);
      if (clip.sample_model(f, nodes, nullptr, r) != Status::ok) return 1;
      put(out, nodes);
    }
  }
  Cursor cursor;
  if (cursor.prepare(clip) != Status::ok) return 1;
  for (double f = -2.0; f < end; f += step * 0.5) {
    if (clip.sample(f, pose, &cursor) != Status::ok || clip.sample_model(f, nodes, &cursor) != Status::ok) return 1;
    put(out, pose), put(out, nodes);
  }
  return std::fclose(out) == 0 ? 0 : 1;
}
