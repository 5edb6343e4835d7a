// The glTF asset's bytes (gltf_writer.h).
#include "gltf_writer.h"

#include <charconv>
#include <cstring>
#include <map>

#include "keyanim/version.h"

namespace keyanim::offline::gltf {

std::string json_number(double v) {
  char buf[32];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}

namespace {

// Length of the valid UTF-8 sequence at s[i], or 0 if none starts there.
size_t utf8_length(const std::string& s, size_t i) {
  const auto b = [&](size_t k) { return k < s.size() ? static_cast<unsigned char>(s[k]) : 0u; };
  const unsigned c = b(i);
  const auto cont = [&](size_t k) { return (b(k) & 0xC0u) == 0x80u; };
  if (c < 0x80) return 1;
  if (c >= 0xC2 && c <= 0xDF) return cont(i + 1) ? 2 : 0;
  if (c >= 0xE0 && c <= 0xEF) {
    const unsigned c1 = b(i + 1);
    if ((c == 0xE0 && c1 < 0xA0) || (c == 0xED && c1 > 0x9F)) return 0;  // overlong, surrogates
    return cont(i + 1) && cont(i + 2) ? 3 : 0;
  }
  if (c >= 0xF0 && c <= 0xF4) {
    const unsigned c1 = b(i + 1);
    if ((c == 0xF0 && c1 < 0x90) || (c == 0xF4 && c1 > 0x8F)) return 0;
    return cont(i + 1) && cont(i + 2) && cont(i + 3) ? 4 : 0;
  }
  return 0;
}

}  // namespace

std::string json_string(const std::string& text) {
  std::string o = "\"";
  for (size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    const size_t len = utf8_length(text, i);
    if (len == 0) {
      o += "\xEF\xBF\xBD";  // U+FFFD
      ++i;
    } else if (c == '"' || c == '\\') {
      o += '\\';
      o += char(c);
      ++i;
    } else if (c < 0x20) {
      static const char kHex[] = "0123456789abcdef";
      o += "\\u00";
      o += kHex[c >> 4];
      o += kHex[c & 15];
      ++i;
    } else {
      o.append(text, i, len);
      i += len;
    }
  }
  return o + "\"";
}

namespace {

// Accessors over one packed buffer; identical arrays (e.g. the time keys of several tracks)
// are stored once.
class BufferBuilder {
 public:
  // Index of an accessor of `type` ("SCALAR", "VEC3", "VEC4") over `data`.
  size_t accessor(const std::vector<float>& data, int components, const char* type) {
    const std::string bytes(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(float));
    const std::string key = std::string(type) + '\0' + bytes;
    if (auto it = seen_.find(key); it != seen_.end()) return it->second;
    std::string a = "{\"bufferView\":0,\"byteOffset\":" + std::to_string(bin_.size()) +
                    ",\"componentType\":5126,\"count\":" + std::to_string(data.size() / size_t(components)) +
                    ",\"type\":\"" + type + "\"";
    std::string mins, maxs;
    for (int c = 0; c < components; ++c) {
      float lo = data[size_t(c)], hi = lo;
      for (size_t i = size_t(c); i < data.size(); i += size_t(components)) lo = std::min(lo, data[i]), hi = std::max(hi, data[i]);
      mins += (c ? "," : "") + json_number(lo);
      maxs += (c ? "," : "") + json_number(hi);
    }
    a += ",\"min\":[" + mins + "],\"max\":[" + maxs + "]}";
    bin_ += bytes;  // little-endian float32, 4-byte aligned since everything is float32
    accessors_.push_back(std::move(a));
    return seen_[key] = accessors_.size() - 1;
  }
  const std::string& bin() const { return bin_; }
  std::string accessors_json() const {
    std::string o;
    for (size_t i = 0; i < accessors_.size(); ++i) o += (i ? "," : "") + accessors_[i];
    return o;
  }

