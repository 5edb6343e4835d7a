// The glTF asset's bytes: JSON, one packed float32 buffer, and the GLB container.
#pragma once
#include <string>

#include "gltf_model.h"

namespace keyanim::offline::gltf {

// A .glb: the JSON chunk, then the buffer as the BIN chunk.
std::string write_glb(const Model& model);
// A .gltf JSON whose buffer is `bin` (to be written at bin_uri, relative to the JSON).
void write_gltf(const Model& model, const std::string& bin_uri, std::string& json, std::string& bin);

// `text` as a JSON string literal: quotes, escapes, and any byte sequence that is not UTF-8
// replaced by U+FFFD (BVH names are bytes; glTF JSON must be UTF-8).
std::string json_string(const std::string& text);
// The shortest decimal that reads back as exactly `v` (finite).
std::string json_number(double v);

}  // namespace keyanim::offline::gltf
