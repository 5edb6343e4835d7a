// The glTF asset's one binary buffer and its accessors (gltf_writer.cpp writes the JSON around
// them). glTF validators want one buffer view per use: animation data and inverse bind matrices
// each share one; every vertex attribute and the indices get one each (with a bufferView target;
// one accessor per view needs no byteStride), laid out in the order they are added.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace keyanim::offline::gltf {

enum class Use : uint8_t { animation, matrices, vertices, indices };

// glTF accessor component types (glTF 2.0, 5.1.1).
enum class Component : uint16_t { u8 = 5121, u16 = 5123, u32 = 5125, f32 = 5126 };

class BufferBuilder {
 public:
  // Index of an accessor of `type` ("SCALAR", "VEC3", "VEC4", "MAT4") over float32 `data`, with
  // min and max. Identical arrays of one use (e.g. the time keys of several tracks) are stored once.
  size_t floats(Use use, const std::vector<float>& data, const char* type);
  // The same over unsigned integers stored as `component`; `normalized` maps them to [0, 1].
  size_t integers(Use use, const std::vector<uint32_t>& data, const char* type, Component component,
                  bool normalized = false);
  // The buffer: the views' bytes one after the other, each 4-byte aligned.
  std::string bin() const;
  // The "accessors" and "bufferViews" JSON arrays' contents.
  std::string accessors_json() const;
  std::string views_json() const;

 private:
  struct Accessor {
    size_t view;
    size_t offset;     // in its view
    std::string json;  // everything but bufferView and byteOffset
  };
  struct View {
    Use use;
    std::string bytes;
  };
  size_t add(Use use, const std::string& bytes, std::string json);

  std::vector<View> views_;
  std::vector<Accessor> accessors_;
  std::map<std::string, size_t> seen_;
};

}  // namespace keyanim::offline::gltf
