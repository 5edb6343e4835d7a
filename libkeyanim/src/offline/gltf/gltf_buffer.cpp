// The glTF asset's buffer and accessors (gltf_buffer.h).
#include "gltf_buffer.h"

#include <algorithm>
#include <cstring>

#include "gltf_writer.h"

namespace keyanim::offline::gltf {
namespace {

int component_count(const std::string& type) {
  return type == "SCALAR" ? 1 : type == "VEC3" ? 3 : type == "VEC4" ? 4 : 16;  // MAT4
}

// "count", "type" and per-component "min" and "max" of `data`, as `text` writes a value.
template <typename T, typename Text>
std::string shape_json(const std::vector<T>& data, const char* type, Text text) {
  const int k = component_count(type);
  std::string mins, maxs;
  for (int c = 0; c < k; ++c) {
    T lo = data[size_t(c)], hi = lo;
    for (size_t i = size_t(c); i < data.size(); i += size_t(k)) lo = std::min(lo, data[i]), hi = std::max(hi, data[i]);
    mins += (c ? "," : "") + text(lo);
    maxs += (c ? "," : "") + text(hi);
  }
  return ",\"count\":" + std::to_string(data.size() / size_t(k)) + ",\"type\":\"" + type + "\",\"min\":[" + mins +
         "],\"max\":[" + maxs + "]";
}

}  // namespace

size_t BufferBuilder::floats(Use use, const std::vector<float>& data, const char* type) {
  const std::string bytes(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(float));
  return add(use, bytes, "\"componentType\":5126" + shape_json(data, type, [](float v) { return json_number(v); }));
}

size_t BufferBuilder::integers(Use use, const std::vector<uint32_t>& data, const char* type, Component component,
                               bool normalized) {
  const size_t width = component == Component::u8 ? 1 : component == Component::u16 ? 2 : 4;
  std::string bytes(data.size() * width, '\0');
  for (size_t i = 0; i < data.size(); ++i)  // little-endian, as glTF stores everything
    for (size_t b = 0; b < width; ++b) bytes[i * width + b] = char((data[i] >> (8 * b)) & 0xFF);
  std::string json = "\"componentType\":" + std::to_string(int(component));
  if (normalized) json += ",\"normalized\":true";
  return add(use, bytes, json + shape_json(data, type, [](uint32_t v) { return std::to_string(v); }));
}

size_t BufferBuilder::add(Use use, const std::string& bytes, std::string json) {
  const std::string key = std::to_string(int(use)) + json + '\0' + bytes;
  if (auto it = seen_.find(key); it != seen_.end()) return it->second;
  const bool shared = use == Use::animation || use == Use::matrices;
  size_t v = views_.size();
  for (size_t i = 0; shared && i < views_.size(); ++i)
    if (views_[i].use == use) v = i;
  if (v == views_.size()) views_.push_back({use, {}});
  std::string& view = views_[v].bytes;
  view.append((4 - view.size() % 4) % 4, '\0');  // every accessor 4-byte aligned (vertex attributes must be)
  accessors_.push_back({v, view.size(), std::move(json)});
  view += bytes;
  return seen_[key] = accessors_.size() - 1;
}

std::string BufferBuilder::bin() const {
  std::string out;
  for (const View& view : views_) {
    out += view.bytes;
    out.append((4 - out.size() % 4) % 4, '\0');
  }
  return out;
}

std::string BufferBuilder::accessors_json() const {
  std::string o;
  for (size_t i = 0; i < accessors_.size(); ++i) {
    const Accessor& a = accessors_[i];
    o += (i ? ",{" : "{") + std::string("\"bufferView\":") + std::to_string(a.view);
    if (a.offset > 0) o += ",\"byteOffset\":" + std::to_string(a.offset);
    o += "," + a.json + "}";
  }
  return o;
}

std::string BufferBuilder::views_json() const {
  std::string o;
  size_t at = 0;
  for (const View& view : views_) {
    o += (o.empty() ? "{" : ",{") + std::string("\"buffer\":0");
    if (at > 0) o += ",\"byteOffset\":" + std::to_string(at);
    o += ",\"byteLength\":" + std::to_string(view.bytes.size());
    if (view.use == Use::vertices) o += ",\"target\":34962";  // ARRAY_BUFFER
    if (view.use == Use::indices) o += ",\"target\":34963";   // ELEMENT_ARRAY_BUFFER
    o += "}";
    at += view.bytes.size();
    at += (4 - at % 4) % 4;
  }
  return o;
}

}  // namespace keyanim::offline::gltf
