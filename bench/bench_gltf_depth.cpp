// glTF export against the depth of the hierarchy (issue 23, class 3): the same N joints, with
// the same channels and values, once as a chain (each the child of the one before) and once
// side by side (each a child of the root), encoded and then exported; the CPU time of the
// export alone (the export runs on the calling thread). An export linear in the number of
// nodes grows as N in both; growth_exponent is log(t2/t1) / log(N2/N1) between the largest
// two sizes (1 linear, 2 quadratic). Prints one JSON object.
// Usage: bench_gltf_depth [--json] [--nodes 250,500,1000] [--frames 10]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "clock.h"
#include "keyanim/clip.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/gltf.h"

namespace {

using namespace keyanim;

// N joints, each rotating a little about Z with its own phase; `chain`: each the child of the
// one before (and an End Site at the tip), else each a child of joint 0.
offline::Motion motion(uint32_t n, uint32_t frames, bool chain) {
  offline::Motion m;
  for (uint32_t i = 0; i < n; ++i) {
    Joint j;
    j.name = "j" + std::to_string(i);
    j.parent = i == 0 ? -1 : chain ? int32_t(i) - 1 : 0;
    j.offset = {0.0, i == 0 ? 0.0 : 1.0, chain ? 0.0 : 0.01 * double(i)};
    j.channels = {ChannelType::z_rotation, ChannelType::x_rotation, ChannelType::y_rotation};
    m.skeleton.joints.push_back(j);
  }
  Joint tip;
  tip.parent = int32_t(n) - 1;
  tip.offset = {0.0, 1.0, 0.0};
  tip.end_site = true;
  m.skeleton.joints.push_back(tip);
  m.skeleton.assign_channel_columns();
  m.frame_count = frames;
  m.frame_time = 1.0 / 30.0;
  m.values.assign(size_t(frames) * 3 * n, 0.0);
  for (uint32_t f = 0; f < frames; ++f)
    for (uint32_t i = 0; i < n; ++i) m.values[(size_t(f) * n + i) * 3] = 0.01 * std::sin(0.3 * f + 0.01 * i);
  return m;
}

// CPU seconds of one glTF export of the motion's encoded clip, and the asset's size.
nlohmann::json export_cost(const offline::Motion& m) {
  offline::EncodeSettings settings;
  const offline::EncodeResult encoded = offline::encode(m, settings);
  const std::vector<uint8_t> bytes = offline::write_kanim(encoded.clip);
  Clip clip;
  if (Clip::load(bytes, clip) != Status::ok) throw std::runtime_error("the encoded clip does not load");
  const double t0 = bench::cpu_ns();
  const offline::GltfOutput out = offline::export_gltf(clip, offline::GltfOptions{});
  const double seconds = (bench::cpu_ns() - t0) * 1e-9;
  return {{"export_s", seconds}, {"glb_bytes", out.main.size()}, {"max_error", out.report.max_error},
          {"rounds", out.report.rounds}};
}

std::vector<uint32_t> sizes(const std::string& text) {
  std::vector<uint32_t> out;
  std::stringstream ss(text);
  for (std::string part; std::getline(ss, part, ',');) out.push_back(uint32_t(std::strtoul(part.c_str(), nullptr, 10)));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<uint32_t> nodes = {250, 500, 1000};
  uint32_t frames = 10;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--json") continue;  // the only output
    if (a == "--nodes" && i + 1 < argc) nodes = sizes(argv[++i]);
    else if (a == "--frames" && i + 1 < argc) frames = uint32_t(std::strtoul(argv[++i], nullptr, 10));
    else {
      std::cerr << "usage: bench_gltf_depth [--json] [--nodes 250,500,1000] [--frames 10]\n";
      return 1;
    }
  }
  if (nodes.size() < 2 || frames < 2) {
    std::cerr << "bench_gltf_depth: give at least two sizes and two frames\n";
    return 1;
  }
  nlohmann::json runs = nlohmann::json::array();
  for (uint32_t n : nodes)
    runs.push_back({{"nodes", n}, {"chain", export_cost(motion(n, frames, true))},
                    {"side_by_side", export_cost(motion(n, frames, false))}});
  const nlohmann::json& a = runs[runs.size() - 2];
  const nlohmann::json& b = runs.back();
  auto growth = [&](const char* shape) {
    return std::log(b[shape]["export_s"].get<double>() / a[shape]["export_s"].get<double>()) /
           std::log(double(b["nodes"].get<uint32_t>()) / double(a["nodes"].get<uint32_t>()));
  };
  const nlohmann::json result = {{"benchmark", "gltf_depth"},
                                 {"frames", frames},
                                 {"runs", runs},
                                 {"growth_exponent", {{"chain", growth("chain")}, {"side_by_side", growth("side_by_side")}}}};
  std::cout << result.dump(2) << "\n";
  return 0;
}
