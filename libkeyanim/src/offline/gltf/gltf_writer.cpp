// The glTF asset's bytes (gltf_writer.h).
#include "gltf_writer.h"

#include <charconv>
#include <cstring>

#include "gltf_buffer.h"
#include "keyanim/offline/metrics.h"
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

std::string vec_json(const double* v, int n) {
  std::string o = "[";
  for (int i = 0; i < n; ++i) o += (i ? "," : "") + json_number(v[i]);
  return o + "]";
}

// Nodes are named as keyanim names points elsewhere (metrics.h, `keyanim sample --world`): an
// End Site without a name is "End Site of PARENT", so a bone is found by the same name everywhere.
std::string node_name(const Skeleton& sk, size_t j) { return point_name(sk, uint32_t(j), 0); }

// The joints' nodes, parents first (`roots`: those without a parent), then (with a mesh) the mesh
// node: a root without a transform, as glTF wants of a skinned mesh (the joints alone place it).
std::string nodes_json(const Skeleton& sk, bool meshed, std::string& roots) {
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
  if (meshed) o += (o.empty() ? "{" : ",{") + std::string("\"name\":\"keyanim bones\",\"mesh\":0,\"skin\":0}");
  return o;
}

// The smallest unsigned glTF component holding `largest`; indices must stay below the
// primitive-restart value (the type's largest), which glTF forbids in indices.
Component component_for(uint64_t largest, bool index) {
  if (largest < (index ? 0xFFu : 0x100u)) return Component::u8;
  if (largest < (index ? 0xFFFFu : 0x10000u)) return Component::u16;
  return Component::u32;
}

// "meshes" and "materials" of the bone mesh: one primitive weighted fully to one joint per
// vertex (JOINTS_0 = that joint, WEIGHTS_0 = 1, 0, 0, 0) and a plain matte material.
std::string mesh_json(const Model& model, BufferBuilder& buffer) {
  const Skin& skin = model.skin;
  const size_t nodes = model.skeleton.joints.size();
  const size_t vertices = skin.joints.size();
  std::vector<uint32_t> joints(4 * vertices, 0), weights(4 * vertices, 0);
  for (size_t v = 0; v < vertices; ++v) joints[4 * v] = skin.joints[v], weights[4 * v] = 255;
  const size_t position = buffer.floats(Use::vertices, skin.positions, "VEC3");
  const size_t joint = buffer.integers(Use::vertices, joints, "VEC4", component_for(nodes - 1, false));
  const size_t weight = buffer.integers(Use::vertices, weights, "VEC4", Component::u8, true);
  const size_t index = buffer.integers(Use::indices, skin.indices, "SCALAR", component_for(vertices - 1, true));
  std::string o = ",\"meshes\":[{\"name\":\"keyanim bones\",\"primitives\":[{\"attributes\":{\"POSITION\":" +
                  std::to_string(position) + ",\"JOINTS_0\":" + std::to_string(joint) + ",\"WEIGHTS_0\":" +
                  std::to_string(weight) + "},\"indices\":" + std::to_string(index) + ",\"material\":0}]}]";
  o += ",\"materials\":[{\"name\":\"keyanim bones\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.8,0.8,0.8,1],"
       "\"metallicFactor\":0,\"roughnessFactor\":0.8}}]";
  return o;
}

// "skins": every node a joint, the skeleton root named when there is one root.
std::string skin_json(const Model& model, const std::string& roots, BufferBuilder& buffer) {
  const size_t nodes = model.skeleton.joints.size();
  const size_t binds = buffer.floats(Use::matrices, model.skin.inverse_binds, "MAT4");
  std::string o = ",\"skins\":[{\"name\":" + json_string(model.animation_name) + ",\"inverseBindMatrices\":" + std::to_string(binds);
  if (roots.find(',') == std::string::npos) o += ",\"skeleton\":" + roots;  // one root
  o += ",\"joints\":[";
  for (size_t j = 0; j < nodes; ++j) o += (j ? "," : "") + std::to_string(j);
  return o + "]}]";
}

// The "animations" member (empty when nothing is animated: a clip without frames).
std::string animation_json(const Model& model, BufferBuilder& buffer) {
  std::string channels, samplers;
  size_t count = 0;
  for (size_t j = 0; j < model.nodes.size(); ++j) {
    const std::pair<const char*, const std::optional<Sampler>*> tracks[] = {
        {"translation", &model.nodes[j].translation}, {"rotation", &model.nodes[j].rotation}};
    for (const auto& [path, track] : tracks) {
      if (!*track) continue;
      const Sampler& s = **track;
      const size_t input = buffer.floats(Use::animation, s.times, "SCALAR");
      const size_t output = buffer.floats(Use::animation, s.values, s.components == 4 ? "VEC4" : "VEC3");
      channels += (count ? "," : "") + std::string("{\"sampler\":") + std::to_string(count) +
                  ",\"target\":{\"node\":" + std::to_string(j) + ",\"path\":\"" + path + "\"}}";
      samplers += (count ? "," : "") + std::string("{\"input\":") + std::to_string(input) +
                  ",\"output\":" + std::to_string(output) + ",\"interpolation\":\"" +
                  (s.interp == Interp::cubic ? "CUBICSPLINE" : "LINEAR") + "\"}";
      ++count;
    }
  }
  if (count == 0) return "";
  std::string o = ",\"animations\":[{\"name\":" + json_string(model.animation_name) + ",\"channels\":[" + channels +
                  "],\"samplers\":[" + samplers + "]";
  if (!model.timing_json.empty()) o += ",\"extras\":" + model.timing_json;
  return o + "}]";
}

// The whole JSON document; `bin_uri` empty for a GLB.
std::string document(const Model& model, const std::string& bin_uri, std::string& bin) {
  BufferBuilder buffer;
  const std::string animations = animation_json(model, buffer);
  std::string roots;
  const bool meshed = model.skin.has_mesh();
  const std::string nodes = nodes_json(model.skeleton, meshed, roots);
  std::string o = "{\"asset\":{\"version\":\"2.0\",\"generator\":\"keyanim " KEYANIM_VERSION_STRING "\"";
  if (!model.extras_json.empty()) o += ",\"extras\":" + model.extras_json;
  const std::string scene_roots = roots + (meshed ? "," + std::to_string(model.skeleton.joints.size()) : "");
  o += "},\"scene\":0,\"scenes\":[{\"nodes\":[" + scene_roots + "]";
  if (!model.timing_json.empty()) o += ",\"extras\":" + model.timing_json;  // Blender keeps these as scene properties
  o += "}],\"nodes\":[" + nodes + "]";
  if (meshed) o += mesh_json(model, buffer);
  if (!model.skin.empty()) o += skin_json(model, roots, buffer);
  o += animations;
  bin = buffer.bin();
  if (!bin.empty()) {
    const std::string size = std::to_string(bin.size());
    o += ",\"accessors\":[" + buffer.accessors_json() + "],\"bufferViews\":[" + buffer.views_json() +
         "],\"buffers\":[{\"byteLength\":" + size + (bin_uri.empty() ? "" : ",\"uri\":" + json_string(bin_uri)) + "}]";
  }
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