 private:
  std::string bin_;
  std::vector<std::string> accessors_;
  std::map<std::string, size_t> seen_;
};

std::string vec_json(const double* v, int n) {
  std::string o = "[";
  for (int i = 0; i < n; ++i) o += (i ? "," : "") + json_number(v[i]);
  return o + "]";
}

std::string node_name(const Skeleton& sk, size_t j) {
  const Joint& joint = sk.joints[j];
  if (!joint.end_site || !joint.name.empty() || joint.parent < 0) return joint.name;
  return sk.joints[size_t(joint.parent)].name + "_End";
}

std::string nodes_json(const Skeleton& sk, std::string& roots) {
  std::vector<std::vector<size_t>> children(sk.joints.size());
  for (size_t j = 0; j < sk.joints.size(); ++j) {
    const int32_t p = sk.joints[j].parent;
    if (p < 0 || size_t(p) >= j) roots += (roots.empty() ? "" : ",") + std::to_string(j);
    else children[size_t(p)].push_back(j);
  }
  std::string o;
  for (size_t j = 0; j < sk.joints.size(); ++j) {
    const Joint& joint = sk.joints[j];
    o += (j ? ",{" : "{") + std::string("\"name\":") + json_string(node_name(sk, j));
    if (joint.offset != Vec3{0, 0, 0}) o += ",\"translation\":" + vec_json(joint.offset.data(), 3);
    if (!children[j].empty()) {
      o += ",\"children\":[";
      for (size_t k = 0; k < children[j].size(); ++k) o += (k ? "," : "") + std::to_string(children[j][k]);
      o += "]";
    }
    o += "}";
  }
  return o;
}

// The whole JSON document; `bin_uri` empty for a GLB.
std::string document(const Model& model, const std::string& bin_uri, std::string& bin) {
  BufferBuilder buffer;
  std::string channels, samplers;
  size_t count = 0;
  for (size_t j = 0; j < model.nodes.size(); ++j) {
    const std::pair<const char*, const std::optional<Sampler>*> tracks[] = {
        {"translation", &model.nodes[j].translation}, {"rotation", &model.nodes[j].rotation}};
    for (const auto& [path, track] : tracks) {
      if (!*track) continue;
      const Sampler& s = **track;
      const size_t input = buffer.accessor(s.times, 1, "SCALAR");
      const size_t output = buffer.accessor(s.values, s.components, s.components == 4 ? "VEC4" : "VEC3");
      channels += (count ? "," : "") + std::string("{\"sampler\":") + std::to_string(count) +
                  ",\"target\":{\"node\":" + std::to_string(j) + ",\"path\":\"" + path + "\"}}";
      samplers += (count ? "," : "") + std::string("{\"input\":") + std::to_string(input) +
                  ",\"output\":" + std::to_string(output) + ",\"interpolation\":\"" +
                  (s.interp == Interp::cubic ? "CUBICSPLINE" : "LINEAR") + "\"}";
      ++count;
    }
  }
  std::string roots;
  const std::string nodes = nodes_json(model.skeleton, roots);
  std::string o = "{\"asset\":{\"version\":\"2.0\",\"generator\":\"keyanim " KEYANIM_VERSION_STRING "\"";
  if (!model.extras_json.empty()) o += ",\"extras\":" + model.extras_json;
  o += "},\"scene\":0,\"scenes\":[{\"nodes\":[" + roots + "]}],\"nodes\":[" + nodes + "]";
  if (count > 0) {
    o += ",\"animations\":[{\"name\":" + json_string(model.animation_name) + ",\"channels\":[" + channels +
         "],\"samplers\":[" + samplers + "]}]";
    const std::string size = std::to_string(buffer.bin().size());
    o += ",\"accessors\":[" + buffer.accessors_json() + "],\"bufferViews\":[{\"buffer\":0,\"byteLength\":" + size +
         "}],\"buffers\":[{\"byteLength\":" + size + (bin_uri.empty() ? "" : ",\"uri\":" + json_string(bin_uri)) + "}]";
  }
  bin = buffer.bin();
  return o + "}";
}

void put_u32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out += char((v >> (8 * i)) & 0xFF);
}

}  // namespace

std::string write_glb(const Model& model) {
  std::string bin;
  std::string json = document(model, "", bin);
  json.append((4 - json.size() % 4) % 4, ' ');
  bin.append((4 - bin.size() % 4) % 4, '\0');
  const size_t total = 12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size());
  std::string out;
  out.reserve(total);
  put_u32(out, 0x46546C67);  // "glTF"
  put_u32(out, 2);
  put_u32(out, uint32_t(total));
  put_u32(out, uint32_t(json.size()));
  put_u32(out, 0x4E4F534A);  // "JSON"
  out += json;
  if (!bin.empty()) {
    put_u32(out, uint32_t(bin.size()));
    put_u32(out, 0x004E4942);  // "BIN\0"
    out += bin;
  }
  return out;
}

void write_gltf(const Model& model, const std::string& bin_uri, std::string& json, std::string& bin) {
  json = document(model, bin_uri, bin);
}

}  // namespace keyanim::offline::gltf
