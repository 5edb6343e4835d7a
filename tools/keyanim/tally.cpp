#include "tally.h"

#include <cstdio>

#include "escape.h"

namespace keyanim::cli {

void EncodeTally::encoded(const nlohmann::json& s) {
  const double limit = s.contains("tolerance") ? s["tolerance"].get<double>() : s.value("error_limit", 0.0);
  const double error = s["error"]["max"].get<double>();
  // The worst input is the one closest to (or furthest past) its own tolerance: tolerances
  // differ between files (percent of each skeleton's size), so raw errors do not compare.
  const double ratio = limit > 0.0 ? error / limit : error;
  std::lock_guard<std::mutex> lock(mutex_);
  ++encoded_;
  bvh_bytes_ += s["bvh_bytes"].get<uint64_t>();
  kanim_bytes_ += s["kanim_bytes"].get<uint64_t>();
  if (ratio > worst_ratio_) worst_ratio_ = ratio, worst_ = s;
}

void EncodeTally::skipped() {
  std::lock_guard<std::mutex> lock(mutex_);
  ++skipped_;
}

std::string EncodeTally::line(const std::string& source, const std::string& outdir, size_t inputs) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const size_t failed = inputs - encoded_ - skipped_;
  char buf[256];
  std::snprintf(buf, sizeof buf, ": %s, %zu encoded%s%s in %.2f s", count_of(inputs, "input").c_str(), encoded_,
                skipped_ ? (", " + std::to_string(skipped_) + " skipped").c_str() : "",
                failed ? (", " + std::to_string(failed) + " failed").c_str() : "", seconds);
  std::string out = printable(source + " -> " + outdir) + buf;
  if (encoded_ == 0) return out;
  std::snprintf(buf, sizeof buf, "; %llu bytes of BVH -> %llu bytes of .kanim (%.4gx smaller)",
                (unsigned long long)bvh_bytes_, (unsigned long long)kanim_bytes_,
                kanim_bytes_ ? double(bvh_bytes_) / double(kanim_bytes_) : 0.0);
  out += buf;
  const nlohmann::json& e = worst_["error"];
  const bool tolerance = worst_.contains("tolerance");
  std::snprintf(buf, sizeof buf, "; worst error %.6g, %s %.6g (", e["max"].get<double>(),
                tolerance ? "tolerance" : "--error", worst_.value(tolerance ? "tolerance" : "error_limit", 0.0));
  out += buf + printable(worst_["input"].get<std::string>() + ", " + e["worst_point"].get<std::string>()) +
         ", frame " + std::to_string(e["worst_frame"].get<uint64_t>()) + ")";
  return out;
}

}  // namespace keyanim::cli
